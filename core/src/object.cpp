#include <facet/object.h>

namespace facet {

namespace {
struct TypeNames {
    ObjectType type;
    const char *name, *folder;
};
constexpr TypeNames TYPE_NAMES[] = {
    {ObjectType::Unknown, "unknown", "unknown"},
    {ObjectType::Scene, "scene", "scenes"},
    {ObjectType::ReconstructionFilter, "rfilter", "rfilters"},
    {ObjectType::Sensor, "sensor", "sensors"},
    {ObjectType::Film, "film", "films"},
    {ObjectType::Emitter, "emitter", "emitters"},
    {ObjectType::Sampler, "sampler", "samplers"},
    {ObjectType::Shape, "shape", "shapes"},
    {ObjectType::Texture, "texture", "textures"},
    {ObjectType::Volume, "volume", "volumes"},
    {ObjectType::Medium, "medium", "media"},
    {ObjectType::BSDF, "bsdf", "bsdfs"},
    {ObjectType::PhaseFunction, "phase", "phases"},
    {ObjectType::Integrator, "integrator", "integrators"},
};
} // namespace

const char *object_type_name(ObjectType type) {
    for (const auto &t : TYPE_NAMES)
        if (t.type == type) return t.name;
    return "unknown";
}

const char *object_type_folder(ObjectType type) {
    for (const auto &t : TYPE_NAMES)
        if (t.type == type) return t.folder;
    return "unknown";
}

ObjectType object_type_from_name(const std::string &name) {
    for (const auto &t : TYPE_NAMES)
        if (t.type != ObjectType::Unknown && name == t.name) return t.type;
    return ObjectType::Unknown;
}

} // namespace facet
