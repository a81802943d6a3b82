static const char *DOC = R"DOC(
# instance: a placed copy of a shapegroup

Adds the shapes of a `shapegroup` to the scene under `to_world`, as an Embree instance of the
group's acceleration structure (one level of instancing: a shapegroup cannot contain an
instance). Instances cannot be emitters. `to_world` must be invertible and may shrink the group
by a factor of at most 10⁴.

| Parameter | Type       | Default  | Description                               |
|-----------|------------|----------|-------------------------------------------|
| (nested)  | shapegroup | —        | The group to place (usually a `ref`)      |
| to_world  | transform  | identity | Object-to-world transform of this copy    |

```xml
<shape type="instance">
    <ref id="tree"/>
    <transform name="to_world"> <rotate y="1" angle="45"/> </transform>
</shape>
```
)DOC";

#include <facet/plugin.h>
#include <facet/shapegroup.h>

namespace facet {

class Instance final : public InstanceShape {
public:
    explicit Instance(const Properties &props) {
        for (const auto &[name, obj] : props.objects()) {
            auto group = std::dynamic_pointer_cast<ShapeGroup>(obj);
            if (!group || m_group)
                FACET_THROW_AT(props.location(name),
                               "instance: expects exactly one nested shapegroup");
            m_group = std::move(group);
            props.mark_queried(name);
        }
        if (!m_group) FACET_THROW_AT(props.location(), "instance: no shapegroup given");
        m_to_world = props.get_transform("to_world", Transform());
        if (std::string why = transform_problem(m_to_world, MaxSceneCoordinate, MaxInstanceShrink);
            !why.empty())
            FACET_THROW_AT(props.location("to_world"), "instance: to_world {}", why);
        BoundingBox3f local = m_group->bbox();
        for (int i = 0; i < 8; ++i) {
            Point3f corner((i & 1) ? local.max.x : local.min.x, (i & 2) ? local.max.y : local.min.y,
                           (i & 4) ? local.max.z : local.min.z);
            m_bbox.expand(m_to_world.apply_point(corner));
        }
    }

    BoundingBox3f bbox() const override { return m_bbox; }
    float surface_area() const override { return m_group->surface_area(); }

    RTCGeometry embree_geometry(RTCDevice device) const override {
        RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(geom, m_group->group_scene(device));
        float m[12]; // 3x4 column major
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 3; ++r) m[c * 3 + r] = m_to_world.matrix.m[r][c];
        rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, m);
        rtcCommitGeometry(geom);
        return geom;
    }

    void compute_surface_interaction(const Ray &, float, uint32_t, const Point2f &,
                                     SurfaceInteraction &) const override {
        FACET_THROW("instance: hits must go through compute_instance_interaction");
    }

    void compute_instance_interaction(const Ray &ray, float t, uint32_t geom_id,
                                      uint32_t prim_index, const Point2f &uv,
                                      SurfaceInteraction &si) const override {
        // Same parametrisation t in object space: transform origin and (unnormalised) direction.
        Transform to_local = m_to_world.inverse();
        Ray local(to_local.apply_point(ray.o), to_local.apply_vector(ray.d), ray.mint, ray.maxt);
        m_group->shape(geom_id).compute_surface_interaction(local, t, prim_index, uv, si);
        si.p = m_to_world.apply_point(si.p);
        si.n = normalize(m_to_world.apply_normal(si.n));
        Vector3f n = normalize(m_to_world.apply_normal(si.sh_frame.n));
        Vector3f s = m_to_world.apply_vector(si.sh_frame.s);
        s = s - n * dot(n, s); // Gram-Schmidt: keep the frame orthonormal under shear/scale
        float sl = norm(s);
        if (sl > 1e-8f) {
            s /= sl;
            si.sh_frame = Frame(s, cross(n, s), n);
        } else {
            si.sh_frame = Frame(n);
        }
        si.dp_du = m_to_world.apply_vector(si.dp_du);
        si.dp_dv = m_to_world.apply_vector(si.dp_dv);
        si.wi = si.sh_frame.to_local(-normalize(ray.d));
        si.t = t;
    }

    PositionSample sample_position(const Point2f &) const override {
        FACET_THROW("instance: sampling positions on instances is not supported");
    }

    std::string to_string() const override {
        return fmt::format("Instance[{}, to_world={}]", m_group->to_string(),
                           m_to_world.to_string());
    }

private:
    std::shared_ptr<ShapeGroup> m_group;
    Transform m_to_world;
    BoundingBox3f m_bbox;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Instance, Shape, "instance",
                          "Placed copy of a shapegroup (Embree instance)", DOC, ::facet::AllModes)
