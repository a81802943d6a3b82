static const char *DOC = R"DOC(
# mesh_attribute: per-vertex data of the mesh that was hit

Reads an attribute stored on the mesh being shaded and interpolates it over each triangle
with the barycentric coordinates of the hit. `vertex_color` is the per-vertex colour of a PLY
(`red`, `green`, `blue` properties) or serialized mesh. On a shape without the attribute the
texture is black and a warning is logged once.

| Parameter | Type   | Default | Description                                         |
|-----------|--------|---------|-----------------------------------------------------|
| name      | string | —       | Attribute name; `vertex_color` is supported         |
| scale     | float  | 1       | Multiplies the attribute                            |

```xml
<bsdf type="diffuse">
    <texture type="mesh_attribute" name="reflectance">
        <string name="name" value="vertex_color"/>
    </texture>
</bsdf>
```
)DOC";

#include <facet/mesh.h>
#include <facet/plugin.h>
#include <facet/texture.h>

#include <atomic>

namespace facet {

class MeshAttribute final : public Texture {
public:
    explicit MeshAttribute(const Properties &props) {
        m_name = props.get_string("name");
        if (m_name != "vertex_color")
            FACET_THROW_AT(props.location("name"),
                           "mesh_attribute: unsupported attribute \"{}\" (supported: vertex_color)",
                           m_name);
        m_scale = float(props.get_float("scale", 1.0));
    }

    Color3f eval(const SurfaceInteraction &si) const override {
        const Mesh *mesh =
            si.shape && si.shape->is_mesh() ? static_cast<const Mesh *>(si.shape) : nullptr;
        if (!mesh || !mesh->has_vertex_colors()) {
            if (!m_warned.exchange(true))
                FACET_LOG(Warn, "mesh_attribute: the shape that was hit has no \"{}\"; using black",
                          m_name);
            return Color3f(0.f);
        }
        const auto &f = mesh->faces();
        const auto &c = mesh->colors();
        uint32_t i0 = f[3 * si.prim_index], i1 = f[3 * si.prim_index + 1],
                 i2 = f[3 * si.prim_index + 2];
        // Barycentrics of the hit point from the triangle's world-space vertices.
        Point3f p0 = mesh->vertex_position(i0), p1 = mesh->vertex_position(i1),
                p2 = mesh->vertex_position(i2);
        Vector3f e1 = p1 - p0, e2 = p2 - p0, v = si.p - p0;
        float d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2), dv1 = dot(v, e1),
              dv2 = dot(v, e2);
        float denom = d11 * d22 - d12 * d12;
        float b1 = denom != 0.f ? (d22 * dv1 - d12 * dv2) / denom : 0.f;
        float b2 = denom != 0.f ? (d11 * dv2 - d12 * dv1) / denom : 0.f;
        b1 = clamp(b1, 0.f, 1.f);
        b2 = clamp(b2, 0.f, 1.f - b1);
        float b0 = 1.f - b1 - b2;
        auto col = [&](uint32_t i) { return Color3f(c[3 * i], c[3 * i + 1], c[3 * i + 2]); };
        return (col(i0) * b0 + col(i1) * b1 + col(i2) * b2) * m_scale;
    }

    Color3f mean() const override { return Color3f(0.5f * m_scale); }
    std::string to_string() const override { return fmt::format("MeshAttribute[\"{}\"]", m_name); }

private:
    std::string m_name;
    float m_scale = 1.f;
    mutable std::atomic<bool> m_warned{false};
};

} // namespace facet

FACET_EXPORT_PLUGIN(facet::MeshAttribute, Texture, "mesh_attribute",
                    "Per-vertex attribute (vertex colours) of the mesh being shaded", DOC)
