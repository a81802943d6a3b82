static const char *DOC = R"DOC(
# mesh_attribute: a named vertex or face attribute of the mesh that was hit

Reads an attribute stored on the mesh being shaded, as Mitsuba 3's `mesh_attribute` does: a
vertex attribute (`vertex_...`) is interpolated over each triangle with the barycentric
coordinates of the hit, a face attribute (`face_...`) is constant over the triangle. The value
is multiplied by `scale`. PLY files provide attributes from their extra properties (see `ply`:
`red, green, blue` give `vertex_color` / `face_color`, `tint_r, tint_g, tint_b` give
`vertex_tint_color`, a face `weight_0` gives `face_weight`); serialized meshes with vertex
colours have `vertex_color`.

Colour queries (a reflectance) accept attributes of 1 channel (a grey) or 3 channels; scalar
queries (a roughness, a blend weight, an opacity) need 1 channel. In the mono mode a colour
query of a 3-channel attribute gives its luminance. Naming an attribute that a
shape using the texture does not have is an error when the scene loads, naming the shape and
listing the attributes it has (shapes other than PLY and serialized meshes have none).

| Parameter | Type   | Default    | Description                                                 |
|-----------|--------|------------|-------------------------------------------------------------|
| name      | string | (required) | Attribute name, starting with `vertex_` or `face_`          |
| scale     | float  | 1          | Multiplies the attribute (e.g. 1/255 for 8-bit PLY colours) |

```xml
<bsdf type="diffuse">
    <texture type="mesh_attribute" name="reflectance">
        <string name="name" value="vertex_color"/>
        <float name="scale" value="0.003921569"/>
    </texture>
</bsdf>
```
)DOC";

#include <facet/mesh.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/spectral_upsampling.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

class MeshAttribute final : public Texture {
public:
    explicit MeshAttribute(const Properties &props) {
        m_name = props.get_string("name");
        if (m_name.rfind("vertex_", 0) != 0 && m_name.rfind("face_", 0) != 0)
            FACET_THROW_AT(props.location("name"),
                           "mesh_attribute: the attribute name \"{}\" must start with \"vertex_\" "
                           "or \"face_\"",
                           m_name);
        m_scale = float(props.get_float("scale", 1.0));
        m_mode = props.mode();
        if (!std::isfinite(m_scale))
            FACET_THROW_AT(props.location("scale"), "mesh_attribute: scale must be finite, got {}",
                           m_scale);
    }

    /// Called by the loader for every shape the texture shades: the attribute must exist there.
    void check_shape(const Shape &shape) const override {
        auto [mesh, a] = lookup(&shape);
        if (a->channels != 1 && a->channels != 3) throw_channels(*mesh, *a, "1 or 3 are needed");
    }

    Color3f eval(const SurfaceInteraction &si) const override {
        auto [mesh, a] = lookup(si.shape);
        float v[4];
        mesh->eval_attribute(*a, si, v);
        if (a->channels == 1) return Color3f(v[0] * m_scale);
        if (a->channels != 3) throw_channels(*mesh, *a, "a colour query needs 1 or 3");
        if (is_spectral(m_mode)) {
            // The interpolated colour's spectrum (as a reflectance: clamped to [0, 1]).
            const SigmoidPolynomial c = rgb_to_sigmoid(Color3f(v[0], v[1], v[2]));
            return c(si.wavelengths) * m_scale;
        }
        return in_mode(Color3f(v[0], v[1], v[2]) * m_scale, m_mode);
    }

    float eval_1(const SurfaceInteraction &si) const override {
        auto [mesh, a] = lookup(si.shape);
        if (a->channels != 1) throw_channels(*mesh, *a, "a scalar query needs 1");
        float v[4];
        mesh->eval_attribute(*a, si, v);
        return v[0] * m_scale;
    }

    /// The attribute's range is unknown until a mesh is hit; half the scale stands for it.
    Color3f mean() const override { return Color3f(0.5f * m_scale); }
    float max() const override { return m_scale; }

    std::string to_string() const override {
        return fmt::format("MeshAttribute[name = \"{}\", scale = {}]", m_name, m_scale);
    }

private:
    std::pair<const Mesh *, const Mesh::Attribute *> lookup(const Shape *shape) const {
        const Mesh *mesh = shape && shape->is_mesh() ? static_cast<const Mesh *>(shape) : nullptr;
        const Mesh::Attribute *a = mesh ? mesh->attribute(m_name) : nullptr;
        if (a) return {mesh, a};
        if (mesh)
            FACET_THROW("mesh_attribute: mesh \"{}\" has no attribute \"{}\" (its attributes: {})",
                        mesh->name(), m_name, mesh->attribute_names());
        FACET_THROW("mesh_attribute: the shape has no attribute \"{}\" (only ply and serialized "
                    "meshes carry attributes; this shape has none)",
                    m_name);
    }

    [[noreturn]] void throw_channels(const Mesh &mesh, const Mesh::Attribute &a,
                                     const char *need) const {
        FACET_THROW("mesh_attribute: attribute \"{}\" of mesh \"{}\" has {} channels, {}", m_name,
                    mesh.name(), a.channels, need);
    }

    std::string m_name;
    float m_scale = 1.f;
    ColourMode m_mode = ColourMode::RGB;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::MeshAttribute, Texture, "mesh_attribute",
                          "Named vertex or face attribute of the mesh being shaded", DOC,
                          ::facet::AllModes)
