#pragma once

#include <facet/color.h>
#include <facet/interaction.h>
#include <facet/logger.h>
#include <facet/object.h>

#include <optional>
#include <utility>

namespace facet {

enum class EmitterFlags : uint32_t {
    Empty = 0,
    DeltaPosition = 0x1,  ///< point-like (point, spot)
    DeltaDirection = 0x2, ///< one direction (directional)
    Infinite = 0x4,       ///< at infinity (constant, envmap, directional)
    Surface = 0x8,        ///< attached to a shape (area)
    SpatiallyVarying = 0x10,
    Delta = DeltaPosition | DeltaDirection,
};
constexpr EmitterFlags operator|(EmitterFlags a, EmitterFlags b) {
    return EmitterFlags(uint32_t(a) | uint32_t(b));
}
constexpr EmitterFlags operator&(EmitterFlags a, EmitterFlags b) {
    return EmitterFlags(uint32_t(a) & uint32_t(b));
}
constexpr bool has_flag(EmitterFlags a, EmitterFlags b) { return (uint32_t(a) & uint32_t(b)) != 0; }

/// A light source.
///
/// Conventions: sample_direction() samples a point on the emitter as seen from `ref` and returns
/// the record (direction, distance, solid-angle pdf; pdf = 1 and delta = true for delta emitters)
/// and the weight L·G/pdf that the integrator multiplies by the BSDF, without any visibility test.
/// eval() gives the radiance arriving along a ray that hit the emitter: for area emitters `si` is
/// the hit (si.wi in the local shading frame); for infinite emitters `si` is a miss record whose
/// sh_frame is the identity and whose si.wi = -ray.d in world space.
class Emitter : public Object {
public:
    ObjectType type() const override { return ObjectType::Emitter; }

    virtual std::pair<DirectionSample, Color3f> sample_direction(const Interaction &ref,
                                                                 const Point2f &u) const = 0;
    /// Solid-angle density of sample_direction() for the point ds.p seen from ref (0 for delta).
    virtual float pdf_direction(const Interaction &ref, const DirectionSample &ds) const = 0;
    /// Emitted radiance; zero for delta emitters.
    virtual Color3f eval(const SurfaceInteraction &si) const = 0;

    /// Samples a ray leaving the emitter (light tracing, photon emission) from two uniform pairs:
    /// `u_pos` for the position, `u_dir` for the direction. Returns the ray and the power
    /// weight (emitted intensity or radiance·cos over the joint density). In the spectral modes
    /// the weight is the power at the path's `wavelengths`, which the ray carries
    /// (Ray::wavelengths); in the others they are ignored. Not every emitter supports it; those
    /// that do not throw.
    virtual std::pair<Ray, Color3f> sample_ray(const Point2f &u_pos, const Point2f &u_dir,
                                               const Wavelengths &wavelengths) const {
        FACET_THROW("{} cannot sample emitted rays", to_string());
    }
    /// Solid-angle density of the directions sample_ray() draws, for emitters with one origin
    /// (point, spot); `d` is a unit world-space direction.
    virtual float pdf_ray_direction(const Vector3f &d) const {
        FACET_THROW("{} cannot sample emitted rays", to_string());
    }

    /// The emitter as a value, when it is the simplest surface emitter: one constant radiance
    /// leaving the front side of its shape (the side its normal points to), the same at every
    /// point and in every direction of that side, nothing from the back. An emitter that returns
    /// it promises that eval(), sample_direction() and pdf_direction() are those of this value
    /// with the shape's own direction sampling; the scene may then compute them from the value
    /// and the shape. Default: none (the scene always asks the emitter).
    virtual std::optional<Color3f> constant_radiance() const { return std::nullopt; }
    /// Position in the emitter list of the scene that holds it (set by the scene).
    uint32_t scene_index() const { return m_scene_index; }
    void set_scene_index(uint32_t index) { m_scene_index = index; }

    /// Called by the shape that owns an area emitter.
    virtual void set_shape(const Shape *shape) { m_shape = shape; }
    const Shape *shape() const { return m_shape; }
    /// Called once the scene's bounds are known (infinite emitters need them).
    virtual void set_scene(const Scene &scene) {}

    EmitterFlags flags() const { return m_flags; }
    bool is_delta() const { return has_flag(m_flags, EmitterFlags::Delta); }
    bool is_infinite() const { return has_flag(m_flags, EmitterFlags::Infinite); }

protected:
    EmitterFlags m_flags = EmitterFlags::Empty;
    const Shape *m_shape = nullptr;
    uint32_t m_scene_index = uint32_t(-1);
};

} // namespace facet
