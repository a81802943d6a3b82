static const char *DOC = R"DOC(
# obj

A triangle mesh read from a Wavefront OBJ file. Polygons are split into triangle fans; vertices
are shared between faces when they use the same position, texture coordinate and normal. Groups,
objects and materials are ignored: the whole file becomes one mesh. Without normals in the file
(and with `face_normals` off), smooth vertex normals are computed from the faces.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| filename | string | (required) | Path of the .obj file (resolved against the scene's folders) |
| face_normals | boolean | false | Ignore the vertex normals and shade with the flat face normals |
| flip_tex_coords | boolean | true | Use 1 - v as the v texture coordinate (OBJ's v axis points up) |
| flip_normals | boolean | false | Flip the normals (the front side becomes the back side) |
| to_world | transform | identity | Object-to-world transform |

```xml
<shape type="obj">
    <string name="filename" value="meshes/bunny.obj"/>
    <transform name="to_world"> <scale value="2"/> </transform>
    <bsdf type="diffuse"/>
</shape>
```
)DOC";

#include <facet/logger.h>
#include <facet/mesh.h>
#include <facet/plugin.h>
#include <facet/resolver.h>

#include <charconv>
#include <cstdio>
#include <cstring>
#include <string_view>

namespace facet {

namespace {

/// The whole file in memory; parsing then walks it with pointers (no stream per token).
class ObjParser {
public:
    ObjParser(const std::string &path, const std::string &data) : m_path(path), m_data(data) {}

    struct Corner {
        int64_t v, vt, vn; // zero-based; -1 when absent
    };

    std::vector<float> positions, texcoords, normals;
    std::vector<Corner> unique; ///< one per mesh vertex
    std::vector<uint32_t> faces;

    void parse() {
        const char *p = m_data.data(), *end = p + m_data.size();
        std::vector<uint32_t> polygon;
        while (p < end) {
            ++m_line;
            const char *eol = static_cast<const char *>(std::memchr(p, '\n', size_t(end - p)));
            if (!eol) eol = end;
            m_cur = p;
            m_end = eol;
            parse_line(polygon);
            p = eol + 1;
        }
    }

private:
    [[noreturn]] void fail(const std::string &msg) const {
        FACET_THROW("{}:{}: {}", m_path, m_line, msg);
    }

    void skip_space() {
        while (m_cur < m_end && (*m_cur == ' ' || *m_cur == '\t' || *m_cur == '\r')) ++m_cur;
    }

    std::string_view word() {
        skip_space();
        const char *b = m_cur;
        while (m_cur < m_end && *m_cur != ' ' && *m_cur != '\t' && *m_cur != '\r') ++m_cur;
        return std::string_view(b, size_t(m_cur - b));
    }

    float number(const char *what) {
        skip_space();
        const char *b = m_cur;
        if (b < m_end && *b == '+') ++b;
        float value;
        auto [ptr, ec] = std::from_chars(b, m_end, value);
        if (ec != std::errc() || ptr == b)
            fail(fmt::format("expected a number for {}, found \"{}\"", what,
                             std::string(m_cur, std::min<size_t>(size_t(m_end - m_cur), 20))));
        m_cur = ptr;
        return value;
    }

    bool at_end_of_data() {
        skip_space();
        return m_cur >= m_end || *m_cur == '#';
    }

    /// One-based (or negative, relative) OBJ index to zero-based.
    int64_t resolve(int64_t index, size_t count, const char *what) const {
        int64_t r = index > 0 ? index - 1 : int64_t(count) + index;
        if (index == 0 || r < 0 || r >= int64_t(count))
            fail(
                fmt::format("{} index {} is out of range ({} defined so far)", what, index, count));
        return r;
    }

    int64_t index_field(const char *what) {
        const char *b = m_cur;
        if (b < m_end && *b == '+') ++b;
        int64_t value;
        auto [ptr, ec] = std::from_chars(b, m_end, value);
        if (ec != std::errc() || ptr == b) fail(fmt::format("malformed {} index in face", what));
        m_cur = ptr;
        return value;
    }

    void parse_line(std::vector<uint32_t> &polygon) {
        std::string_view key = word();
        if (key.empty() || key[0] == '#') return;
        if (key == "v") {
            for (int k = 0; k < 3; ++k) positions.push_back(number("a vertex position"));
        } else if (key == "vt") {
            float u = number("a texture coordinate");
            float v = at_end_of_data() ? 0.f : number("a texture coordinate");
            texcoords.push_back(u);
            texcoords.push_back(v);
        } else if (key == "vn") {
            for (int k = 0; k < 3; ++k) normals.push_back(number("a normal"));
        } else if (key == "f") {
            polygon.clear();
            while (!at_end_of_data()) {
                Corner c{-1, -1, -1};
                c.v = resolve(index_field("vertex"), positions.size() / 3, "vertex");
                if (m_cur < m_end && *m_cur == '/') {
                    ++m_cur;
                    if (m_cur < m_end && *m_cur != '/')
                        c.vt = resolve(index_field("texture coordinate"), texcoords.size() / 2,
                                       "texture coordinate");
                    if (m_cur < m_end && *m_cur == '/') {
                        ++m_cur;
                        c.vn = resolve(index_field("normal"), normals.size() / 3, "normal");
                    }
                }
                if (m_cur < m_end && *m_cur != ' ' && *m_cur != '\t' && *m_cur != '\r' &&
                    *m_cur != '#')
                    fail("malformed face vertex (expected v, v/vt, v//vn or v/vt/vn)");
                polygon.push_back(vertex_id(c));
            }
            if (polygon.size() < 3)
                fail(fmt::format("a face needs at least 3 vertices, found {}", polygon.size()));
            for (size_t i = 1; i + 1 < polygon.size(); ++i)
                faces.insert(faces.end(), {polygon[0], polygon[i], polygon[i + 1]});
        }
        // Everything else (o, g, s, usemtl, mtllib, l, p, ...) does not affect the geometry.
    }

    /// Mesh vertex for a (v, vt, vn) triple, shared between the faces that use the same triple.
    uint32_t vertex_id(const Corner &c) {
        size_t v = size_t(c.v);
        if (v >= m_first.size()) m_first.resize(positions.size() / 3, uint32_t(-1));
        for (uint32_t id = m_first[v]; id != uint32_t(-1); id = m_next[id])
            if (unique[id].vt == c.vt && unique[id].vn == c.vn) return id;
        uint32_t id = uint32_t(unique.size());
        unique.push_back(c);
        m_next.push_back(m_first[v]);
        m_first[v] = id;
        return id;
    }

    const std::string &m_path;
    const std::string &m_data;
    const char *m_cur = nullptr, *m_end = nullptr;
    size_t m_line = 0;
    std::vector<uint32_t> m_first, m_next; ///< per position: chain of the vertices using it
};

} // namespace

class Obj final : public Mesh {
public:
    explicit Obj(const Properties &props) : Mesh(props) {
        std::string filename = props.get_string("filename");
        bool face_normals = props.get_bool("face_normals", false);
        bool flip_tex_coords = props.get_bool("flip_tex_coords", true);
        bool flip_normals = props.get_bool("flip_normals", false);
        Transform to_world = props.get_transform("to_world", Transform());
        m_name = filename;

        std::string path = file_resolver().resolve(filename);
        std::string data = read_file(path, "obj");
        ObjParser parser(filename, data);
        parser.parse();
        if (parser.faces.empty()) FACET_THROW("{}: the file has no faces", filename);

        bool any_uv = false, any_normal = false;
        for (const auto &c : parser.unique) {
            any_uv |= c.vt >= 0;
            any_normal |= c.vn >= 0;
        }
        size_t n = parser.unique.size();
        m_positions.resize(3 * n);
        if (any_uv) m_uvs.assign(2 * n, 0.f);
        if (any_normal && !face_normals) m_normals.assign(3 * n, 0.f);
        for (size_t i = 0; i < n; ++i) {
            const auto &c = parser.unique[i];
            for (int k = 0; k < 3; ++k)
                m_positions[3 * i + k] = parser.positions[3 * size_t(c.v) + k];
            if (any_uv && c.vt >= 0) {
                float u = parser.texcoords[2 * size_t(c.vt)],
                      v = parser.texcoords[2 * size_t(c.vt) + 1];
                m_uvs[2 * i] = u;
                m_uvs[2 * i + 1] = flip_tex_coords ? 1.f - v : v;
            }
            if (!m_normals.empty() && c.vn >= 0)
                for (int k = 0; k < 3; ++k)
                    m_normals[3 * i + k] = parser.normals[3 * size_t(c.vn) + k];
        }
        m_faces = std::move(parser.faces);
        initialize(to_world, face_normals, flip_normals);
        if (!face_normals && !has_vertex_normals()) recompute_vertex_normals();
        FACET_LOG(Debug, "obj: \"{}\": {} vertices, {} triangles", filename, vertex_count(),
                  face_count());
    }
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Obj, Shape, "obj", "Triangle mesh from a Wavefront OBJ file", DOC,
                          ::facet::AllModes)
