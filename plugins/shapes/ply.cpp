static const char *DOC = R"DOC(
# ply

A triangle mesh read from a Stanford PLY file (ascii, binary_little_endian or
binary_big_endian). Read from the `vertex` element: positions `x, y, z`; normals `nx, ny, nz`;
texture coordinates `u, v` (also `s, t`, `texture_u, texture_v`, `texture_s, texture_t`). From the
`face` element: the list `vertex_indices` (or `vertex_index`) of any integer type; polygons are
split into triangle fans. Without normals in the file (and with `face_normals` off), smooth vertex
normals are computed from the faces. Other elements are skipped.

Every other property of the vertex and face elements becomes a named mesh attribute, read with
the `mesh_attribute` texture, grouped as Mitsuba 3 groups them:
- bare `r, g, b` or `red, green, blue` (optionally with `a` / `alpha`): `vertex_color` on
  vertices, `face_color` on faces;
- consecutive properties `<name>_<c>` whose one-letter suffixes run through one family,
  `x y z w`, `r g b a`, `0 1 2 3` or `1 2 3 4`, with 1 or 3 members: `vertex_<name>` /
  `face_<name>`, and `vertex_<name>_color` / `face_<name>_color` for the `r g b` family
  (`color_0..2` gives `vertex_color`, `tint_r, tint_g, tint_b` gives `vertex_tint_color`, a face
  property `weight_0` gives `face_weight`).
Integer properties are kept as they are (a `uchar red` of 255 is 255, not 1; Mitsuba 3.8 does
the same and warns): scale them with `mesh_attribute`'s `scale`. Properties that fit no group
are skipped with a warning.

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

#include <facet/checked.h>
#include <facet/logger.h>
#include <facet/mesh.h>
#include <facet/plugin.h>
#include <facet/resolver.h>

#include <sys/mman.h>
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <string_view>
#include <unistd.h>
#include <unordered_set>

namespace facet {

namespace {

/// A regular file's bytes mapped read-only: the parser reads them where the page cache holds
/// them, without copying the file into memory first. Empty when the file cannot be mapped
/// (missing, not a regular file, empty): the caller then reads it with read_file(), which says
/// why it cannot. The file must not be truncated while it is mapped (the mapping is released
/// before the constructor returns).
class MappedFile {
public:
    explicit MappedFile(const std::string &path) {
        const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd < 0) return;
        struct stat st;
        if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
            void *p =
                ::mmap(nullptr, size_t(st.st_size), PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
            if (p != MAP_FAILED) {
                m_data = static_cast<const char *>(p);
                m_size = size_t(st.st_size);
            }
        }
        ::close(fd);
    }
    ~MappedFile() {
        if (m_data) ::munmap(const_cast<char *>(m_data), m_size);
    }
    MappedFile(const MappedFile &) = delete;
    MappedFile &operator=(const MappedFile &) = delete;
    bool mapped() const { return m_data != nullptr; }
    std::string_view view() const { return {m_data, m_size}; }

private:
    const char *m_data = nullptr;
    size_t m_size = 0;
};

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

    bool is_ascii() const { return m_format == PlyFormat::Ascii; }
    /// Binary in this machine's byte order: values can be copied as they are stored.
    bool is_native_binary() const {
        const uint16_t one = 1;
        unsigned char low;
        std::memcpy(&low, &one, 1);
        return m_format == (low ? PlyFormat::BinaryLittle : PlyFormat::BinaryBig);
    }
    /// The next `size` bytes of a binary file (checked to be there), skipped over.
    const char *take(size_t size, const char *what) {
        if (size_t(m_end - m_cur) < size)
            FACET_THROW("{}: the file ends early, while reading {}", m_name, what);
        const char *p = m_cur;
        m_cur += size;
        return p;
    }
    size_t remaining() const { return size_t(m_end - m_cur); }

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

        const std::string path = file_resolver().resolve(filename);
        {
            MappedFile file(path);
            if (file.mapped()) {
                load(filename, file.view(), flip_tex_coords);
            } else {
                const std::string data = read_file(path, "ply");
                load(filename, data, flip_tex_coords);
            }
        }
        initialize(to_world, face_normals, flip_normals);
        if (!face_normals && !has_vertex_normals()) recompute_vertex_normals();
        FACET_LOG(Debug, "ply: \"{}\": {} vertices, {} triangles", filename, vertex_count(),
                  face_count());
    }

private:
    void load(const std::string &name, std::string_view data, bool flip_tex_coords) {
        // --- Header --------------------------------------------------------------------------
        size_t pos = 0, line_no = 0;
        auto next_line = [&](std::string &line) {
            if (pos >= data.size()) FACET_THROW("{}: the header ends without end_header", name);
            size_t eol = data.find('\n', pos);
            if (eol == std::string_view::npos) eol = data.size();
            line.assign(data.substr(pos, eol - pos));
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
            if ((el.name == "vertex" && have_vertices) || (el.name == "face" && have_faces))
                FACET_THROW("{}: the header declares more than one {} element", name, el.name);
            if (el.name == "vertex") {
                read_vertices(el, reader, flip_tex_coords);
                have_vertices = true;
            } else if (el.name == "face") {
                read_faces(el, reader);
                have_faces = true;
            } else {
                check_count(el, reader);
                if (el.props.empty() && !reader.is_ascii()) continue;
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
        size_t count = list_count(prop, reader, prop.name.c_str());
        for (size_t k = 0; k < count; ++k) reader.read(prop.type, prop.name.c_str());
    }

    /// The length of a list, read with its count type: a whole number, and no more entries
    /// than the rest of the file can hold (so a loop over them is bounded by the file).
    static size_t list_count(const PlyProperty &prop, PlyReader &reader, const char *what) {
        double count = reader.read(prop.count_type, what);
        double most =
            double(reader.remaining()) / double(reader.is_ascii() ? 1 : type_size(prop.type));
        if (!(count >= 0.0) || count != std::floor(count) || count > most)
            FACET_THROW("{}: bad list count {} for {} (a whole number of entries that the rest "
                        "of the file holds)",
                        reader.where(), count, what);
        return size_t(count);
    }

    /// Warnings of one kind are logged once, with their count and the first few names they
    /// concern: a header may declare thousands of properties that all fail the same way.
    class WarningTally {
    public:
        explicit WarningTally(const std::string &file) : m_file(file) {}
        /// `many` says what several of them are ("list properties of element vertex ignored");
        /// `single()` gives the message of one.
        template <typename Single>
        void add(const std::string &many, const std::string &name, Single single) {
            for (Kind &k : m_kinds)
                if (k.many == many) {
                    ++k.count;
                    if (k.names.size() < 3) k.names.push_back(name);
                    return;
                }
            m_kinds.push_back(Kind{many, single(), 1, {name}});
        }
        void log() const {
            for (const Kind &k : m_kinds) {
                if (k.count == 1) {
                    FACET_LOG(Warn, "{}", k.single);
                    continue;
                }
                std::string names;
                for (const std::string &n : k.names)
                    names += (names.empty() ? "\"" : ", \"") + n + "\"";
                FACET_LOG(Warn, "{}: {} {}: {}{}", m_file, k.count, k.many, names,
                          k.count > k.names.size() ? ", ..." : "");
            }
        }

    private:
        struct Kind {
            std::string many, single;
            size_t count;
            std::vector<std::string> names;
        };
        const std::string &m_file;
        std::vector<Kind> m_kinds;
    };

    /// A named attribute made of some of an element's properties (one per channel).
    struct AttributeGroup {
        std::string name;
        std::vector<size_t> props; ///< property indices, in channel order
        std::vector<float> data;
    };

    /**
     * Mitsuba's grouping of the properties outside the reserved set into named attributes
     * (`prefix` is "vertex_" or "face_"): bare r, g, b (or red, green, blue; with a or alpha)
     * give `<prefix>color`; otherwise consecutive properties `<name>_<c>` with one-letter
     * suffixes running through one family, x y z w, r g b a, 0 1 2 3 or 1 2 3 4, form
     * `<prefix><name>` (with `_color` appended for the r g b a family); a group needs 1 or 3
     * members. Properties that fit no group are skipped with a warning, as Mitsuba does.
     */
    std::vector<AttributeGroup> group_attributes(const PlyElement &el, const std::string &prefix,
                                                 std::vector<char> &reserved) const {
        std::vector<AttributeGroup> groups;
        WarningTally warnings(m_name);
        auto find = [&](const char *n) -> int {
            for (size_t i = 0; i < el.props.size(); ++i)
                if (!el.props[i].is_list && el.props[i].name == n) return int(i);
            return -1;
        };
        auto integer_warning = [&](const AttributeGroup &g) {
            if (g.props.size() >= 3 && is_integer(el.props[g.props[0]].type))
                warnings.add("mesh attributes have integer fields: color attributes are expected "
                             "to be in the [0, 1] range (the values are used as they are)",
                             g.name, [&] {
                                 return fmt::format("{}: mesh attribute \"{}\" has integer fields: "
                                                    "color attributes are expected to be in the "
                                                    "[0, 1] range (the values are used as they "
                                                    "are)",
                                                    m_name, g.name);
                             });
        };

        const char *bare[2][4] = {{"r", "g", "b", "a"}, {"red", "green", "blue", "alpha"}};
        for (auto &names : bare) {
            int r = find(names[0]), g = find(names[1]), b = find(names[2]), a = find(names[3]);
            if (r < 0 || g < 0 || b < 0) continue;
            AttributeGroup group{prefix + "color", {size_t(r), size_t(g), size_t(b)}, {}};
            if (a >= 0) group.props.push_back(size_t(a));
            integer_warning(group);
            groups.push_back(std::move(group));
            break;
        }
        for (auto &names : bare)
            for (const char *n : names)
                if (int i = find(n); i >= 0) reserved[size_t(i)] = 1;

        static const char *families[4] = {"xr01", "yg12", "zb23", "wa34"};
        std::unordered_set<std::string> seen;
        AttributeGroup current;
        std::string current_prefix;
        int family = -1;
        auto flush = [&]() {
            if (family < 0) return;
            size_t n = current.props.size();
            if (n == 1 || n == 3) {
                current.name = prefix + current_prefix + (family == 1 ? "_color" : "");
                integer_warning(current);
                seen.insert(current_prefix);
                groups.push_back(std::move(current));
            } else {
                warnings.add("attributes ignored (1 or 3 fields are needed)",
                             prefix + current_prefix, [&] {
                                 return fmt::format("{}: attribute \"{}{}\" has {} fields (1 or 3 "
                                                    "are needed); ignored",
                                                    m_name, prefix, current_prefix, n);
                             });
            }
            current = AttributeGroup();
            family = -1;
        };
        for (size_t i = 0; i < el.props.size(); ++i) {
            const PlyProperty &p = el.props[i];
            if (reserved[i]) continue;
            if (p.is_list) {
                warnings.add(fmt::format("list properties of element {} ignored", el.name), p.name,
                             [&] {
                                 return fmt::format("{}: list property \"{}\" of element {} "
                                                    "ignored",
                                                    m_name, p.name, el.name);
                             });
                continue;
            }
            size_t pos = p.name.find_last_of('_');
            if (pos == std::string::npos || pos + 2 != p.name.size()) {
                warnings.add(fmt::format("properties of element {} ignored (attributes are "
                                         "named <name>_<one-letter suffix>)",
                                         el.name),
                             p.name, [&] {
                                 return fmt::format("{}: property \"{}\" of element {} ignored "
                                                    "(attributes are named <name>_<one-letter "
                                                    "suffix>)",
                                                    m_name, p.name, el.name);
                             });
                flush();
                continue;
            }
            std::string name = p.name.substr(0, pos);
            char suffix = p.name[pos + 1];
            if (family >= 0 && name != current_prefix) flush();
            if (family < 0) {
                if (seen.count(name)) {
                    warnings.add("properties ignored (their attribute was seen before)", p.name,
                                 [&] {
                                     return fmt::format("{}: attribute \"{}\" seen before: "
                                                        "property \"{}\" ignored",
                                                        m_name, name, p.name);
                                 });
                    continue;
                }
                const char *f = std::strchr(families[0], suffix);
                if (!f || suffix == 0) {
                    warnings.add("properties ignored (an attribute's first suffix is one of x, "
                                 "r, 0, 1)",
                                 p.name, [&] {
                                     return fmt::format("{}: property \"{}\" ignored (an "
                                                        "attribute's first suffix is one of x, "
                                                        "r, 0, 1)",
                                                        m_name, p.name);
                                 });
                    continue;
                }
                family = int(f - families[0]);
                current_prefix = name;
                current.props.push_back(i);
                continue;
            }
            size_t level = current.props.size();
            if (level >= 4 || families[level][family] != suffix) {
                warnings.add("attributes ignored (invalid suffix sequences)", current_prefix, [&] {
                    return fmt::format("{}: attribute \"{}\" has an invalid suffix sequence; "
                                       "ignored",
                                       m_name, current_prefix);
                });
                seen.insert(current_prefix);
                current = AttributeGroup();
                family = -1;
                continue;
            }
            current.props.push_back(i);
        }
        flush();
        warnings.log();
        for (const AttributeGroup &g : groups)
            for (size_t i : g.props) reserved[i] = 1;
        return groups;
    }

    /// A count from the header that the rest of the file cannot hold is an error (before any
    /// allocation): every element takes at least one byte per property, and in binary files
    /// exactly the sizes of its scalar properties plus the counts of its lists.
    void check_count(const PlyElement &el, const PlyReader &reader) const {
        size_t per_element = 0;
        for (const PlyProperty &p : el.props)
            per_element += reader.is_ascii() ? 1 : type_size(p.is_list ? p.count_type : p.type);
        size_t need = 0;
        if (!checked_mul(el.count, std::max<size_t>(per_element, 1), need) ||
            need > reader.remaining() + (reader.is_ascii() || per_element == 0 ? 1 : 0))
            FACET_THROW("{}: the header declares {} {} elements, more than the file holds", m_name,
                        el.count, el.name);
    }

    void read_vertices(const PlyElement &el, PlyReader &reader, bool flip_tex_coords) {
        // Where each property goes: 0-2 position, 3-5 normal, 6-7 uv, -1 elsewhere.
        std::vector<int> slot(el.props.size(), -1);
        std::vector<char> reserved(el.props.size(), 0);
        int found[8] = {};
        auto assign = [&](size_t i, int s) {
            slot[i] = s;
            found[s] = 1;
            reserved[i] = 1;
        };
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
        }
        if (!(found[0] && found[1] && found[2]))
            FACET_THROW("{}: the vertex element lacks x, y or z", m_name);
        bool normals = found[3] && found[4] && found[5];
        bool uvs = found[6] && found[7];
        std::vector<AttributeGroup> groups = group_attributes(el, "vertex_", reserved);
        check_count(el, reader);

        // check_count() bounds n by the file size, so 3 n cannot wrap; the limit still applies.
        size_t n = el.count;
        allocation_bytes(n, 3 * sizeof(float), m_name, "vertex positions");
        // initialize() appends a float of padding for Embree: room for it now, not a copy then.
        m_positions.reserve(3 * n + 1);
        m_positions.resize(3 * n);
        if (normals) m_normals.resize(3 * n);
        if (uvs) m_uvs.resize(2 * n);
        for (AttributeGroup &g : groups) g.data.reserve(g.props.size() * n);
        std::vector<double> values(el.props.size(), 0.0);
        double sv[8] = {};
        // The common binary layout, floats only in the machine's byte order, is copied from the
        // file's rows straight into the arrays (the general reader below decodes value by value).
        const bool raw_floats =
            reader.is_native_binary() &&
            std::all_of(el.props.begin(), el.props.end(), [](const PlyProperty &p) {
                return !p.is_list && p.type == PlyType::Float32;
            });
        if (raw_floats) {
            // check_count() made sure the file holds n rows of `stride` bytes.
            const size_t stride = el.props.size() * sizeof(float);
            const char *rows = reader.take(n * stride, "the vertices");
            // The byte offset in a row of each slot's float (the last property of a name wins,
            // as in the general reader).
            size_t offset[8] = {};
            for (size_t i = 0; i < el.props.size(); ++i)
                if (slot[i] >= 0) offset[slot[i]] = i * sizeof(float);
            auto get = [](const char *p) {
                float f;
                std::memcpy(&f, p, sizeof(float));
                return f;
            };
            for (size_t v = 0; v < n; ++v) {
                const char *row = rows + v * stride;
                for (int k = 0; k < 3; ++k) m_positions[3 * v + k] = get(row + offset[k]);
                if (normals)
                    for (int k = 0; k < 3; ++k) m_normals[3 * v + k] = get(row + offset[3 + k]);
                if (uvs) {
                    m_uvs[2 * v] = get(row + offset[6]);
                    const float t = get(row + offset[7]);
                    m_uvs[2 * v + 1] = flip_tex_coords ? 1.f - t : t;
                }
                for (AttributeGroup &g : groups)
                    for (size_t i : g.props) g.data.push_back(get(row + i * sizeof(float)));
            }
            for (AttributeGroup &g : groups)
                add_attribute(g.name, uint32_t(g.props.size()), std::move(g.data));
            return;
        }
        for (size_t v = 0; v < n; ++v) {
            {
                for (size_t i = 0; i < el.props.size(); ++i) {
                    if (el.props[i].is_list)
                        skip(el.props[i], reader);
                    else
                        values[i] = reader.read(el.props[i].type, el.props[i].name.c_str());
                    if (slot[i] >= 0) sv[slot[i]] = values[i];
                }
            }
            reader.end_element();
            for (int k = 0; k < 3; ++k) m_positions[3 * v + k] = float(sv[k]);
            if (normals)
                for (int k = 0; k < 3; ++k) m_normals[3 * v + k] = float(sv[3 + k]);
            if (uvs) {
                m_uvs[2 * v] = float(sv[6]);
                m_uvs[2 * v + 1] = flip_tex_coords ? 1.f - float(sv[7]) : float(sv[7]);
            }
            // Integer properties are kept raw (0..255 for uchar), as Mitsuba 3.8 does.
            for (AttributeGroup &g : groups)
                for (size_t i : g.props) g.data.push_back(float(values[i]));
        }
        for (AttributeGroup &g : groups)
            add_attribute(g.name, uint32_t(g.props.size()), std::move(g.data));
    }

    /// Faces of the common binary layout (a uchar count and 32-bit indices in the machine's byte
    /// order, nothing else) written straight into m_faces, triangles as they are and polygons
    /// as fans. The checks are those of the general reader in read_faces().
    void read_raw_faces(size_t count, bool signed_indices, PlyReader &reader) {
        // A triangle per face to begin with (check_count() bounded the count by the file);
        // polygons with more corners grow the array.
        m_faces.resize(3 * count);
        size_t out = 0;
        auto bad_index = [&](size_t f, uint32_t index) {
            if (signed_indices && int32_t(index) < 0)
                FACET_THROW("{}: face {} has a bad vertex index {}", reader.where(), f,
                            int32_t(index));
            FACET_THROW("{}: face {} has a bad vertex index {}", reader.where(), f, index);
        };
        // A negative int32 index reads as a huge uint32: out of range in initialize().
        const uint32_t limit = signed_indices ? 0x7fffffffu : 0xfffffffeu;
        uint32_t polygon[255];
        for (size_t f = 0; f < count; ++f) {
            const size_t corners = size_t(uint8_t(*reader.take(1, "a face's vertex count")));
            if (corners < 3)
                FACET_THROW("{}: face {} has {} vertices (at least 3 needed)", reader.where(), f,
                            corners);
            const char *idx = reader.take(corners * sizeof(uint32_t), "a vertex index");
            std::memcpy(polygon, idx, corners * sizeof(uint32_t));
            for (size_t k = 0; k < corners; ++k)
                if (polygon[k] > limit) bad_index(f, polygon[k]);
            const size_t need = out + 3 * (corners - 2);
            if (need > m_faces.size()) m_faces.resize(std::max(need, 2 * m_faces.size()));
            for (size_t k = 1; k + 1 < corners; ++k) {
                m_faces[out++] = polygon[0];
                m_faces[out++] = polygon[k];
                m_faces[out++] = polygon[k + 1];
            }
        }
        m_faces.resize(out);
    }

    void read_faces(const PlyElement &el, PlyReader &reader) {
        int list = -1;
        std::vector<char> reserved(el.props.size(), 0);
        for (size_t i = 0; i < el.props.size(); ++i)
            if (el.props[i].is_list &&
                (el.props[i].name == "vertex_indices" || el.props[i].name == "vertex_index")) {
                list = int(i);
                reserved[i] = 1;
            }
        if (list < 0) FACET_THROW("{}: the face element has no vertex_indices list", m_name);
        if (!is_integer(el.props[size_t(list)].type))
            FACET_THROW("{}: vertex_indices must be integers", m_name);
        std::vector<AttributeGroup> groups = group_attributes(el, "face_", reserved);
        check_count(el, reader);

        // A triangle per face to begin with; polygons with more corners grow it with the data.
        m_faces.reserve(allocation_bytes(el.count, 3 * sizeof(uint32_t), m_name, "faces") /
                        sizeof(uint32_t));
        std::vector<uint32_t> polygon;
        std::vector<double> values(el.props.size(), 0.0);
        // The common binary layout, only a uchar count and 32-bit indices in the machine's byte
        // order, is copied a face at a time (the general reader below decodes value by value).
        const PlyType index_type = el.props[size_t(list)].type;
        const bool raw_indices = reader.is_native_binary() && el.props.size() == 1 &&
                                 el.props[0].count_type == PlyType::UInt8 &&
                                 (index_type == PlyType::Int32 || index_type == PlyType::UInt32);
        if (raw_indices) {
            read_raw_faces(el.count, index_type == PlyType::Int32, reader);
            return;
        }
        for (size_t f = 0; f < el.count; ++f) {
            for (size_t i = 0; i < el.props.size(); ++i) {
                const auto &prop = el.props[i];
                if (int(i) != list) {
                    if (prop.is_list)
                        skip(prop, reader);
                    else
                        values[i] = reader.read(prop.type, prop.name.c_str());
                    continue;
                }
                size_t count = list_count(prop, reader, "a face's vertex count");
                if (count < 3)
                    FACET_THROW("{}: face {} has {} vertices (at least 3 needed)", reader.where(),
                                f, count);
                polygon.clear();
                for (size_t k = 0; k < count; ++k) {
                    double idx = reader.read(prop.type, "a vertex index");
                    // Written so that NaN fails too; ascii files may hold non-integers.
                    if (!(idx >= 0.0 && idx < 4294967295.0) || idx != std::floor(idx))
                        FACET_THROW("{}: face {} has a bad vertex index {}", reader.where(), f,
                                    idx);
                    polygon.push_back(uint32_t(idx));
                }
            }
            reader.end_element();
            // Polygons become triangle fans; each triangle carries the face's attributes.
            for (size_t k = 1; k + 1 < polygon.size(); ++k) {
                m_faces.insert(m_faces.end(), {polygon[0], polygon[k], polygon[k + 1]});
                for (AttributeGroup &g : groups)
                    for (size_t i : g.props) g.data.push_back(float(values[i]));
            }
        }
        for (AttributeGroup &g : groups)
            add_attribute(g.name, uint32_t(g.props.size()), std::move(g.data));
    }
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Ply, Shape, "ply", "Triangle mesh from a PLY file", DOC,
                          ::facet::AllModes)
