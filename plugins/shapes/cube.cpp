static const char *DOC = R"DOC(
# cube

The cube [-1, 1]³ placed by `to_world`: 12 triangles over 24 vertices, so that each face has
its own normal (pointing outwards) and its own texture coordinates over [0, 1]².

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| flip_normals | boolean | false | Make the normals point inwards |
| to_world | transform | identity | Object-to-world transform |

```xml
<shape type="cube">
    <transform name="to_world">
        <scale value="0.5"/>
        <translate y="0.5"/>
    </transform>
    <bsdf type="diffuse"/>
</shape>
```
)DOC";

#include <facet/mesh.h>
#include <facet/plugin.h>

namespace facet {

class Cube final : public Mesh {
public:
    explicit Cube(const Properties &props) : Mesh(props) {
        bool flip_normals = props.get_bool("flip_normals", false);
        Transform to_world = props.get_transform("to_world", Transform());
        // Each face: outward normal n and in-plane axes s, t with s × t = n, so that the
        // corners listed counter-clockwise in (s, t) wind counter-clockwise around n.
        const Vector3f axes[6][3] = {
            {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{-1, 0, 0}, {0, 1, 0}, {0, 0, -1}},
            {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}}, {{0, 0, 1}, {0, 1, 0}, {-1, 0, 0}},
            {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}}, {{1, 0, 0}, {0, 0, 1}, {0, -1, 0}},
        };
        const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
        for (uint32_t f = 0; f < 6; ++f) {
            const Vector3f &s = axes[f][0], &t = axes[f][1], &n = axes[f][2];
            for (const auto &c : corners) {
                Point3f p = n + s * c[0] + t * c[1];
                m_positions.insert(m_positions.end(), {p.x, p.y, p.z});
                m_normals.insert(m_normals.end(), {n.x, n.y, n.z});
                m_uvs.insert(m_uvs.end(), {0.5f * (c[0] + 1.f), 0.5f * (c[1] + 1.f)});
            }
            uint32_t b = 4 * f;
            m_faces.insert(m_faces.end(), {b, b + 1, b + 2, b + 2, b + 3, b});
        }
        initialize(to_world, false, flip_normals);
    }
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Cube, Shape, "cube", "Cube [-1, 1]³ as 12 triangles", DOC,
                          ::facet::AllModes)
