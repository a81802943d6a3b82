#pragma once

#include <facet/shape.h>

#include <mutex>
#include <vector>

namespace facet {

/// A group of shapes with its own Embree scene, placed in the world by `instance` shapes.
/// Declared in core so that the instance plugin can use it without including another plugin.
class ShapeGroup : public Shape {
public:
    explicit ShapeGroup(const Properties &props);
    ~ShapeGroup() override;

    BoundingBox3f bbox() const override { return m_bbox; }
    float surface_area() const override { return m_area; }
    /// Not attached to the scene by itself.
    RTCGeometry embree_geometry(RTCDevice) const override { return nullptr; }
    void compute_surface_interaction(const Ray &ray, float t, uint32_t prim_index,
                                     const Point2f &uv, SurfaceInteraction &si) const override;
    PositionSample sample_position(const Point2f &u) const override;
    std::string to_string() const override;

    /// The group's committed Embree scene (built on first use; geometry id i = shape i), with
    /// Embree's robust triangle test when `robust`. The first call fixes it: the scene builds its
    /// groups with its own `embree_use_robust_intersections` before it attaches their instances.
    RTCScene group_scene(RTCDevice device, bool robust = false) const;
    const Shape &shape(uint32_t geom_id) const { return *m_shapes[geom_id]; }
    const std::vector<std::shared_ptr<Shape>> &shapes() const { return m_shapes; }

private:
    std::vector<std::shared_ptr<Shape>> m_shapes;
    BoundingBox3f m_bbox;
    float m_area = 0.f;
    mutable std::mutex m_mutex;
    mutable RTCScene m_scene = nullptr;
};

/// Base class of the `instance` plugin: lets a group recognise (and refuse) a nested instance.
class InstanceShape : public Shape {
protected:
    InstanceShape() = default;
};

/// Most an instance's to_world may shrink (the largest entry of its inverse): the rays of an
/// instance are the world's rays under the inverse, and Embree asserts that they stay below
/// 1.8e18; with world coordinates below MaxSceneCoordinate this bound keeps them there.
constexpr float MaxInstanceShrink = 1e4f;

/// A shape that stands for other shapes (`merge`): the scene and shape groups hold its shapes()
/// in its place and never the list itself. Declared in core so the scene can expand it.
class ShapeList : public Shape {
public:
    ~ShapeList() override;
    const std::vector<std::shared_ptr<Shape>> &shapes() const { return m_shapes; }

    BoundingBox3f bbox() const override;
    float surface_area() const override;
    RTCGeometry embree_geometry(RTCDevice) const override { return nullptr; }
    void compute_surface_interaction(const Ray &ray, float t, uint32_t prim_index,
                                     const Point2f &uv, SurfaceInteraction &si) const override;
    PositionSample sample_position(const Point2f &u) const override;

protected:
    ShapeList() = default;
    std::vector<std::shared_ptr<Shape>> m_shapes;
};

/// The shapes `shape` stands for: a ShapeList's shapes, otherwise the shape itself.
std::vector<std::shared_ptr<Shape>> expand_shape(const std::shared_ptr<Shape> &shape);

} // namespace facet
