// Shapes: the mesh loaders (obj, ply), the built-in meshes (rectangle, cube), the exact shapes
// (sphere, disk), their areas, bounds, position sampling and direction sampling, and exact
// intersections through Embree.
#include "draws.h"

#include <facet/interaction.h>
#include <facet/mesh.h>
#include <facet/plugin.h>
#include <facet/random.h>
#include <facet/resolver.h>
#include <facet/scene.h>
#include <facet/shape.h>
#include <facet/warp.h>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <unistd.h>

using namespace facet;
namespace fs = std::filesystem;

namespace {

std::shared_ptr<Shape> make_shape(const std::string &type, Properties props = Properties()) {
    props.set_plugin_name(type);
    return PluginRegistry::instance().create_as<Shape>(ObjectType::Shape, props);
}

std::shared_ptr<Mesh> make_mesh(const std::string &type, Properties props = Properties()) {
    auto mesh = std::dynamic_pointer_cast<Mesh>(make_shape(type, std::move(props)));
    EXPECT_TRUE(mesh) << type << " is not a mesh";
    return mesh;
}

/// A folder of its own for the files a test writes.
class TempDir {
public:
    TempDir() {
        static int counter = 0;
        m_path = fs::temp_directory_path() /
                 fmt::format("facet_shapes_{}_{}", long(::getpid()), counter++);
        fs::create_directories(m_path);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(m_path, ec);
    }
    std::string write(const std::string &name, const std::string &content) const {
        std::string p = (m_path / name).string();
        std::ofstream(p, std::ios::binary) << content;
        return p;
    }

private:
    fs::path m_path;
};

Properties file_props(const std::string &path) {
    Properties props;
    props.set_string("filename", path);
    return props;
}

/// Message of the facet::Error thrown by `f` (fails the test when nothing is thrown).
template <typename F> std::string error_of(F &&f) {
    try {
        f();
    } catch (const Error &e) {
        return e.what();
    }
    ADD_FAILURE() << "expected a facet::Error";
    return "";
}

/// One shape in an Embree scene of its own, to test intersections without a full Scene.
class SingleShape {
public:
    explicit SingleShape(std::shared_ptr<Shape> shape) : m_shape(std::move(shape)) {
        RTCDevice device = embree_device();
        m_scene = rtcNewScene(device);
        rtcSetSceneFlags(m_scene, RTC_SCENE_FLAG_ROBUST);
        RTCGeometry geom = m_shape->embree_geometry(device);
        rtcAttachGeometry(m_scene, geom);
        rtcReleaseGeometry(geom);
        rtcCommitScene(m_scene);
    }
    ~SingleShape() { rtcReleaseScene(m_scene); }

    bool intersect(const Ray &ray, SurfaceInteraction &si) const {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRayHit rh{};
        rh.ray.org_x = ray.o.x;
        rh.ray.org_y = ray.o.y;
        rh.ray.org_z = ray.o.z;
        rh.ray.dir_x = ray.d.x;
        rh.ray.dir_y = ray.d.y;
        rh.ray.dir_z = ray.d.z;
        rh.ray.tnear = ray.mint;
        rh.ray.tfar = ray.maxt;
        rh.ray.mask = 0xFFFFFFFFu;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(m_scene, &ctx, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
        m_shape->compute_surface_interaction(ray, rh.ray.tfar, rh.hit.primID,
                                             Point2f(rh.hit.u, rh.hit.v), si);
        // What Scene::ray_intersect() adds to the geometry the shape filled in.
        si.t = rh.ray.tfar;
        si.wi = si.to_local(-ray.d);
        return true;
    }

    bool occluded(const Ray &ray) const {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRay r{};
        r.org_x = ray.o.x;
        r.org_y = ray.o.y;
        r.org_z = ray.o.z;
        r.dir_x = ray.d.x;
        r.dir_y = ray.d.y;
        r.dir_z = ray.d.z;
        r.tnear = ray.mint;
        r.tfar = ray.maxt;
        r.mask = 0xFFFFFFFFu;
        rtcOccluded1(m_scene, &ctx, &r);
        return r.tfar == -Infinity;
    }

private:
    std::shared_ptr<Shape> m_shape;
    RTCScene m_scene;
};

Transform scale(float x, float y, float z) { return Transform::scale(Vector3f(x, y, z)); }

void expect_near_vec(const Vector3f &a, const Vector3f &b, float tol) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

} // namespace

// ---------------------------------------------------------------------------------------------
// OBJ

TEST(ObjLoader, QuadIsSplitIntoTwoTriangles) {
    TempDir dir;
    std::string path = dir.write("quad.obj", "# a unit square\n"
                                             "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                             "f 1 2 3 4\n");
    auto mesh = make_mesh("obj", file_props(path));
    EXPECT_EQ(mesh->vertex_count(), 4u);
    EXPECT_EQ(mesh->face_count(), 2u);
    EXPECT_NEAR(mesh->surface_area(), 1.f, 1e-6f);
    EXPECT_FALSE(mesh->has_uvs());
    // No normals in the file: smooth ones are computed, all +z for a flat square.
    ASSERT_TRUE(mesh->has_vertex_normals());
    for (size_t i = 0; i < 4; ++i) EXPECT_FLOAT_EQ(mesh->normals()[3 * i + 2], 1.f);
}

TEST(ObjLoader, PentagonFanAndNegativeIndices) {
    TempDir dir;
    const char *verts = "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\n";
    auto pos =
        make_mesh("obj", file_props(dir.write("pos.obj", std::string(verts) + "f 1 2 3 4 5\n")));
    auto neg = make_mesh(
        "obj", file_props(dir.write("neg.obj", std::string(verts) + "f -5 -4 -3 -2 -1\n")));
    EXPECT_EQ(pos->face_count(), 3u);
    EXPECT_EQ(neg->faces(), pos->faces());
    EXPECT_EQ(neg->positions(), pos->positions());
    EXPECT_NEAR(pos->surface_area(), 3.f, 1e-5f); // 2x1 rectangle + triangle of area 1
}

TEST(ObjLoader, IndexFormsAndVertexSharing) {
    TempDir dir;
    // Two triangles sharing an edge. The shared positions use the same (v, vt, vn) in both faces
    // except vertex 3, which has a different normal in the second face.
    std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                      "vt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\n"
                      "vn 0 0 1\nvn 0 0.6 0.8\n"
                      "f 1/1/1 2/2/1 3/3/1\n"
                      "f 2/2/1 4/4/1 3/3/2\n";
    auto mesh = make_mesh("obj", file_props(dir.write("a.obj", obj)));
    EXPECT_EQ(mesh->face_count(), 2u);
    EXPECT_EQ(mesh->vertex_count(), 5u); // 1, 2, 3, 4 and 3 with the second normal
    ASSERT_TRUE(mesh->has_uvs());
    ASSERT_TRUE(mesh->has_vertex_normals());
    // flip_tex_coords is on by default: v becomes 1 - v.
    const auto &f = mesh->faces();
    const auto &uv = mesh->uvs();
    EXPECT_FLOAT_EQ(uv[2 * f[2]], 0.f);
    EXPECT_FLOAT_EQ(uv[2 * f[2] + 1], 0.f); // vt 0 1 -> (0, 0)
    EXPECT_FLOAT_EQ(uv[2 * f[0] + 1], 1.f); // vt 0 0 -> (0, 1)
    EXPECT_NE(f[2], f[5]);                  // vertex 3 split by its normal
    EXPECT_EQ(f[1], f[3]);                  // vertex 2 shared

    Properties props = file_props(dir.write("b.obj", obj));
    props.set_bool("flip_tex_coords", false);
    auto unflipped = make_mesh("obj", props);
    EXPECT_FLOAT_EQ(unflipped->uvs()[2 * unflipped->faces()[2] + 1], 1.f);

    // v//vn and v/vt forms.
    std::string obj2 = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.5 0.5\nvn 0 0 1\n"
                       "f 1//1 2//1 3//1\nf 1/1 2/1 3/1\n";
    auto mesh2 = make_mesh("obj", file_props(dir.write("c.obj", obj2)));
    EXPECT_EQ(mesh2->face_count(), 2u);
    EXPECT_EQ(mesh2->vertex_count(), 6u);
    EXPECT_TRUE(mesh2->has_uvs());
}

TEST(ObjLoader, FaceNormalsDropVertexNormals) {
    TempDir dir;
    std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 1 0 0\nf 1//1 2//1 3//1\n";
    Properties props = file_props(dir.write("a.obj", obj));
    props.set_bool("face_normals", true);
    auto mesh = make_mesh("obj", props);
    EXPECT_FALSE(mesh->has_vertex_normals());
}

TEST(ObjLoader, MissingFileIsAnError) {
    std::string msg = error_of([] { make_mesh("obj", file_props("no/such/file_4711.obj")); });
    EXPECT_NE(msg.find("file_4711.obj"), std::string::npos) << msg;
}

TEST(ObjLoader, BadIndexNamesFileAndLine) {
    TempDir dir;
    std::string path = dir.write("broken.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 7\n");
    std::string msg = error_of([&] { make_mesh("obj", file_props(path)); });
    EXPECT_NE(msg.find("broken.obj:5"), std::string::npos) << msg;
    EXPECT_NE(msg.find("7"), std::string::npos) << msg;

    path = dir.write("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
    msg = error_of([&] { make_mesh("obj", file_props(path)); });
    EXPECT_NE(msg.find("zero.obj:4"), std::string::npos) << msg;

    path = dir.write("garbage.obj", "v 0 0 0\nv 1 x 0\n");
    msg = error_of([&] { make_mesh("obj", file_props(path)); });
    EXPECT_NE(msg.find("garbage.obj:2"), std::string::npos) << msg;

    path = dir.write("nan.obj", "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n");
    msg = error_of([&] { make_mesh("obj", file_props(path)); });
    EXPECT_NE(msg.find("nan.obj"), std::string::npos) << msg;
    EXPECT_NE(msg.find("non-finite"), std::string::npos) << msg;

    path = dir.write("empty.obj", "v 0 0 0\n");
    msg = error_of([&] { make_mesh("obj", file_props(path)); });
    EXPECT_NE(msg.find("empty.obj"), std::string::npos) << msg;
}

TEST(ObjLoader, FilenameGoesThroughTheResolver) {
    TempDir dir;
    std::string path = dir.write("resolved_mesh.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    file_resolver().prepend(fs::path(path).parent_path().string());
    auto mesh = make_mesh("obj", file_props("resolved_mesh.obj"));
    EXPECT_EQ(mesh->face_count(), 1u);
}

// ---------------------------------------------------------------------------------------------
// PLY

namespace {

/// The test mesh: a unit square (one quad face) plus a triangle, with normals, uvs and colours.
struct PlyMesh {
    std::vector<float> pos = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1};
    std::vector<float> nrm = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, -1, 0};
    std::vector<float> uv = {0, 0, 1, 0, 1, 1, 0, 1, 0.25f, 0.75f};
    std::vector<uint8_t> rgb = {255, 0, 0, 0, 255, 0, 0, 0, 255, 51, 102, 153, 0, 0, 0};
    std::vector<std::vector<int32_t>> faces = {{0, 1, 2, 3}, {0, 4, 1}};
};

std::string ply_header(const char *format, size_t nv, size_t nf) {
    return fmt::format("ply\nformat {} 1.0\ncomment written by the facet tests\n"
                       "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n"
                       "property float nx\nproperty float ny\nproperty float nz\n"
                       "property float u\nproperty float v\n"
                       "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                       "element face {}\nproperty list uchar int vertex_indices\n"
                       "property int flags\n"
                       "element extra 2\nproperty list uchar float stuff\nproperty double w\n"
                       "end_header\n",
                       format, nv, nf);
}

template <typename T> void put(std::string &s, T v, bool big) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (big) std::reverse(b, b + sizeof(T));
    s.append(b, sizeof(T));
}

std::string write_ply(const PlyMesh &m, const char *format) {
    size_t nv = m.pos.size() / 3;
    std::string s = ply_header(format, nv, m.faces.size());
    if (std::string(format) == "ascii") {
        for (size_t i = 0; i < nv; ++i)
            s += fmt::format("{} {} {} {} {} {} {} {} {} {} {}\n", m.pos[3 * i], m.pos[3 * i + 1],
                             m.pos[3 * i + 2], m.nrm[3 * i], m.nrm[3 * i + 1], m.nrm[3 * i + 2],
                             m.uv[2 * i], m.uv[2 * i + 1], m.rgb[3 * i], m.rgb[3 * i + 1],
                             m.rgb[3 * i + 2]);
        for (const auto &f : m.faces) {
            s += std::to_string(f.size());
            for (int32_t i : f) s += " " + std::to_string(i);
            s += " 7\n";
        }
        s += "3 1 2 3 0.5\n0 -1\n";
        return s;
    }
    bool big = std::string(format) == "binary_big_endian";
    for (size_t i = 0; i < nv; ++i) {
        for (int k = 0; k < 3; ++k) put(s, m.pos[3 * i + k], big);
        for (int k = 0; k < 3; ++k) put(s, m.nrm[3 * i + k], big);
        for (int k = 0; k < 2; ++k) put(s, m.uv[2 * i + k], big);
        for (int k = 0; k < 3; ++k) put(s, m.rgb[3 * i + k], big);
    }
    for (const auto &f : m.faces) {
        put(s, uint8_t(f.size()), big);
        for (int32_t i : f) put(s, i, big);
        put(s, int32_t(7), big);
    }
    put(s, uint8_t(2), big);
    put(s, 1.5f, big);
    put(s, 2.5f, big);
    put(s, 0.25, big);
    put(s, uint8_t(0), big);
    put(s, -1.0, big);
    return s;
}

} // namespace

TEST(PlyLoader, AsciiAndBinaryRoundTrip) {
    TempDir dir;
    PlyMesh m;
    for (const char *format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
        SCOPED_TRACE(format);
        auto mesh = make_mesh(
            "ply", file_props(dir.write(std::string(format) + ".ply", write_ply(m, format))));
        ASSERT_EQ(mesh->vertex_count(), 5u);
        ASSERT_EQ(mesh->face_count(), 3u);
        EXPECT_EQ(mesh->faces(), (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 4, 1}));
        // uchar red/green/blue become vertex_color, raw (0..255) as in Mitsuba 3.8.
        const Mesh::Attribute *color = mesh->attribute("vertex_color");
        ASSERT_TRUE(color);
        EXPECT_EQ(color->channels, 3u);
        EXPECT_FALSE(color->per_face);
        ASSERT_EQ(color->data.size(), 15u);
        for (size_t i = 0; i < 15; ++i) {
            EXPECT_FLOAT_EQ(mesh->positions()[i], m.pos[i]);
            EXPECT_FLOAT_EQ(mesh->normals()[i], m.nrm[i]);
            EXPECT_EQ(color->data[i], float(m.rgb[i]));
        }
        // The face property "flags" has no one-letter suffix: Mitsuba skips it too.
        EXPECT_EQ(mesh->attribute_names(), "vertex_color");
        // PLY keeps v as it is (flip_tex_coords defaults to false).
        for (size_t i = 0; i < 10; ++i) EXPECT_FLOAT_EQ(mesh->uvs()[i], m.uv[i]);
        EXPECT_NEAR(mesh->surface_area(), 1.5f, 1e-6f);
    }
}

TEST(PlyLoader, FlipTexCoordsAndFaceNormals) {
    TempDir dir;
    PlyMesh m;
    Properties props = file_props(dir.write("a.ply", write_ply(m, "binary_little_endian")));
    props.set_bool("flip_tex_coords", true);
    props.set_bool("face_normals", true);
    auto mesh = make_mesh("ply", props);
    EXPECT_FLOAT_EQ(mesh->uvs()[9], 0.25f);
    EXPECT_FALSE(mesh->has_vertex_normals());
}

TEST(PlyLoader, TruncatedAndMalformedFilesAreErrors) {
    TempDir dir;
    PlyMesh m;
    std::string bin = write_ply(m, "binary_little_endian");
    // Cut in the middle of the face list.
    std::string path = dir.write(
        "cut.ply", bin.substr(0, ply_header("binary_little_endian", 5, 2).size() + 5 * 35 + 7));
    std::string msg = error_of([&] { make_mesh("ply", file_props(path)); });
    EXPECT_NE(msg.find("cut.ply"), std::string::npos) << msg;
    // The face count of the header is checked against what is left before reading.
    EXPECT_NE(msg.find("2 face elements, more than the file holds"), std::string::npos) << msg;

    std::string ascii = write_ply(m, "ascii");
    path = dir.write("cut_ascii.ply", ascii.substr(0, ascii.find("4 0 1 2 3")));
    msg = error_of([&] { make_mesh("ply", file_props(path)); });
    EXPECT_NE(msg.find("cut_ascii.ply"), std::string::npos) << msg;

    path = dir.write("bad_index.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                      "property float y\nproperty float z\nelement face 1\n"
                                      "property list uchar uint vertex_index\nend_header\n"
                                      "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
    msg = error_of([&] { make_mesh("ply", file_props(path)); });
    EXPECT_NE(msg.find("bad_index.ply"), std::string::npos) << msg;
    EXPECT_NE(msg.find("vertex 3"), std::string::npos) << msg;

    path = dir.write("not.ply", "solid ascii stl\n");
    msg = error_of([&] { make_mesh("ply", file_props(path)); });
    EXPECT_NE(msg.find("not a PLY"), std::string::npos) << msg;

    path = dir.write("fmt.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n");
    msg = error_of([&] { make_mesh("ply", file_props(path)); });
    EXPECT_NE(msg.find("binary_middle_endian"), std::string::npos) << msg;
}

TEST(PlyLoader, IntegerIndexTypesAndDoublePositions) {
    TempDir dir;
    std::string s = "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\n"
                    "property double y\nproperty double z\nelement face 1\n"
                    "property list int ushort vertex_indices\nend_header\n";
    const double p[9] = {0, 0, 0, 4, 0, 0, 0, 2, 0};
    for (double v : p) put(s, v, true);
    put(s, int32_t(3), true);
    for (uint16_t i : {0, 1, 2}) put(s, i, true);
    auto mesh = make_mesh("ply", file_props(dir.write("d.ply", s)));
    EXPECT_EQ(mesh->face_count(), 1u);
    EXPECT_NEAR(mesh->surface_area(), 4.f, 1e-6f);
    EXPECT_FALSE(mesh->has_vertex_colors());
}

// ---------------------------------------------------------------------------------------------
// Areas and bounds

TEST(ShapeGeometry, AreasAndBoundsWithScale) {
    {
        Properties props;
        props.set_float("radius", 2.0);
        props.set_vector("center", Vector3f(1, 2, 3));
        auto s = make_shape("sphere", props);
        EXPECT_NEAR(s->surface_area(), 16.f * Pi, 1e-4f);
        expect_near_vec(s->bbox().min, Vector3f(-1, 0, 1), 1e-6f);
        expect_near_vec(s->bbox().max, Vector3f(3, 4, 5), 1e-6f);
    }
    {
        Properties props;
        props.set_transform("to_world", Transform::translate(Vector3f(0, 0, 5)) * scale(3, 3, 3));
        auto s = make_shape("sphere", props);
        EXPECT_NEAR(s->surface_area(), 36.f * Pi, 1e-3f);
        expect_near_vec(s->bbox().max, Vector3f(3, 3, 8), 1e-5f);
    }
    {
        auto d = make_shape("disk");
        EXPECT_NEAR(d->surface_area(), Pi, 1e-6f);
        Properties props;
        props.set_transform("to_world", scale(2, 3, 1));
        d = make_shape("disk", props);
        EXPECT_NEAR(d->surface_area(), 6.f * Pi, 1e-5f);
        expect_near_vec(d->bbox().max, Vector3f(2, 3, 0), 1e-6f);
    }
    {
        auto r = make_shape("rectangle");
        EXPECT_NEAR(r->surface_area(), 4.f, 1e-6f);
        Properties props;
        props.set_transform("to_world", scale(2, 3, 1));
        r = make_shape("rectangle", props);
        EXPECT_NEAR(r->surface_area(), 24.f, 1e-5f);
        expect_near_vec(r->bbox().min, Vector3f(-2, -3, 0), 1e-6f);
    }
    {
        auto c = make_shape("cube");
        EXPECT_NEAR(c->surface_area(), 24.f, 1e-5f);
        auto mesh = std::dynamic_pointer_cast<Mesh>(c);
        EXPECT_EQ(mesh->vertex_count(), 24u);
        EXPECT_EQ(mesh->face_count(), 12u);
        Properties props;
        props.set_transform("to_world", scale(2, 2, 2));
        c = make_shape("cube", props);
        EXPECT_NEAR(c->surface_area(), 96.f, 1e-4f);
        expect_near_vec(c->bbox().max, Vector3f(2, 2, 2), 1e-6f);
    }
}

TEST(ShapeGeometry, SphereRejectsNonUniformScale) {
    Properties props;
    props.set_transform("to_world", scale(1, 2, 1));
    std::string msg = error_of([&] { make_shape("sphere", props); });
    EXPECT_NE(msg.find("to_world"), std::string::npos) << msg;

    Properties bad_radius;
    bad_radius.set_float("radius", -1.0);
    msg = error_of([&] { make_shape("sphere", bad_radius); });
    EXPECT_NE(msg.find("radius"), std::string::npos) << msg;

    // Rotations are fine.
    Properties rotated;
    rotated.set_transform("to_world", Transform::rotate(Vector3f(1, 1, 0), 30.f) * scale(2, 2, 2));
    EXPECT_NEAR(make_shape("sphere", rotated)->surface_area(), 16.f * Pi, 1e-3f);
}

TEST(ShapeGeometry, CubeNormalsPointOutwardsAlsoWhenMirrored) {
    for (const Transform &tr : {Transform(), scale(-1, 2, 1)}) {
        Properties props;
        props.set_transform("to_world", tr);
        auto cube = std::dynamic_pointer_cast<Mesh>(make_shape("cube", props));
        SingleShape scene(cube);
        const auto &f = cube->faces();
        for (size_t t = 0; t < cube->face_count(); ++t) {
            Point3f p0 = cube->vertex_position(f[3 * t]), p1 = cube->vertex_position(f[3 * t + 1]),
                    p2 = cube->vertex_position(f[3 * t + 2]);
            Vector3f n = normalize(cross(p1 - p0, p2 - p0));
            Point3f c = (p0 + p1 + p2) / 3.f;
            EXPECT_GT(dot(n, normalize(c)), 0.3f) << "triangle " << t;
            Vector3f vn(cube->normals()[3 * f[3 * t]], cube->normals()[3 * f[3 * t] + 1],
                        cube->normals()[3 * f[3 * t] + 2]);
            expect_near_vec(vn, n, 1e-6f);
            // Hit from outside: geometric and shading normal face the ray origin.
            Point3f o = c + n * 3.f;
            SurfaceInteraction si;
            ASSERT_TRUE(scene.intersect(Ray(o, -n), si));
            EXPECT_NEAR(dot(si.n, n), 1.f, 1e-5f);
            EXPECT_NEAR(si.wi.z, 1.f, 1e-5f);
        }
    }
    // A mirrored rectangle keeps its normal along the transformed +z, as a disk does.
    Properties props;
    props.set_transform("to_world", scale(-1, 1, 1));
    PositionSample ps = make_shape("rectangle", props)->sample_position(Point2f(0.5f, 0.5f));
    expect_near_vec(ps.n, Vector3f(0, 0, 1), 1e-6f);
    ps = make_shape("disk", props)->sample_position(Point2f(0.5f, 0.5f));
    expect_near_vec(ps.n, Vector3f(0, 0, 1), 1e-6f);
}

// ---------------------------------------------------------------------------------------------
// Position sampling

namespace {

struct ShapeCase {
    const char *type;
    Transform to_world;
    /// Signed distance-like residual: 0 on the surface.
    std::function<float(const Point3f &)> residual;
};

} // namespace

TEST(ShapeSampling, PositionsLieOnTheSurfaceWithUniformPdf) {
    Transform tr = Transform::translate(Vector3f(1, -2, 0.5f)) * scale(2, 2, 2);
    std::vector<ShapeCase> cases = {
        {"sphere", tr, [](const Point3f &p) { return norm(p - Point3f(1, -2, 0.5f)) - 2.f; }},
        {"disk", tr,
         [](const Point3f &p) {
             float r = std::hypot(p.x - 1.f, p.y + 2.f);
             return std::abs(p.z - 0.5f) + std::max(0.f, r - 2.f);
         }},
        {"rectangle", tr,
         [](const Point3f &p) {
             return std::abs(p.z - 0.5f) + std::max(0.f, std::abs(p.x - 1.f) - 2.f) +
                    std::max(0.f, std::abs(p.y + 2.f) - 2.f);
         }},
        {"cube", tr,
         [](const Point3f &p) {
             Vector3f q = abs(p - Point3f(1, -2, 0.5f));
             return std::abs(max_component(q) - 2.f);
         }},
    };
    for (const auto &c : cases) {
        SCOPED_TRACE(c.type);
        Properties props;
        props.set_transform("to_world", c.to_world);
        auto shape = make_shape(c.type, props);
        PCG32 rng(7);
        for (int i = 0; i < 2000; ++i) {
            PositionSample ps = shape->sample_position(next_point2f(rng));
            ASSERT_NEAR(c.residual(ps.p), 0.f, 1e-5f) << ps.p;
            ASSERT_NEAR(ps.pdf, 1.f / shape->surface_area(), 1e-6f);
            ASSERT_NEAR(norm(ps.n), 1.f, 1e-5f);
            ASSERT_FLOAT_EQ(shape->pdf_position(ps), ps.pdf);
        }
    }
}

TEST(ShapeSampling, MeshPicksTrianglesByArea) {
    TempDir dir;
    // Two triangles with areas 1 and 3.
    std::string path = dir.write("two.obj", "v 0 0 0\nv 2 0 0\nv 0 1 0\n"
                                            "v 0 0 5\nv 3 0 5\nv 0 2 5\n"
                                            "f 1 2 3\nf 4 5 6\n");
    auto mesh = make_mesh("obj", file_props(path));
    EXPECT_NEAR(mesh->surface_area(), 4.f, 1e-6f);
    PCG32 rng(3);
    const int n = 40000;
    int upper = 0;
    double mean_x = 0.0;
    for (int i = 0; i < n; ++i) {
        PositionSample ps = mesh->sample_position(next_point2f(rng));
        if (ps.p.z > 2.5f) {
            ++upper;
            mean_x += ps.p.x;
        }
    }
    // Binomial(40000, 0.75): standard deviation 87.
    EXPECT_NEAR(upper, 30000, 5 * 87);
    // The centroid of the second triangle has x = 1.
    EXPECT_NEAR(mean_x / upper, 1.0, 0.02);
}

TEST(ShapeSampling, MeshPicksTheTriangleOfEachCdfInterval) {
    // n triangles of area 1 at z = 0, 1, ..., n - 1: the cumulative areas are (k + 1) / n. A
    // sample u.x picks the first triangle whose cumulative area exceeds it, so a value on a
    // boundary belongs to the next triangle. Few triangles (a light) and many (a binary search).
    for (int n : {2, 3, 8, 9, 12}) {
        SCOPED_TRACE(n);
        TempDir dir;
        std::string obj;
        for (int k = 0; k < n; ++k) obj += fmt::format("v 0 0 {0}\nv 2 0 {0}\nv 0 1 {0}\n", k);
        for (int k = 0; k < n; ++k)
            obj += fmt::format("f {} {} {}\n", 3 * k + 1, 3 * k + 2, 3 * k + 3);
        auto mesh = make_mesh("obj", file_props(dir.write("tris.obj", obj)));
        ASSERT_NEAR(mesh->surface_area(), float(n), 1e-5f);
        auto picked = [&](float ux) {
            return int(std::lround(mesh->sample_position(Point2f(ux, 0.5f)).p.z));
        };
        EXPECT_EQ(picked(0.f), 0);
        EXPECT_EQ(picked(OneMinusEpsilon), n - 1);
        EXPECT_EQ(picked(1.f), n - 1);
        for (int k = 0; k + 1 < n; ++k) {
            const float boundary = float(double(k + 1) / double(n));
            EXPECT_EQ(picked(std::nextafter(boundary, 0.f)), k) << "below boundary " << k;
            EXPECT_EQ(picked(boundary), k + 1) << "on boundary " << k;
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Intersections

TEST(ShapeIntersection, SphereHitDistanceIsExact) {
    const Point3f center(0.5f, -1.f, 2.f);
    const float radius = 1.5f;
    Properties props;
    props.set_vector("center", center);
    props.set_float("radius", radius);
    auto sphere = make_shape("sphere", props);
    SingleShape scene(sphere);
    PCG32 rng(11);
    int hits = 0;
    for (int i = 0; i < 2000; ++i) {
        // Origins at distances from 2 to 1000 radii, aimed near the sphere.
        float dist = radius * std::pow(500.f, rng.next_float()) * 2.f;
        Vector3f dir_o = warp::square_to_uniform_sphere(next_point2f(rng));
        Point3f o = center + dir_o * dist;
        Point3f target =
            center + warp::square_to_uniform_sphere(next_point2f(rng)) * (radius * 1.2f);
        Vector3f d = normalize(target - o);
        // Reference in double.
        Vector3d od = Vector3d(o) - Vector3d(center), dd = Vector3d(d);
        double b = dot(od, dd), c = dot(od, od) - double(radius) * radius;
        double disc = b * b - c * dot(dd, dd);
        SurfaceInteraction si;
        bool hit = scene.intersect(Ray(o, d), si);
        if (disc < 0.0) {
            // Misses must be clear misses (the reference is exact enough away from the rim).
            if (disc < -1e-3 * radius * radius) {
                EXPECT_FALSE(hit);
            }
            continue;
        }
        double t_ref = (-b - std::sqrt(disc)) / dot(dd, dd);
        if (disc < 1e-3 * radius * radius) continue; // grazing: skip the rim
        ASSERT_TRUE(hit);
        ++hits;
        EXPECT_NEAR(si.t, t_ref, 1e-5 * t_ref);
        EXPECT_NEAR(norm(si.p - center), radius, 1e-5f * radius);
        expect_near_vec(si.n, normalize(si.p - center), 1e-5f);
        EXPECT_GT(si.wi.z, 0.f); // seen from outside
        EXPECT_NEAR(dot(si.sh_frame.n, si.n), 1.f, 1e-6f);
        EXPECT_NEAR(si.wi.z, -dot(d, si.n), 1e-5f);
    }
    EXPECT_GT(hits, 500);
}

TEST(ShapeIntersection, SphereShadowRaysStopShortOrReachIt) {
    // A shadow ray towards a light's sphere ends just before its surface (the occlusion test
    // answers those without solving the quadratic); one ending just past it must be blocked.
    const Point3f center(-2.f, 0.5f, 1.f);
    const float radius = 0.25f;
    Properties props;
    props.set_vector("center", center);
    props.set_float("radius", radius);
    SingleShape scene(make_shape("sphere", props));
    PCG32 rng(17);
    int checked = 0;
    for (int i = 0; i < 3000; ++i) {
        const float dist = radius * std::pow(1000.f, rng.next_float()) * 1.5f;
        const Point3f o = center + warp::square_to_uniform_sphere(next_point2f(rng)) * dist;
        const Point3f target =
            center + warp::square_to_uniform_sphere(next_point2f(rng)) * (radius * 0.9f);
        const Vector3f d = normalize(target - o);
        const Vector3d od = Vector3d(o) - Vector3d(center), dd = Vector3d(d);
        // |d| is 1 only to float rounding, which matters near the rim of a distant sphere.
        const double a = dot(dd, dd), b = dot(od, dd);
        const double disc = b * b - a * (dot(od, od) - double(radius) * radius);
        if (disc < 1e-2 * double(radius) * radius) continue; // the rim
        const double t = (-b - std::sqrt(disc)) / a;
        for (double gap : {1e-3, 1e-4, 1e-5}) {
            EXPECT_FALSE(scene.occluded(Ray(o, d, 0.f, float(t * (1.0 - gap)))))
                << "ends " << gap << " short, at " << dist / radius << " radii";
            EXPECT_TRUE(scene.occluded(Ray(o, d, 0.f, float(t * (1.0 + gap)))))
                << "ends " << gap << " beyond, at " << dist / radius << " radii";
        }
        ++checked;
    }
    EXPECT_GT(checked, 1500);
}

TEST(ShapeIntersection, SphereFromInsideAndFlippedNormals) {
    Properties props;
    props.set_bool("flip_normals", true);
    props.set_float("radius", 2.0);
    auto sphere = make_shape("sphere", props);
    SingleShape scene(sphere);
    SurfaceInteraction si;
    ASSERT_TRUE(scene.intersect(Ray(Point3f(0.5f, 0, 0), Vector3f(1, 0, 0)), si));
    EXPECT_NEAR(si.t, 1.5f, 1e-6f);
    expect_near_vec(si.n, Vector3f(-1, 0, 0), 1e-6f);
    EXPECT_GT(si.wi.z, 0.99f); // seen from inside, the flipped normal faces the viewer
    // uv: the +x axis is longitude 0, the equator is v = 0.5.
    EXPECT_NEAR(si.uv.x, 0.f, 1e-6f);
    EXPECT_NEAR(si.uv.y, 0.5f, 1e-6f);
    // mint/maxt are honoured.
    EXPECT_FALSE(scene.intersect(Ray(Point3f(0.5f, 0, 0), Vector3f(1, 0, 0), 0.f, 1.4f), si));
    EXPECT_TRUE(scene.occluded(Ray(Point3f(0.5f, 0, 0), Vector3f(1, 0, 0), 0.f, 1.6f)));
    EXPECT_FALSE(scene.occluded(Ray(Point3f(0.5f, 0, 0), Vector3f(1, 0, 0), 0.f, 1.4f)));
}

TEST(ShapeIntersection, DiskHitIsExactWithUvAndNormal) {
    Properties props;
    props.set_transform("to_world", Transform::translate(Vector3f(0, 0, 3)) * scale(2, 2, 2));
    auto disk = make_shape("disk", props);
    SingleShape scene(disk);
    PCG32 rng(5);
    for (int i = 0; i < 1000; ++i) {
        const Point2f qo = next_point2f(rng), qt = next_point2f(rng);
        Point3f o(qo.x * 8 - 4, qo.y * 8 - 4, -5.f);
        Point3f target(qt.x * 5 - 2.5f, qt.y * 5 - 2.5f, 3.f);
        Vector3f d = normalize(target - o);
        double t_ref = (3.0 - double(o.z)) / double(d.z);
        double r = std::hypot(double(o.x) + t_ref * d.x, double(o.y) + t_ref * d.y);
        SurfaceInteraction si;
        bool hit = scene.intersect(Ray(o, d), si);
        if (std::abs(r - 2.0) < 1e-4) continue;
        ASSERT_EQ(hit, r < 2.0) << r;
        if (!hit) continue;
        EXPECT_NEAR(si.t, t_ref, 1e-5 * t_ref);
        EXPECT_NEAR(si.p.z, 3.f, 1e-6f);
        expect_near_vec(si.n, Vector3f(0, 0, 1), 1e-6f);
        EXPECT_NEAR(si.uv.x, r / 2.0, 1e-5);
        EXPECT_LT(si.wi.z, 0.f); // hit from below: the back side
    }
}

TEST(ShapeIntersection, RectangleUvFrameAndFlip) {
    Properties props;
    props.set_transform("to_world", scale(2, 1, 1));
    auto rect = make_shape("rectangle", props);
    // Flat: normals and frame of its faces come from the table built at load.
    ASSERT_TRUE(std::dynamic_pointer_cast<Mesh>(rect));
    EXPECT_TRUE(std::dynamic_pointer_cast<Mesh>(rect)->flat_faces());
    SingleShape scene(rect);
    SurfaceInteraction si;
    ASSERT_TRUE(scene.intersect(Ray(Point3f(1.f, 0.5f, 2.f), Vector3f(0, 0, -1)), si));
    EXPECT_NEAR(si.t, 2.f, 1e-6f);
    expect_near_vec(si.p, Vector3f(1.f, 0.5f, 0.f), 1e-6f);
    expect_near_vec(si.n, Vector3f(0, 0, 1), 1e-6f);
    EXPECT_NEAR(si.uv.x, 0.75f, 1e-6f);
    EXPECT_NEAR(si.uv.y, 0.75f, 1e-6f);
    expect_near_vec(normalize(si.dp_du), Vector3f(1, 0, 0), 1e-6f);
    expect_near_vec(si.dp_du, Vector3f(4, 0, 0), 1e-5f); // u spans 4 units
    expect_near_vec(si.sh_frame.s, Vector3f(1, 0, 0), 1e-6f);
    expect_near_vec(si.sh_frame.t, Vector3f(0, 1, 0), 1e-6f);
    expect_near_vec(si.wi, Vector3f(0, 0, 1), 1e-6f);
    EXPECT_EQ(si.shape, rect.get());

    props.set_bool("flip_normals", true);
    auto flipped = make_shape("rectangle", props);
    SingleShape scene2(flipped);
    ASSERT_TRUE(scene2.intersect(Ray(Point3f(1.f, 0.5f, 2.f), Vector3f(0, 0, -1)), si));
    expect_near_vec(si.n, Vector3f(0, 0, -1), 1e-6f);
    EXPECT_NEAR(si.wi.z, -1.f, 1e-6f);
    EXPECT_NEAR(dot(cross(si.sh_frame.s, si.sh_frame.t), si.sh_frame.n), 1.f, 1e-6f);
    PositionSample ps = flipped->sample_position(Point2f(0.3f, 0.6f));
    expect_near_vec(ps.n, Vector3f(0, 0, -1), 1e-6f);
}

TEST(ShapeIntersection, MeshShadingNormalsAreInterpolated) {
    TempDir dir;
    std::string path = dir.write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                            "vn -1 0 1\nvn 1 0 1\nvn 0 0 1\n"
                                            "f 1//1 2//2 3//3\n");
    auto mesh = make_mesh("obj", file_props(path));
    EXPECT_FALSE(mesh->flat_faces()); // smooth: the frame is built at every hit
    SingleShape scene(mesh);
    SurfaceInteraction si;
    ASSERT_TRUE(scene.intersect(Ray(Point3f(0.5f, 0.25f, 1.f), Vector3f(0, 0, -1)), si));
    expect_near_vec(si.n, Vector3f(0, 0, 1), 1e-6f);
    // Barycentrics (0.25, 0.5, 0.25): normal ∝ 0.25·(-1,0,1)/√2 + 0.5·(1,0,1)/√2 + 0.25·(0,0,1).
    Vector3f expected =
        normalize(Vector3f(-1, 0, 1) * (0.25f / std::sqrt(2.f)) +
                  Vector3f(1, 0, 1) * (0.5f / std::sqrt(2.f)) + Vector3f(0, 0, 1) * 0.25f);
    expect_near_vec(si.sh_frame.n, expected, 1e-5f);
    // Without texture coordinates, uv are the barycentrics of vertices 1 and 2.
    EXPECT_NEAR(si.uv.x, 0.5f, 1e-6f);
    EXPECT_NEAR(si.uv.y, 0.25f, 1e-6f);
    expect_near_vec(si.p, Vector3f(0.5f, 0.25f, 0.f), 1e-6f);
    EXPECT_NEAR(si.sh_frame.n.x * si.sh_frame.s.x + si.sh_frame.n.y * si.sh_frame.s.y +
                    si.sh_frame.n.z * si.sh_frame.s.z,
                0.f, 1e-6f);
}

// ---------------------------------------------------------------------------------------------
// Direction sampling

namespace {

/// Monte Carlo estimate of ∫ pdf_direction dω over all directions from `ref`, the integrand
/// evaluated at the first visible point of `shape` along each uniform direction.
double integrate_direction_pdf(const Shape &shape, const SingleShape &scene, const Interaction &ref,
                               int n, uint64_t seed) {
    PCG32 rng(seed);
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        Vector3f d = warp::square_to_uniform_sphere(next_point2f(rng));
        SurfaceInteraction si;
        if (!scene.intersect(Ray(ref.p, d), si)) continue;
        DirectionSample ds;
        ds.p = si.p;
        ds.n = si.n;
        ds.uv = si.uv;
        ds.d = d;
        ds.dist = si.t;
        sum += shape.pdf_direction(ref, ds);
    }
    return sum / n * 4.0 * 3.14159265358979323846;
}

} // namespace

TEST(ShapeSampling, SphereDirectionPdfIntegratesToOne) {
    Properties props;
    props.set_vector("center", Vector3f(0, 0, 1));
    props.set_float("radius", 0.7);
    auto sphere = make_shape("sphere", props);
    SingleShape scene(sphere);
    for (Point3f ref_p : {Point3f(0, 0, -1), Point3f(0.3f, 2.f, 1.5f), Point3f(0.2f, 0.1f, 1.2f)}) {
        SCOPED_TRACE(ref_p);
        Interaction ref;
        ref.p = ref_p;
        double integral = integrate_direction_pdf(*sphere, scene, ref, 1000000, 17);
        EXPECT_NEAR(integral, 1.0, 0.02);
    }
}

TEST(ShapeSampling, SphereConeSamplingIsUniformInTheCone) {
    Properties props;
    props.set_float("radius", 0.5);
    auto sphere = make_shape("sphere", props);
    SingleShape scene(sphere);
    Interaction ref;
    ref.p = Point3f(0.f, 3.f, 0.f);
    ref.n = Normal3f(0.f, 1.f, 0.f);
    const double sin2_max = 0.25 / 9.0, one_minus_cos_max = 1.0 - std::sqrt(1.0 - sin2_max);
    const float expected_pdf = float(1.0 / (2.0 * 3.14159265358979323846 * one_minus_cos_max));
    // Histogram over (1 - cos θ) / (1 - cos θmax) and φ: 8 x 8 bins of equal solid angle.
    const int n = 64000, bins = 8;
    std::vector<int> hist(bins * bins, 0);
    PCG32 rng(99);
    for (int i = 0; i < n; ++i) {
        DirectionSample ds = sphere->sample_direction(ref, next_point2f(rng));
        ASSERT_NEAR(ds.pdf, expected_pdf, 1e-3f * expected_pdf);
        ASSERT_EQ(sphere->pdf_direction(ref, ds), ds.pdf); // one arithmetic for both
        ASSERT_NEAR(norm(ds.p), 0.5f, 1e-6f);
        ASSERT_GT(dot(ds.n, -ds.d), -1e-4f); // on the visible side
        ASSERT_NEAR(norm(ds.d), 1.f, 1e-5f);
        expect_near_vec(ref.p + ds.d * ds.dist, ds.p, 1e-5f);
        // The sampled point is the first hit along ds.d.
        SurfaceInteraction si;
        ASSERT_TRUE(scene.intersect(Ray(ref.p, ds.d), si));
        ASSERT_NEAR(si.t, ds.dist, 1e-4f);
        double c = -double(ds.d.y);
        double x = (1.0 - c) / one_minus_cos_max;
        double phi =
            std::atan2(double(ds.d.z), double(ds.d.x)) / (2.0 * 3.14159265358979323846) + 0.5;
        int bx = std::min(bins - 1, int(x * bins)), by = std::min(bins - 1, int(phi * bins));
        hist[by * bins + bx]++;
    }
    // Pearson χ² with 63 degrees of freedom: the 0.999 quantile is 103.4.
    double expected = double(n) / (bins * bins), chi2 = 0.0;
    for (int h : hist) chi2 += (h - expected) * (h - expected) / expected;
    EXPECT_LT(chi2, 103.4);
}

TEST(ShapeSampling, DefaultDirectionPdfMatchesAndIntegrates) {
    Properties props;
    props.set_transform("to_world", Transform::translate(Vector3f(0, 0, 1)));
    for (const char *type : {"rectangle", "disk", "cube"}) {
        SCOPED_TRACE(type);
        auto shape = make_shape(type, props);
        SingleShape scene(shape);
        Interaction ref;
        ref.p = Point3f(0.3f, -0.2f, -1.5f);
        PCG32 rng(1);
        for (int i = 0; i < 200; ++i) {
            DirectionSample ds = shape->sample_direction(ref, next_point2f(rng));
            ASSERT_GT(ds.pdf, 0.f);
            EXPECT_NEAR(shape->pdf_direction(ref, ds), ds.pdf, 1e-4f * ds.pdf);
            EXPECT_NEAR(norm(ds.d), 1.f, 1e-5f);
        }
        // Only the visible side counts for the cube: use a flat shape for the integral.
        if (std::string(type) != "cube") {
            double integral = integrate_direction_pdf(*shape, scene, ref, 1000000, 23);
            EXPECT_NEAR(integral, 1.0, 0.02);
        }
    }
}
