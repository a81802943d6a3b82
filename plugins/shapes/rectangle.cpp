static const char *DOC = R"DOC(
# rectangle

The square [-1, 1]² in the z = 0 plane with its normal along +z, placed by `to_world`; two
triangles.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| flip_normals | boolean | false | Make the normal point along -z (object space) |
| to_world | transform | identity | Object-to-world transform |

Texture coordinates run from (0, 0) at (-1, -1) to (1, 1) at (1, 1).

```xml
<shape type="rectangle">
    <transform name="to_world">
        <scale x="2" y="3"/>
        <rotate x="1" angle="-90"/>
    </transform>
    <bsdf type="diffuse"/>
</shape>
```
)DOC";

#include <facet/mesh.h>
#include <facet/plugin.h>

namespace facet {

class Rectangle final : public Mesh {
public:
    explicit Rectangle(const Properties &props) : Mesh(props) {
        bool flip_normals = props.get_bool("flip_normals", false);
        Transform to_world = props.get_transform("to_world", Transform());
        m_positions = {-1.f, -1.f, 0.f, 1.f, -1.f, 0.f, 1.f, 1.f, 0.f, -1.f, 1.f, 0.f};
        m_uvs = {0.f, 0.f, 1.f, 0.f, 1.f, 1.f, 0.f, 1.f};
        // Counter-clockwise seen from +z, so the face normal is +z.
        m_faces = {0, 1, 2, 2, 3, 0};
        initialize(to_world, false, flip_normals);
    }

    /// uv ∈ [0, 1]² spans the square once: p = c₀ + u·(c₁ − c₀) + v·(c₃ − c₀) from the corners
    /// at uv (0, 0), (1, 0) and (0, 1); the normal is that of its faces.
    bool eval_parameterization(const Point2f &uv, PositionSample &ps,
                               float &area_per_uv) const override {
        if (!(uv.x >= 0.f && uv.x <= 1.f && uv.y >= 0.f && uv.y <= 1.f)) return false;
        const Point3f c0 = vertex_position(0), c1 = vertex_position(1), c3 = vertex_position(3);
        const Vector3f du = c1 - c0, dv = c3 - c0;
        const Vector3f cross_uv = cross(du, dv);
        area_per_uv = norm(cross_uv);
        if (!(area_per_uv > 0.f) || !std::isfinite(area_per_uv)) return false;
        ps.p = c0 + du * uv.x + dv * uv.y;
        ps.n = Normal3f(cross_uv / area_per_uv);
        if (flip_normals()) ps.n = -ps.n;
        ps.uv = uv;
        return true;
    }
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Rectangle, Shape, "rectangle",
                          "Square [-1, 1]² in the z = 0 plane", DOC, ::facet::AllModes)
