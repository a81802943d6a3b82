#pragma once

#include <facet/fwd.h>

#include <string>

namespace facet {

/// Kinds of scene objects; the XML tag of each is given by object_type_name().
enum class ObjectType : uint32_t {
    Unknown = 0,
    Scene,
    ReconstructionFilter,
    Sensor,
    Film,
    Emitter,
    Sampler,
    Shape,
    Texture,
    Volume,
    Medium,
    BSDF,
    PhaseFunction,
    Integrator,
};

/// XML tag for a kind: "rfilter", "bsdf", "shape", ...
const char *object_type_name(ObjectType type);
/// Plugin folder name for a kind: "rfilters", "bsdfs", "shapes", ...
const char *object_type_folder(ObjectType type);
/// Inverse of object_type_name(); Unknown when the tag is not an object tag.
ObjectType object_type_from_name(const std::string &name);

/// Base class of everything a scene file can create.
class Object : public std::enable_shared_from_this<Object> {
public:
    virtual ~Object() = default;
    virtual ObjectType type() const = 0;
    virtual std::string to_string() const { return std::string(object_type_name(type())); }
    /// Id given in the scene file (may be empty).
    const std::string &id() const { return m_id; }
    void set_id(const std::string &id) { m_id = id; }
    /// Called once by the loader after all objects of the scene exist (parents included).
    virtual void parameters_changed() {}

private:
    std::string m_id;
};

} // namespace facet
