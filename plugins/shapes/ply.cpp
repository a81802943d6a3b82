static const char *DOC = R"DOC(
# ply

A triangle mesh read from a Stanford PLY file (ascii, binary_little_endian or
binary_big_endian). Read from the `vertex` element: positions `x, y, z`; normals `nx, ny, nz`;
texture coordinates `u, v` (also `s, t`, `texture_u, texture_v`, `texture_s, texture_t`); colours
`r, g, b` or `red, green, blue` (integer types are scaled to [0, 1]). From the `face` element: the
list `vertex_indices` (or `vertex_index`) of any integer type; polygons are split into triangle
fans. Other elements and properties are skipped. Without normals in the file (and with
`face_normals` off), smooth vertex normals are computed from the faces.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| filename | string | (required) | Path of the .ply file (resolved against the scene's folders) |
| face_normals | boolean | false | Ignore the vertex normals and shade with the flat face normals |
| flip_tex_coords | boolean | false | Use 1 - v as the v texture coordinate |
| flip_normals | boolean | false | Flip the normals (the front side becomes the back side) |
| to_world | transform | identity | Object-to-world transform |

```xml
<shape type="ply">
    <string name="filename" value="meshes/dragon.ply"/>
    <bsdf type="roughplastic"/>
</shape>
```
)DOC";

#include <facet/logger.h>
#include <facet/mesh.h>
#include <facet/plugin.h>
#include <facet/resolver.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <cstring>

namespace facet {

namespace {

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

bool parse_type(const std::string &name, PlyType &type) {
    static const struct {
        const char *name;
        PlyType type;
    } table[] = {
        {"char", PlyType::Int8},      {"int8", PlyType::Int8},       {"uchar", PlyType::UInt8},
        {"uint8", PlyType::UInt8},    {"short", PlyType::Int16},     {"int16", PlyType::Int16},
        {"ushort", PlyType::UInt16},  {"uint16", PlyType::UInt16},   {"int", PlyType::Int32},
        {"int32", PlyType::Int32},    {"uint", PlyType::UInt32},     {"uint32", PlyType::UInt32},
        {"float", PlyType::Float32},  {"float32", PlyType::Float32}, {"double", PlyType::Float64},
        {"float64", PlyType::Float64}};
    for (const auto &e : table)
        if (name == e.name) {
            type = e.type;
            return true;
        }
    return false;
}

size_t type_size(PlyType t) {
    switch (t) {
    case PlyType::Int8:
    case PlyType::UInt8:
        return 1;
    case PlyType::Int16:
    case PlyType::UInt16:
        return 2;
    case PlyType::Int32:
    case PlyType::UInt32:
    case PlyType::Float32:
        return 4;
    case PlyType::Float64:
        return 8;
    }
    return 0;
}

bool is_integer(PlyType t) { return t != PlyType::Float32 && t != PlyType::Float64; }

/// Largest value of an integer type (colours are scaled by it).
double type_max(PlyType t) {
    switch (t) {
    case PlyType::Int8:
        return 127.0;
    case PlyType::UInt8:
        return 255.0;
    case PlyType::Int16:
        return 32767.0;
    case PlyType::UInt16:
        return 65535.0;
    case PlyType::Int32:
        return 2147483647.0;
    case PlyType::UInt32:
        return 4294967295.0;
    default:
        return 1.0;
    }
}

struct PlyProperty {
    std::string name;
    PlyType type = PlyType::Float32;
    bool is_list = false;
    PlyType count_type = PlyType::UInt8;
};

struct PlyElement {
    std::string name;
    size_t count = 0;
    std::vector<PlyProperty> props;
};

enum class PlyFormat { Ascii, BinaryLittle, BinaryBig };

/// Reads values one at a time from the body of the file, in any of the three encodings.
class PlyReader {
public:
    PlyReader(const std::string &name, const char *begin, const char *end, PlyFormat format,
              size_t header_lines)
        : m_name(name), m_cur(begin), m_end(end), m_format(format), m_line(header_lines) {}

    double read(PlyType type, const char *what) {
        if (m_format == PlyFormat::Ascii) return read_ascii(what);
        size_t size = type_size(type);
        if (size_t(m_end - m_cur) < size)
            FACET_THROW("{}: the file ends early, while reading {}", m_name, what);
        unsigned char b[8];
        std::memcpy(b, m_cur, size);
        m_cur += size;
        if (m_format == PlyFormat::BinaryBig) std::reverse(b, b + size);
        switch (type) {
        case PlyType::Int8:
            return double(int8_t(b[0]));
        case PlyType::UInt8:
            return double(b[0]);
        case PlyType::Int16: {
            int16_t v;
            std::memcpy(&v, b, 2);
            return v;
        }
        case PlyType::UInt16: {
            uint16_t v;
            std::memcpy(&v, b, 2);
            return v;
        }
        case PlyType::Int32: {
            int32_t v;
            std::memcpy(&v, b, 4);
            return v;
        }
        case PlyType::UInt32: {
            uint32_t v;
            std::memcpy(&v, b, 4);
            return v;
        }
        case PlyType::Float32: {
            float v;
            std::memcpy(&v, b, 4);
            return v;
        }
        case PlyType::Float64: {
            double v;
            std::memcpy(&v, b, 8);
            return v;
        }
        }
        return 0.0;
    }

    /// In ascii files every element sits on its own line.
    void end_element() {
        if (m_format != PlyFormat::Ascii) return;
        while (m_cur < m_end && *m_cur != '\n') ++m_cur;
        if (m_cur < m_end) ++m_cur;
        ++m_line;
    }

    std::string where() const {
        return m_format == PlyFormat::Ascii ? fmt::format("{}:{}", m_name, m_line + 1) : m_name;
    }

private:
    double read_ascii(const char *what) {
        while (m_cur < m_end && (*m_cur == ' ' || *m_cur == '\t' || *m_cur == '\r')) ++m_cur;
        if (m_cur >= m_end || *m_cur == '\n')
            FACET_THROW("{}:{}: the {} ends early, while reading {}", m_name, m_line + 1,
                        m_cur >= m_end ? "file" : "line", what);
        const char *b = m_cur;
        if (*b == '+') ++b;
        double value;
        auto [ptr, ec] = std::from_chars(b, m_end, value);
        if (ec != std::errc() || ptr == b)
            FACET_THROW("{}:{}: expected a number for {}", m_name, m_line + 1, what);
        m_cur = ptr;
        return value;
    }

    const std::string &m_name;
    const char *m_cur, *m_end;
    PlyFormat m_format;
    size_t m_line;
};

std::vector<std::string> split_words(const std::string &line) {
    std::vector<std::string> words;
    size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        size_t j = i;
        while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
        if (j > i) words.push_back(line.substr(i, j - i));
        i = j;
    }
    return words;
}

} // namespace

class Ply final : public Mesh {
public:
    explicit Ply(const Properties &props) : Mesh(props) {
        std::string filename = props.get_string("filename");
        bool face_normals = props.get_bool("face_normals", false);
        bool flip_tex_coords = props.get_bool("flip_tex_coords", false);
        bool flip_normals = props.get_bool("flip_normals", false);
        Transform to_world = props.get_transform("to_world", Transform());
        m_name = filename;

        std::string data = read_file(file_resolver().resolve(filename), "ply");
        load(filename, data, flip_tex_coords);
        initialize(to_world, face_normals, flip_normals);
        if (!face_normals && !has_vertex_normals()) recompute_vertex_normals();
        FACET_LOG(Debug, "ply: \"{}\": {} vertices, {} triangles", filename, vertex_count(),
                  face_count());
    }

private:
    void load(const std::string &name, const std::string &data, bool flip_tex_coords) {
        // --- Header --------------------------------------------------------------------------
        size_t pos = 0, line_no = 0;
        auto next_line = [&](std::string &line) {
            if (pos >= data.size()) FACET_THROW("{}: the header ends without end_header", name);
            size_t eol = data.find('\n', pos);
            if (eol == std::string::npos) eol = data.size();
            line = data.substr(pos, eol - pos);
            if (!line.empty() && line.back() == '\r') line.pop_back();
            pos = eol + 1;
            ++line_no;
        };
        std::string line;
        next_line(line);
        if (line != "ply") FACET_THROW("{}: not a PLY file (the first line is not \"ply\")", name);
        PlyFormat format = PlyFormat::Ascii;
        bool have_format = false;
        std::vector<PlyElement> elements;
        for (;;) {
            next_line(line);
            auto w = split_words(line);
            if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
            if (w[0] == "end_header") break;
            if (w[0] == "format") {
                if (w.size() < 2) FACET_THROW("{}:{}: incomplete format line", name, line_no);
                if (w[1] == "ascii")
                    format = PlyFormat::Ascii;
                else if (w[1] == "binary_little_endian")
                    format = PlyFormat::BinaryLittle;
                else if (w[1] == "binary_big_endian")
                    format = PlyFormat::BinaryBig;
                else
                    FACET_THROW("{}:{}: unknown format \"{}\" (expected ascii, "
                                "binary_little_endian or binary_big_endian)",
                                name, line_no, w[1]);
                have_format = true;
            } else if (w[0] == "element") {
                if (w.size() < 3) FACET_THROW("{}:{}: incomplete element line", name, line_no);
                PlyElement el;
                el.name = w[1];
                auto [p, ec] = std::from_chars(w[2].data(), w[2].data() + w[2].size(), el.count);
                if (ec != std::errc() || p != w[2].data() + w[2].size())
                    FACET_THROW("{}:{}: bad element count \"{}\"", name, line_no, w[2]);
                elements.push_back(std::move(el));
            } else if (w[0] == "property") {
                if (elements.empty())
                    FACET_THROW("{}:{}: property before any element", name, line_no);
                PlyProperty prop;
                if (w.size() >= 5 && w[1] == "list") {
                    prop.is_list = true;
                    if (!parse_type(w[2], prop.count_type) || !parse_type(w[3], prop.type))
                        FACET_THROW("{}:{}: unknown list types \"{} {}\"", name, line_no, w[2],
                                    w[3]);
                    if (!is_integer(prop.count_type))
                        FACET_THROW("{}:{}: list counts must be integers", name, line_no);
                    prop.name = w[4];
                } else if (w.size() >= 3) {
                    if (!parse_type(w[1], prop.type))
                        FACET_THROW("{}:{}: unknown property type \"{}\"", name, line_no, w[1]);
                    prop.name = w[2];
                } else {
                    FACET_THROW("{}:{}: incomplete property line", name, line_no);
                }
                elements.back().props.push_back(prop);
            } else {
                FACET_THROW("{}:{}: unexpected header line \"{}\"", name, line_no, line);
            }
        }
        if (!have_format) FACET_THROW("{}: the header has no format line", name);

        // --- Body ----------------------------------------------------------------------------
        PlyReader reader(name, data.data() + std::min(pos, data.size()), data.data() + data.size(),
                         format, line_no);
        bool have_vertices = false, have_faces = false;
        for (const PlyElement &el : elements) {
            if (el.name == "vertex") {
                read_vertices(el, reader, flip_tex_coords);
                have_vertices = true;
            } else if (el.name == "face") {
                read_faces(el, reader);
                have_faces = true;
            } else {
                for (size_t i = 0; i < el.count; ++i) {
                    for (const auto &prop : el.props) skip(prop, reader);
                    reader.end_element();
                }
            }
        }
        if (!have_vertices) FACET_THROW("{}: no vertex element", name);
        if (!have_faces) FACET_THROW("{}: no face element", name);
    }

    static void skip(const PlyProperty &prop, PlyReader &reader) {
        if (!prop.is_list) {
            reader.read(prop.type, prop.name.c_str());
            return;
        }
        double count = reader.read(prop.count_type, prop.name.c_str());
        for (int64_t k = 0; k < int64_t(count); ++k) reader.read(prop.type, prop.name.c_str());
    }

    void read_vertices(const PlyElement &el, PlyReader &reader, bool flip_tex_coords) {
        // Where each property goes: 0-2 position, 3-5 normal, 6-7 uv, 8-10 colour, -1 skipped.
        std::vector<int> slot(el.props.size(), -1);
        int found[11] = {};
        auto assign = [&](size_t i, int s) {
            slot[i] = s;
            found[s] = 1;
        };
        PlyType color_type = PlyType::Float32;
        for (size_t i = 0; i < el.props.size(); ++i) {
            const auto &p = el.props[i];
            if (p.is_list) continue;
            const std::string &n = p.name;
            if (n == "x")
                assign(i, 0);
            else if (n == "y")
                assign(i, 1);
            else if (n == "z")
                assign(i, 2);
            else if (n == "nx")
                assign(i, 3);
            else if (n == "ny")
                assign(i, 4);
            else if (n == "nz")
                assign(i, 5);
            else if (n == "u" || n == "s" || n == "texture_u" || n == "texture_s")
                assign(i, 6);
            else if (n == "v" || n == "t" || n == "texture_v" || n == "texture_t")
                assign(i, 7);
            else if (n == "r" || n == "red") {
                assign(i, 8);
                color_type = p.type;
            } else if (n == "g" || n == "green")
                assign(i, 9);
            else if (n == "b" || n == "blue")
                assign(i, 10);
        }
        if (!(found[0] && found[1] && found[2]))
            FACET_THROW("{}: the vertex element lacks x, y or z", m_name);
        bool normals = found[3] && found[4] && found[5];
        bool uvs = found[6] && found[7];
        bool colors = found[8] && found[9] && found[10];
        double color_scale = is_integer(color_type) ? 1.0 / type_max(color_type) : 1.0;

        size_t n = el.count;
        m_positions.resize(3 * n);
        if (normals) m_normals.resize(3 * n);
        if (uvs) m_uvs.resize(2 * n);
        if (colors) m_colors.resize(3 * n);
        double values[11];
        for (size_t v = 0; v < n; ++v) {
            for (size_t i = 0; i < el.props.size(); ++i) {
                if (slot[i] < 0 || el.props[i].is_list)
                    skip(el.props[i], reader);
                else
                    values[slot[i]] = reader.read(el.props[i].type, el.props[i].name.c_str());
            }
            reader.end_element();
            for (int k = 0; k < 3; ++k) m_positions[3 * v + k] = float(values[k]);
            if (normals)
                for (int k = 0; k < 3; ++k) m_normals[3 * v + k] = float(values[3 + k]);
            if (uvs) {
                m_uvs[2 * v] = float(values[6]);
                m_uvs[2 * v + 1] = flip_tex_coords ? 1.f - float(values[7]) : float(values[7]);
            }
            if (colors)
                for (int k = 0; k < 3; ++k)
                    m_colors[3 * v + k] = float(values[8 + k] * color_scale);
        }
    }

    void read_faces(const PlyElement &el, PlyReader &reader) {
        int list = -1;
        for (size_t i = 0; i < el.props.size(); ++i)
            if (el.props[i].is_list &&
                (el.props[i].name == "vertex_indices" || el.props[i].name == "vertex_index"))
                list = int(i);
        if (list < 0) FACET_THROW("{}: the face element has no vertex_indices list", m_name);
        if (!is_integer(el.props[size_t(list)].type))
            FACET_THROW("{}: vertex_indices must be integers", m_name);
        m_faces.reserve(3 * el.count);
        std::vector<uint32_t> polygon;
        for (size_t f = 0; f < el.count; ++f) {
            for (size_t i = 0; i < el.props.size(); ++i) {
                const auto &prop = el.props[i];
                if (int(i) != list) {
                    skip(prop, reader);
                    continue;
                }
                double count = reader.read(prop.count_type, "a face's vertex count");
                if (count < 3)
                    FACET_THROW("{}: face {} has {} vertices (at least 3 needed)", reader.where(),
                                f, count);
                polygon.clear();
                for (int64_t k = 0; k < int64_t(count); ++k) {
                    double idx = reader.read(prop.type, "a vertex index");
                    if (idx < 0 || idx >= 4294967295.0)
                        FACET_THROW("{}: face {} has a bad vertex index {}", reader.where(), f,
                                    idx);
                    polygon.push_back(uint32_t(idx));
                }
                for (size_t k = 1; k + 1 < polygon.size(); ++k)
                    m_faces.insert(m_faces.end(), {polygon[0], polygon[k], polygon[k + 1]});
            }
            reader.end_element();
        }
    }
};

} // namespace facet

FACET_EXPORT_PLUGIN(facet::Ply, Shape, "ply", "Triangle mesh from a PLY file", DOC)
