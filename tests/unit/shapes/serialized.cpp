// The serialized mesh format: a file written here (two meshes, versions 3 and 4, float and
// double precision) reads back exactly; damaged files are refused with a message naming them.
#include <facet/mesh.h>
#include <facet/plugin.h>

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <zlib.h>

using namespace facet;
namespace fs = std::filesystem;

namespace {

struct TestMesh {
    std::string name;
    std::vector<double> positions, normals, uvs;
    std::vector<uint32_t> faces;
};

template <typename T> void put(std::vector<uint8_t> &out, T v) {
    uint8_t bytes[sizeof(T)];
    std::memcpy(bytes, &v, sizeof(T));
    out.insert(out.end(), bytes, bytes + sizeof(T));
}

/// Writes meshes in the serialized layout (Mitsuba's format, versions 3 and 4).
std::vector<uint8_t> write_serialized(const std::vector<TestMesh> &meshes, uint16_t version,
                                      bool dbl) {
    std::vector<uint8_t> file;
    std::vector<uint64_t> offsets;
    for (const TestMesh &m : meshes) {
        offsets.push_back(file.size());
        put<uint16_t>(file, 0x041C);
        put<uint16_t>(file, version);
        std::vector<uint8_t> raw;
        uint32_t flags =
            (dbl ? 0x2000u : 0x1000u) | (m.normals.empty() ? 0u : 1u) | (m.uvs.empty() ? 0u : 2u);
        put<uint32_t>(raw, flags);
        if (version == 4) {
            raw.insert(raw.end(), m.name.begin(), m.name.end());
            raw.push_back(0);
        }
        put<uint64_t>(raw, m.positions.size() / 3);
        put<uint64_t>(raw, m.faces.size() / 3);
        for (const auto *arr : {&m.positions, &m.normals, &m.uvs})
            for (double v : *arr) {
                if (dbl)
                    put<double>(raw, v);
                else
                    put<float>(raw, float(v));
            }
        for (uint32_t f : m.faces) put<uint32_t>(raw, f);
        uLongf size = compressBound(uLong(raw.size()));
        std::vector<uint8_t> packed(size);
        EXPECT_EQ(compress(packed.data(), &size, raw.data(), uLong(raw.size())), Z_OK);
        file.insert(file.end(), packed.begin(), packed.begin() + long(size));
    }
    for (uint64_t o : offsets) {
        if (version == 4)
            put<uint64_t>(file, o);
        else
            put<uint32_t>(file, uint32_t(o));
    }
    put<uint32_t>(file, uint32_t(meshes.size()));
    return file;
}

fs::path write_file(const std::string &name, const std::vector<uint8_t> &bytes) {
    fs::path dir = fs::temp_directory_path() / "facet-serialized-test";
    fs::create_directories(dir);
    fs::path p = dir / name;
    std::ofstream(p, std::ios::binary)
        .write(reinterpret_cast<const char *>(bytes.data()), long(bytes.size()));
    return p;
}

std::shared_ptr<Mesh> load(const fs::path &p, int index) {
    Properties props("serialized");
    props.set_string("filename", p.string());
    props.set_int("shape_index", index);
    return std::dynamic_pointer_cast<Mesh>(
        PluginRegistry::instance().create(ObjectType::Shape, props));
}

std::vector<TestMesh> two_meshes() {
    TestMesh quad{"quad",
                  {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0},
                  {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1},
                  {0, 0, 1, 0, 1, 1, 0, 1},
                  {0, 1, 2, 0, 2, 3}};
    TestMesh tri{"tri", {0, 0, 0.25, 2, 0, 0.25, 0, 3, 0.25}, {}, {}, {0, 1, 2}};
    return {quad, tri};
}

} // namespace

TEST(Serialized, RoundTripVersion4Float) {
    auto meshes = two_meshes();
    fs::path p = write_file("v4.serialized", write_serialized(meshes, 4, false));
    for (int index = 0; index < 2; ++index) {
        auto mesh = load(p, index);
        ASSERT_TRUE(mesh);
        const TestMesh &ref = meshes[size_t(index)];
        ASSERT_EQ(mesh->vertex_count(), ref.positions.size() / 3);
        ASSERT_EQ(mesh->face_count(), ref.faces.size() / 3);
        for (size_t i = 0; i < mesh->vertex_count(); ++i) {
            Point3f v = mesh->vertex_position(i);
            EXPECT_FLOAT_EQ(v.x, float(ref.positions[3 * i]));
            EXPECT_FLOAT_EQ(v.y, float(ref.positions[3 * i + 1]));
            EXPECT_FLOAT_EQ(v.z, float(ref.positions[3 * i + 2]));
        }
        for (size_t i = 0; i < ref.faces.size(); ++i) EXPECT_EQ(mesh->faces()[i], ref.faces[i]);
        // From the file, or recomputed (smooth) when the file has none, as obj and ply do.
        EXPECT_TRUE(mesh->has_vertex_normals());
        EXPECT_EQ(mesh->has_uvs(), !ref.uvs.empty());
    }
    EXPECT_FLOAT_EQ(load(p, 1)->surface_area(), 3.f);
    EXPECT_FLOAT_EQ(load(p, 0)->surface_area(), 1.f);
}

TEST(Serialized, FaceNormalsDropVertexNormals) {
    fs::path p = write_file("faces.serialized", write_serialized(two_meshes(), 4, false));
    Properties props("serialized");
    props.set_string("filename", p.string());
    props.set_bool("face_normals", true);
    auto mesh = std::dynamic_pointer_cast<Mesh>(
        PluginRegistry::instance().create(ObjectType::Shape, props));
    ASSERT_TRUE(mesh);
    EXPECT_FALSE(mesh->has_vertex_normals());
}

TEST(Serialized, RoundTripVersion3Double) {
    auto meshes = two_meshes();
    fs::path p = write_file("v3.serialized", write_serialized(meshes, 3, true));
    auto mesh = load(p, 1);
    ASSERT_TRUE(mesh);
    EXPECT_EQ(mesh->face_count(), 1u);
    EXPECT_FLOAT_EQ(mesh->vertex_position(2).y, 3.f);
}

TEST(Serialized, ShapeIndexOutOfRangeIsAnError) {
    fs::path p = write_file("range.serialized", write_serialized(two_meshes(), 4, false));
    try {
        load(p, 2);
        FAIL() << "expected an error";
    } catch (const std::exception &e) {
        std::string msg = e.what();
        EXPECT_NE(msg.find("shape_index 2 is out of range"), std::string::npos) << msg;
        EXPECT_NE(msg.find("2 mesh"), std::string::npos) << msg;
    }
}

TEST(Serialized, TruncatedFileIsAnError) {
    auto bytes = write_serialized(two_meshes(), 4, false);
    // Cut the first mesh's compressed stream short but keep a valid-looking table.
    std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + 20);
    uint64_t zero = 0;
    uint32_t one = 1;
    cut.insert(cut.end(), reinterpret_cast<uint8_t *>(&zero),
               reinterpret_cast<uint8_t *>(&zero) + 8);
    cut.insert(cut.end(), reinterpret_cast<uint8_t *>(&one), reinterpret_cast<uint8_t *>(&one) + 4);
    fs::path p = write_file("cut.serialized", cut);
    try {
        load(p, 0);
        FAIL() << "expected an error";
    } catch (const std::exception &e) {
        std::string msg = e.what();
        EXPECT_NE(msg.find("cut.serialized"), std::string::npos) << msg;
    }
}

TEST(Serialized, NotASerializedFile) {
    fs::path p = write_file("junk.serialized", std::vector<uint8_t>(64, 0x41));
    EXPECT_THROW(load(p, 0), std::exception);
    EXPECT_THROW(load(fs::temp_directory_path() / "no-such-file.serialized", 0), std::exception);
}
