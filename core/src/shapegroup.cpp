#include <facet/logger.h>
#include <facet/shapegroup.h>

namespace facet {

ShapeGroup::ShapeGroup(const Properties &props) {
    for (const auto &[name, obj] : props.objects()) {
        auto shape = std::dynamic_pointer_cast<Shape>(obj);
        if (!shape)
            FACET_THROW_AT(props.location(name),
                           "shapegroup: only shapes can be nested (\"{}\" is a {})", name,
                           object_type_name(obj->type()));
        if (dynamic_cast<const ShapeGroup *>(shape.get()))
            FACET_THROW_AT(props.location(name), "shapegroup: shape groups cannot be nested");
        // Embree (as built here) traverses one level of instances and aborts on a second.
        if (dynamic_cast<const InstanceShape *>(shape.get()))
            FACET_THROW_AT(props.location(name),
                           "shapegroup: a shape group cannot contain an instance (nested "
                           "instancing is not supported; put the inner group's shapes in this "
                           "group instead)");
        if (std::string why = bounds_problem(shape->bbox()); !why.empty())
            FACET_THROW_AT(props.location(name), "shapegroup: the bounding box of \"{}\" {}", name,
                           why);
        props.mark_queried(name);
        for (auto &part : expand_shape(shape)) {
            if (part->emitter())
                FACET_THROW_AT(props.location(name),
                               "shapegroup: emitters inside a shape group are not supported");
            m_bbox.expand(part->bbox());
            m_area += part->surface_area();
            m_shapes.push_back(std::move(part));
        }
    }
    if (m_shapes.empty()) FACET_THROW_AT(props.location(), "shapegroup: the group is empty");
}

ShapeGroup::~ShapeGroup() {
    if (m_scene) rtcReleaseScene(m_scene);
}

RTCScene ShapeGroup::group_scene(RTCDevice device, bool robust) const {
    std::lock_guard<std::mutex> lock(m_mutex); // scene construction only, not a hot path
    if (m_scene) return m_scene;
    m_scene = rtcNewScene(device);
    rtcSetSceneFlags(m_scene, robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
    rtcSetSceneBuildQuality(m_scene, RTC_BUILD_QUALITY_HIGH);
    for (size_t i = 0; i < m_shapes.size(); ++i) {
        RTCGeometry geom = m_shapes[i]->embree_geometry(device);
        if (!geom) continue;
        rtcAttachGeometryByID(m_scene, geom, unsigned(i));
        rtcReleaseGeometry(geom);
    }
    rtcCommitScene(m_scene);
    return m_scene;
}

void ShapeGroup::compute_surface_interaction(const Ray &, float, uint32_t, const Point2f &,
                                             SurfaceInteraction &) const {
    FACET_THROW("shapegroup: a shape group is only visible through instances");
}

PositionSample ShapeGroup::sample_position(const Point2f &) const {
    FACET_THROW("shapegroup: sampling positions on a shape group is not supported");
}

std::string ShapeGroup::to_string() const {
    return fmt::format("ShapeGroup[{} shapes]", m_shapes.size());
}

ShapeList::~ShapeList() = default;

BoundingBox3f ShapeList::bbox() const {
    BoundingBox3f box;
    for (const auto &shape : m_shapes) box.expand(shape->bbox());
    return box;
}

float ShapeList::surface_area() const {
    float area = 0.f;
    for (const auto &shape : m_shapes) area += shape->surface_area();
    return area;
}

void ShapeList::compute_surface_interaction(const Ray &, float, uint32_t, const Point2f &,
                                            SurfaceInteraction &) const {
    FACET_THROW("{}: a shape list is only visible through the shapes it stands for", to_string());
}

PositionSample ShapeList::sample_position(const Point2f &) const {
    FACET_THROW("{}: a shape list is only visible through the shapes it stands for", to_string());
}

std::vector<std::shared_ptr<Shape>> expand_shape(const std::shared_ptr<Shape> &shape) {
    if (auto list = dynamic_cast<const ShapeList *>(shape.get())) return list->shapes();
    return {shape};
}

} // namespace facet
