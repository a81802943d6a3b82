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

#include <facet/checked.h>
#include <facet/logger.h>
#include <facet/mesh.h>
#include <facet/plugin.h>
#include <facet/resolver.h>

#include <algorithm>
#include <cstring>
#include <limits>
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

/**
 * The zlib stream of one mesh, inflated on demand straight into the arrays that hold it. Memory
 * then grows with the data the stream really holds, not with the counts of its header (a few
 * bytes can claim 10^12 vertices, and deflate expands up to ~1000:1).
 */
class InflateStream {
public:
    InflateStream(const uint8_t *src, size_t size, const std::string &file)
        : m_src(src), m_left(size), m_file(file) {
        if (inflateInit(&m_zs) != Z_OK) FACET_THROW("serialized: zlib initialisation failed");
    }
    ~InflateStream() { inflateEnd(&m_zs); }
    InflateStream(const InflateStream &) = delete;
    InflateStream &operator=(const InflateStream &) = delete;

    /// Exactly `bytes` bytes into `dst`, or an error (truncated or corrupt stream).
    void read(void *dst, size_t bytes) {
        auto *out = static_cast<uint8_t *>(dst);
        while (bytes > 0) {
            if (m_done) truncated();
            if (m_zs.avail_in == 0 && m_left > 0) {
                uInt chunk = uInt(std::min<size_t>(m_left, size_t(1) << 30));
                m_zs.next_in = const_cast<Bytef *>(m_src);
                m_zs.avail_in = chunk;
                m_src += chunk;
                m_left -= chunk;
            }
            uInt want = uInt(std::min<size_t>(bytes, size_t(1) << 30));
            m_zs.next_out = out;
            m_zs.avail_out = want;
            int ret = inflate(&m_zs, Z_NO_FLUSH);
            size_t got = want - m_zs.avail_out;
            out += got;
            bytes -= got;
            if (ret == Z_STREAM_END) {
                m_done = true;
            } else if (ret == Z_BUF_ERROR && m_zs.avail_in == 0 && m_left == 0) {
                truncated();
            } else if (ret != Z_OK) {
                FACET_THROW("serialized: \"{}\" has a corrupt compressed stream ({})", m_file,
                            m_zs.msg ? m_zs.msg : zError(ret));
            }
        }
    }
    template <typename T> T read() {
        T value;
        read(&value, sizeof(T));
        return value;
    }
    std::string read_cstring() {
        std::string s;
        for (;;) {
            char c = char(read<uint8_t>());
            if (c == 0) return s;
            if (s.size() >= 4096)
                FACET_THROW("serialized: \"{}\": the mesh name runs past 4096 bytes", m_file);
            s += c;
        }
    }
    /// `count` reals stored as float or double, appended to `out` as floats chunk by chunk.
    void read_reals(std::vector<float> &out, size_t count, bool dbl, const char *what) {
        allocation_bytes(count, sizeof(float), m_file, what);
        out.clear();
        constexpr size_t chunk = size_t(1) << 16;
        std::vector<double> buffer;
        for (size_t done = 0; done < count;) {
            size_t n = std::min(chunk, count - done);
            out.resize(done + n);
            if (dbl) {
                buffer.resize(n);
                read(buffer.data(), n * sizeof(double));
                for (size_t i = 0; i < n; ++i) out[done + i] = float(buffer[i]);
            } else {
                read(out.data() + done, n * sizeof(float));
            }
            done += n;
        }
    }
    void read_indices(std::vector<uint32_t> &out, size_t count) {
        allocation_bytes(count, sizeof(uint32_t), m_file, "triangle indices");
        out.clear();
        constexpr size_t chunk = size_t(1) << 16;
        for (size_t done = 0; done < count;) {
            size_t n = std::min(chunk, count - done);
            out.resize(done + n);
            read(out.data() + done, n * sizeof(uint32_t));
            done += n;
        }
    }

private:
    [[noreturn]] void truncated() const {
        FACET_THROW("serialized: \"{}\" is truncated (the compressed mesh data ends early)",
                    m_file);
    }
    z_stream m_zs{};
    const uint8_t *m_src;
    size_t m_left;
    const std::string &m_file;
    bool m_done = false;
};

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

        std::string file;
        try {
            file = read_file(path, "serialized");
        } catch (const Error &e) {
            FACET_THROW_AT(props.location("filename"), "{}", e.message());
        }
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
    bool load(const std::string &bytes, const std::string &path, int64_t index,
              const Properties &props) {
        const auto *data = reinterpret_cast<const uint8_t *>(bytes.data());
        const size_t size = bytes.size();
        if (size < 8) FACET_THROW("serialized: \"{}\" is too small to be a mesh file", path);
        uint16_t id, version;
        std::memcpy(&id, data, 2);
        std::memcpy(&version, data + 2, 2);
        if (id != FormatId)
            FACET_THROW("serialized: \"{}\" is not a serialized mesh (bad format id 0x{:04x})",
                        path, id);
        if (version != 3 && version != 4)
            FACET_THROW("serialized: \"{}\" has format version {}; versions 3 and 4 are supported",
                        path, version);

        // The dictionary at the end: offsets (uint64 in v4, uint32 in v3) then a uint32 count.
        uint32_t count;
        std::memcpy(&count, data + size - 4, 4);
        size_t offset_size = version == 4 ? 8 : 4;
        if (count == 0 || size_t(count) * offset_size + 4 > size)
            FACET_THROW("serialized: \"{}\" has a corrupt mesh table ({} meshes)", path, count);
        if (index < 0 || index >= int64_t(count))
            FACET_THROW_AT(props.location("shape_index"),
                           "serialized: shape_index {} is out of range: \"{}\" holds {} mesh(es)",
                           index, path, count);
        size_t table = size - 4 - size_t(count) * offset_size;
        auto offset_of = [&](size_t i) -> size_t {
            if (version == 4) {
                uint64_t o;
                std::memcpy(&o, data + table + 8 * i, 8);
                return size_t(o);
            }
            uint32_t o;
            std::memcpy(&o, data + table + 4 * i, 4);
            return size_t(o);
        };
        // Written without begin + 4, which wraps for offsets near 2^64.
        size_t begin = offset_of(size_t(index));
        size_t end = size_t(index) + 1 < count ? offset_of(size_t(index) + 1) : table;
        if (end > table || begin > end || end - begin < 4)
            FACET_THROW("serialized: \"{}\" has a corrupt offset for mesh {}", path, index);
        uint16_t mesh_id, mesh_version;
        std::memcpy(&mesh_id, data + begin, 2);
        std::memcpy(&mesh_version, data + begin + 2, 2);
        if (mesh_id != FormatId)
            FACET_THROW("serialized: \"{}\": mesh {} has a bad header (format id 0x{:04x})", path,
                        index, mesh_id);
        if (mesh_version != 3 && mesh_version != 4)
            FACET_THROW("serialized: \"{}\": mesh {} has format version {}; versions 3 and 4 are "
                        "supported",
                        path, index, mesh_version);

        InflateStream r(data + begin + 4, end - begin - 4, path);
        uint32_t flags = r.read<uint32_t>();
        if ((flags & SinglePrecision) && (flags & DoublePrecision))
            FACET_THROW("serialized: \"{}\": mesh {} is flagged both single and double precision",
                        path, index);
        if (mesh_version == 4) m_name = r.read_cstring();
        uint64_t nv = r.read<uint64_t>(), nf = r.read<uint64_t>();
        bool dbl = (flags & DoublePrecision) != 0;
        if (nv == 0 || nf == 0) FACET_THROW("serialized: \"{}\": mesh {} is empty", path, index);
        // Vertex indices are 32-bit; 3 nv and 3 nf are checked (allocation_bytes) before use.
        if (nv >= uint64_t(std::numeric_limits<uint32_t>::max()) ||
            nf > std::numeric_limits<size_t>::max() / 3)
            FACET_THROW("serialized: \"{}\": mesh {} claims {} vertices and {} triangles, more "
                        "than a mesh can hold",
                        path, index, nv, nf);
        r.read_reals(m_positions, size_t(nv) * 3, dbl, "vertex positions");
        if (flags & HasNormals) r.read_reals(m_normals, size_t(nv) * 3, dbl, "vertex normals");
        if (flags & HasUVs) r.read_reals(m_uvs, size_t(nv) * 2, dbl, "texture coordinates");
        if (flags & HasColors) r.read_reals(m_colors, size_t(nv) * 3, dbl, "vertex colours");
        r.read_indices(m_faces, size_t(nf) * 3);
        if (flags & FaceNormals) m_normals.clear();
        return (flags & FaceNormals) != 0;
    }
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::SerializedMesh, Shape, "serialized",
                          "Triangle mesh from Mitsuba's compressed .serialized format", DOC,
                          ::facet::AllModes)
