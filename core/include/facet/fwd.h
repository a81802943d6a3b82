#pragma once

#include <cstdint>
#include <memory>

/// Forward declarations of the facet object model.
namespace facet {

using Float = float;

template <typename T> struct Vec2;
template <typename T> struct Vec3;
struct Color3f;
struct Frame;
struct Matrix4f;
struct Transform;
struct Ray;
struct BoundingBox3f;
struct Interaction;
struct SurfaceInteraction;
struct PositionSample;
struct DirectionSample;
struct BSDFContext;
struct BSDFSample;
struct Location;

class Object;
class Properties;
class PluginRegistry;
class BSDF;
class Emitter;
class Shape;
class Mesh;
class Sensor;
class Film;
class FilmBuffer;
class ImageBlock;
class Sampler;
class Texture;
class SpectrumTexture;
class ReconstructionFilter;
class Integrator;
class Scene;

using ref_object = std::shared_ptr<Object>;

} // namespace facet
