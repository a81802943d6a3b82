static const char *DOC = R"DOC(
# serialized: Mitsuba's compressed binary mesh format

Loads one mesh of a `.serialized` file (format versions 3 and 4): a header per mesh followed by
a zlib stream with the vertex data and triangles, and a table of mesh offsets at the end of
the file. `shape_index` selects the mesh.

| Parameter    | Type      | Default  | Description                                              |
|--------------|-----------|----------|----------------------------------------------------------|
| filename     | string    | —        | Path of the .serialized file (required)                  |
| shape_index  | integer   | 0        | Which mesh of the file to load                           |
| face_normals | boolean   | false    | Ignore vertex normals and shade with face normals        |
| flip_normals | boolean   | false    | Flip the surface orientation                             |
| to_world     | transform | identity | Object-to-world transform                                |

```xml
<shape type="serialized">
    <string name="filename" value="matpreview.serialized"/>
    <integer name="shape_index" value="1"/>
</shape>
```
)DOC";

#include <facet/mesh.h>
#include <facet/plugin.h>
#include <facet/resolver.h>

#include <cstring>
#include <fstream>
#include <vector>
#include <zlib.h>

namespace facet {

namespace {

constexpr uint16_t FormatId = 0x041C;
enum : uint32_t {
    HasNormals = 0x0001,
    HasUVs = 0x0002,
    HasColors = 0x0008,
    FaceNormals = 0x0010,
    SinglePrecision = 0x1000,
    DoublePrecision = 0x2000,
};

/// Reads little-endian values from the inflated stream with bounds checks.
class Reader {
public:
    Reader(const std::vector<uint8_t> &data, const std::string &file)
        : m_data(data), m_file(file) {}
    template <typename T> T read() {
        T value;
        need(sizeof(T));
        std::memcpy(&value, m_data.data() + m_pos, sizeof(T));
        m_pos += sizeof(T);
        return value;
    }
    std::string read_cstring() {
        std::string s;
        for (;;) {
            char c = char(read<uint8_t>());
            if (c == 0) return s;
            s += c;
        }
    }
    /// Reads `count` reals stored as float or double into `out` as floats.
    void read_reals(std::vector<float> &out, size_t count, bool dbl) {
        need(count * (dbl ? 8 : 4));
        out.resize(count);
        for (size_t i = 0; i < count; ++i) {
            if (dbl) {
                double d;
                std::memcpy(&d, m_data.data() + m_pos + 8 * i, 8);
                out[i] = float(d);
            } else {
                std::memcpy(&out[i], m_data.data() + m_pos + 4 * i, 4);
            }
        }
        m_pos += count * (dbl ? 8 : 4);
    }
    void skip(size_t bytes) {
        need(bytes);
        m_pos += bytes;
    }

private:
    void need(size_t bytes) const {
        if (m_pos + bytes > m_data.size())
            FACET_THROW("serialized: \"{}\" is truncated (mesh data ends after {} bytes)", m_file,
                        m_data.size());
    }
    const std::vector<uint8_t> &m_data;
    const std::string &m_file;
    size_t m_pos = 0;
};

std::vector<uint8_t> inflate_all(const uint8_t *src, size_t size, const std::string &file) {
    std::vector<uint8_t> out;
    z_stream zs{};
    if (inflateInit(&zs) != Z_OK) FACET_THROW("serialized: zlib initialisation failed");
    zs.next_in = const_cast<Bytef *>(src);
    zs.avail_in = uInt(size);
    uint8_t buffer[1 << 16];
    int ret;
    do {
        zs.next_out = buffer;
        zs.avail_out = sizeof(buffer);
        ret = inflate(&zs, Z_NO_FLUSH);
        if (ret != Z_OK && ret != Z_STREAM_END) {
            inflateEnd(&zs);
            FACET_THROW("serialized: \"{}\" has a corrupt compressed stream ({})", file,
                        zs.msg ? zs.msg : "truncated data");
        }
        out.insert(out.end(), buffer, buffer + (sizeof(buffer) - zs.avail_out));
        if (ret != Z_STREAM_END && zs.avail_in == 0) {
            inflateEnd(&zs);
            FACET_THROW("serialized: \"{}\" is truncated (compressed stream ends early)", file);
        }
    } while (ret != Z_STREAM_END);
    inflateEnd(&zs);
    return out;
}

} // namespace

class SerializedMesh final : public Mesh {
public:
    explicit SerializedMesh(const Properties &props) : Mesh(props) {
        std::string filename = props.get_string("filename");
        std::string path = file_resolver().resolve(filename);
        m_name = filename;
        int64_t index = props.get_int("shape_index", 0);
        bool face_normals = props.get_bool("face_normals", false);
        bool flip = props.get_bool("flip_normals", false);
        Transform to_world = props.get_transform("to_world", Transform());

        std::ifstream in(path, std::ios::binary);
        if (!in) FACET_THROW_AT(props.location("filename"), "serialized: cannot open \"{}\"", path);
        std::vector<uint8_t> file((std::istreambuf_iterator<char>(in)),
                                  std::istreambuf_iterator<char>());
        // Like obj and ply: smooth normals unless the scene or the file asks for face normals.
        bool file_face_normals = load(file, path, index, props);
        initialize(to_world, face_normals, flip);
        if (!face_normals && !file_face_normals && !has_vertex_normals())
            recompute_vertex_normals();
    }

    std::string to_string() const override {
        return fmt::format("SerializedMesh[\"{}\", {} vertices, {} triangles]", m_name,
                           vertex_count(), face_count());
    }

private:
    /// Reads mesh `index`; returns whether the file asks for face normals.
    bool load(const std::vector<uint8_t> &file, const std::string &path, int64_t index,
              const Properties &props) {
        if (file.size() < 8) FACET_THROW("serialized: \"{}\" is too small to be a mesh file", path);
        uint16_t id, version;
        std::memcpy(&id, file.data(), 2);
        std::memcpy(&version, file.data() + 2, 2);
        if (id != FormatId)
            FACET_THROW("serialized: \"{}\" is not a serialized mesh (bad format id 0x{:04x})",
                        path, id);
        if (version != 3 && version != 4)
            FACET_THROW("serialized: \"{}\" has format version {}; versions 3 and 4 are supported",
                        path, version);

        // The dictionary at the end: offsets (uint64 in v4, uint32 in v3) then a uint32 count.
        uint32_t count;
        std::memcpy(&count, file.data() + file.size() - 4, 4);
        size_t offset_size = version == 4 ? 8 : 4;
        if (count == 0 || size_t(count) * offset_size + 4 > file.size())
            FACET_THROW("serialized: \"{}\" has a corrupt mesh table ({} meshes)", path, count);
        if (index < 0 || index >= int64_t(count))
            FACET_THROW_AT(props.location("shape_index"),
                           "serialized: shape_index {} is out of range: \"{}\" holds {} mesh(es)",
                           index, path, count);
        size_t table = file.size() - 4 - size_t(count) * offset_size;
        auto offset_of = [&](size_t i) -> size_t {
            if (version == 4) {
                uint64_t o;
                std::memcpy(&o, file.data() + table + 8 * i, 8);
                return size_t(o);
            }
            uint32_t o;
            std::memcpy(&o, file.data() + table + 4 * i, 4);
            return size_t(o);
        };
        size_t begin = offset_of(size_t(index));
        size_t end = size_t(index) + 1 < count ? offset_of(size_t(index) + 1) : table;
        if (begin + 4 > end || end > file.size())
            FACET_THROW("serialized: \"{}\" has a corrupt offset for mesh {}", path, index);
        uint16_t mesh_id, mesh_version;
        std::memcpy(&mesh_id, file.data() + begin, 2);
        std::memcpy(&mesh_version, file.data() + begin + 2, 2);
        if (mesh_id != FormatId || (mesh_version != 3 && mesh_version != 4))
            FACET_THROW("serialized: \"{}\": mesh {} has a bad header", path, index);

        std::vector<uint8_t> data = inflate_all(file.data() + begin + 4, end - begin - 4, path);
        Reader r(data, path);
        uint32_t flags = r.read<uint32_t>();
        if (mesh_version == 4) m_name = r.read_cstring();
        uint64_t nv = r.read<uint64_t>(), nf = r.read<uint64_t>();
        bool dbl = (flags & DoublePrecision) != 0;
        if (nv == 0 || nf == 0) FACET_THROW("serialized: \"{}\": mesh {} is empty", path, index);
        // Guard against absurd counts before allocating.
        size_t real = dbl ? 8 : 4;
        size_t need = size_t(nv) * 3 * real + size_t(nf) * 12;
        if (need > data.size())
            FACET_THROW("serialized: \"{}\": mesh {} claims {} vertices and {} triangles, more "
                        "than its data holds",
                        path, index, nv, nf);
        r.read_reals(m_positions, size_t(nv) * 3, dbl);
        if (flags & HasNormals) r.read_reals(m_normals, size_t(nv) * 3, dbl);
        if (flags & HasUVs) r.read_reals(m_uvs, size_t(nv) * 2, dbl);
        if (flags & HasColors) r.read_reals(m_colors, size_t(nv) * 3, dbl);
        m_faces.resize(size_t(nf) * 3);
        for (auto &f : m_faces) f = r.read<uint32_t>();
        if (flags & FaceNormals) m_normals.clear();
        return (flags & FaceNormals) != 0;
    }
};

} // namespace facet

FACET_EXPORT_PLUGIN(facet::SerializedMesh, Shape, "serialized",
                    "Triangle mesh from Mitsuba's compressed .serialized format", DOC)
