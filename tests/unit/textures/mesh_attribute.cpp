// PLY vertex and face attributes and the mesh_attribute texture, as Mitsuba 3.8 has them: the
// grouping of PLY properties into named attributes (vertex_color, vertex_tint_color,
// face_weight, ...), raw integer values, barycentric interpolation of vertex attributes and
// constant face attributes, `scale`, colour and scalar queries, and the errors (an attribute
// the shape lacks, a bad name, a header count the file cannot hold).

#include <facet/bsdf.h>
#include <facet/mesh.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/scene.h>
#include <facet/texture.h>
#include <facet/xml.h>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>

using namespace facet;
namespace fs = std::filesystem;

namespace {

/// A folder of its own for each test (ctest runs the tests of this file in parallel).
fs::path test_dir() {
    const auto *info = ::testing::UnitTest::GetInstance()->current_test_info();
    fs::path dir = fs::temp_directory_path() / fmt::format("facet-mesh-attribute-{}", info->name());
    fs::create_directories(dir);
    return dir;
}

std::string write(const fs::path &path, const std::string &text) {
    std::ofstream(path, std::ios::binary) << text;
    return path.string();
}

std::shared_ptr<Scene> scene_of(const std::string &shapes) {
    LoadOptions opts;
    return std::dynamic_pointer_cast<Scene>(
        load_string("<scene version=\"3.0.0\">" + shapes + "</scene>", opts));
}

std::string load_error(const std::string &shapes) {
    try {
        scene_of(shapes);
    } catch (const Error &e) {
        return e.what();
    }
    ADD_FAILURE() << "expected an error";
    return {};
}

std::shared_ptr<Texture> make_attribute(const std::string &name, double scale = 1.0) {
    Properties props("mesh_attribute");
    props.set_string("name", name);
    if (scale != 1.0) props.set_float("scale", scale);
    return PluginRegistry::instance().create_as<Texture>(ObjectType::Texture, props);
}

std::string ply_shape(const std::string &file, const std::string &bsdf = "") {
    return fmt::format(R"(<shape type="ply"><string name="filename" value="{}"/>{}</shape>)", file,
                       bsdf);
}

/// The hit of a ray straight down at (x, y) (the test meshes lie in z = 0).
SurfaceInteraction hit(const Scene &scene, float x, float y) {
    SurfaceInteraction si;
    EXPECT_TRUE(scene.ray_intersect(Ray(Point3f(x, y, 1.f), Vector3f(0, 0, -1)), si));
    return si;
}

template <typename T> void put(std::string &s, T v, bool big) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (big) std::reverse(b, b + sizeof(T));
    s.append(b, sizeof(T));
}

/// A unit square of two triangles with every kind of attribute property, in `format`.
std::string attribute_ply(const std::string &format) {
    std::string s = "ply\nformat " + format +
                    " 1.0\nelement vertex 4\n"
                    "property float x\nproperty float y\nproperty float z\n"
                    "property float color_0\nproperty float color_1\nproperty float color_2\n"
                    "property float tint_r\nproperty float tint_g\nproperty float tint_b\n"
                    "property uchar mass_x\n" // one member of x y z w: vertex_mass
                    "property float pair_x\nproperty float pair_y\n" // two members: ignored
                    "property float quality\n"                       // no suffix: ignored
                    "element face 2\nproperty list uchar int vertex_indices\n"
                    "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                    "property float weight_0\n"
                    "end_header\n";
    const float pos[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const float color[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.5f, 0.5f, 0.5f}};
    const float tint[4][3] = {
        {0.1f, 0.2f, 0.3f}, {0.4f, 0.5f, 0.6f}, {0.7f, 0.8f, 0.9f}, {0.f, 0.f, 0.f}};
    const int mass[4] = {10, 20, 30, 40};
    const int faces[2][3] = {{0, 1, 2}, {0, 2, 3}};
    const int rgb[2][3] = {{255, 128, 0}, {0, 64, 32}};
    const float weight[2] = {0.25f, 0.75f};
    if (format == "ascii") {
        for (int i = 0; i < 4; ++i)
            s += fmt::format("{} {} {} {} {} {} {} {} {} {} 7 8 9\n", pos[i][0], pos[i][1],
                             pos[i][2], color[i][0], color[i][1], color[i][2], tint[i][0],
                             tint[i][1], tint[i][2], mass[i]);
        for (int f = 0; f < 2; ++f)
            s += fmt::format("3 {} {} {} {} {} {} {}\n", faces[f][0], faces[f][1], faces[f][2],
                             rgb[f][0], rgb[f][1], rgb[f][2], weight[f]);
        return s;
    }
    bool big = format == "binary_big_endian";
    for (int i = 0; i < 4; ++i) {
        for (float v : pos[i]) put(s, v, big);
        for (float v : color[i]) put(s, v, big);
        for (float v : tint[i]) put(s, v, big);
        put(s, uint8_t(mass[i]), big);
        for (float v : {7.f, 8.f, 9.f}) put(s, v, big);
    }
    for (int f = 0; f < 2; ++f) {
        put(s, uint8_t(3), big);
        for (int i : faces[f]) put(s, int32_t(i), big);
        for (int c : rgb[f]) put(s, uint8_t(c), big);
        put(s, weight[f], big);
    }
    return s;
}

} // namespace

TEST(MeshAttribute, PlyPropertiesAreGroupedAsMitsubaGroupsThem) {
    fs::path dir = test_dir();
    for (const char *format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
        SCOPED_TRACE(format);
        auto scene =
            scene_of(ply_shape(write(dir / (std::string(format) + ".ply"), attribute_ply(format))));
        ASSERT_TRUE(scene);
        SurfaceInteraction si = hit(*scene, 0.6f, 0.2f); // in face 0
        const auto *mesh = dynamic_cast<const Mesh *>(si.shape);
        ASSERT_TRUE(mesh);
        EXPECT_EQ(mesh->attribute_names(),
                  "vertex_color, vertex_tint_color, vertex_mass, face_color, face_weight");
        const Mesh::Attribute *mass = mesh->attribute("vertex_mass");
        ASSERT_TRUE(mass);
        EXPECT_EQ(mass->channels, 1u);
        // Integer properties stay raw (no division by 255, no sRGB decoding).
        EXPECT_EQ(mass->data, (std::vector<float>{10, 20, 30, 40}));
        const Mesh::Attribute *face_color = mesh->attribute("face_color");
        ASSERT_TRUE(face_color);
        EXPECT_TRUE(face_color->per_face);
        EXPECT_EQ(face_color->data, (std::vector<float>{255, 128, 0, 0, 64, 32}));
        EXPECT_EQ(mesh->attribute("face_weight")->data, (std::vector<float>{0.25f, 0.75f}));
        EXPECT_EQ(mesh->attribute("vertex_tint_color")->channels, 3u);
        EXPECT_FALSE(mesh->attribute("vertex_pair"));
        EXPECT_FALSE(mesh->attribute("vertex_quality"));
    }
}

TEST(MeshAttribute, VertexAttributesInterpolateFaceAttributesAreConstant) {
    fs::path dir = test_dir();
    auto scene = scene_of(ply_shape(write(dir / "a.ply", attribute_ply("binary_little_endian"))));
    ASSERT_TRUE(scene);
    auto color = make_attribute("vertex_color"), tint = make_attribute("vertex_tint_color", 2.0);
    auto face_color = make_attribute("face_color", 1.0 / 255.0);
    auto weight = make_attribute("face_weight", 0.8), mass = make_attribute("vertex_mass");

    // Face 0 = vertices 0, 1, 2 at (0,0), (1,0), (1,1): (0.75, 0.25) has barycentrics
    // (0.25, 0.5, 0.25).
    SurfaceInteraction si = hit(*scene, 0.75f, 0.25f);
    ASSERT_EQ(si.prim_index, 0u);
    Color3f c = color->eval(si);
    EXPECT_NEAR(c.r, 0.25f, 1e-5f);
    EXPECT_NEAR(c.g, 0.5f, 1e-5f);
    EXPECT_NEAR(c.b, 0.25f, 1e-5f);
    Color3f t = tint->eval(si); // scale 2
    EXPECT_NEAR(t.r, 2.f * (0.25f * 0.1f + 0.5f * 0.4f + 0.25f * 0.7f), 1e-5f);
    EXPECT_NEAR(t.b, 2.f * (0.25f * 0.3f + 0.5f * 0.6f + 0.25f * 0.9f), 1e-5f);
    EXPECT_NEAR(mass->eval_1(si), 0.25f * 10 + 0.5f * 20 + 0.25f * 30, 1e-4f);
    // A 1-channel attribute answers colour queries as a grey.
    EXPECT_NEAR(mass->eval(si).g, 20.f, 1e-4f);

    // Face attributes: the same value anywhere on the triangle, scaled.
    for (auto [x, y] : {std::pair{0.75f, 0.25f}, {0.9f, 0.05f}, {0.98f, 0.9f}}) {
        SurfaceInteraction s = hit(*scene, x, y);
        ASSERT_EQ(s.prim_index, 0u);
        EXPECT_NEAR(weight->eval_1(s), 0.8f * 0.25f, 1e-6f);
        Color3f fc = face_color->eval(s);
        EXPECT_NEAR(fc.r, 1.f, 1e-6f);
        EXPECT_NEAR(fc.g, 128.f / 255.f, 1e-6f);
        EXPECT_EQ(fc.b, 0.f);
    }
    SurfaceInteraction other = hit(*scene, 0.2f, 0.7f);
    ASSERT_EQ(other.prim_index, 1u);
    EXPECT_NEAR(weight->eval_1(other), 0.8f * 0.75f, 1e-6f);

    // A scalar query of a 3-channel attribute is an error (Mitsuba's eval_1 needs 1 channel).
    try {
        color->eval_1(si);
        ADD_FAILURE() << "expected an error";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("3 channels"), std::string::npos) << e.what();
    }
}

TEST(MeshAttribute, DrivesABlendWeightAndAReflectance) {
    // The peer scene's pattern: a face_weight blend of a vertex_color and a face_color diffuse.
    fs::path dir = test_dir();
    std::string file = write(dir / "a.ply", attribute_ply("ascii"));
    auto scene = scene_of(ply_shape(file, R"(<bsdf type="blendbsdf">
            <texture type="mesh_attribute" name="weight"><string name="name" value="face_weight"/></texture>
            <bsdf type="diffuse"><texture type="mesh_attribute" name="reflectance">
                <string name="name" value="vertex_color"/></texture></bsdf>
            <bsdf type="diffuse"><texture type="mesh_attribute" name="reflectance">
                <string name="name" value="face_color"/>
                <float name="scale" value="0.003921569"/></texture></bsdf>
        </bsdf>)"));
    ASSERT_TRUE(scene);
    SurfaceInteraction si = hit(*scene, 0.75f, 0.25f);
    si.wi = Vector3f(0.f, 0.f, 1.f);
    Vector3f wo = normalize(Vector3f(0.2f, 0.1f, 1.f));
    Color3f f = si.bsdf()->eval(BSDFContext(), si, wo);
    // weight 0.25: 0.75 · (0.25, 0.5, 0.25)/π + 0.25 · (1, 128/255, 0)/π, times cos θo.
    Color3f expected =
        (Color3f(0.25f, 0.5f, 0.25f) * 0.75f + Color3f(1.f, 128.f / 255.f, 0.f) * 0.25f) *
        (InvPi * wo.z);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[c], expected[c], 1e-5f);
}

TEST(MeshAttribute, VertexColorsOfAnAsciiPly) {
    fs::path dir = test_dir();
    std::string ply = write(dir / "tri.ply",
                            "ply\nformat ascii 1.0\nelement vertex 3\n"
                            "property float x\nproperty float y\nproperty float z\n"
                            "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                            "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                            "0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n3 0 1 2\n");
    auto scene = scene_of(ply_shape(ply, R"(<bsdf type="diffuse">
            <texture type="mesh_attribute" name="reflectance">
                <string name="name" value="vertex_color"/>
                <float name="scale" value="0.003921569"/>
            </texture></bsdf>)"));
    ASSERT_TRUE(scene);
    auto check = [&](float x, float y, const Color3f &expected) {
        SurfaceInteraction si = hit(*scene, x, y);
        Color3f albedo = si.bsdf()->eval_diffuse_reflectance(si);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(albedo[c], expected[c], 2e-3f) << x << ", " << y;
    };
    check(0.01f, 0.01f, Color3f(0.98f, 0.01f, 0.01f));
    check(0.98f, 0.01f, Color3f(0.01f, 0.98f, 0.01f));
    check(0.25f, 0.25f, Color3f(0.5f, 0.25f, 0.25f));
}

TEST(MeshAttribute, PolygonsCarryTheirFaceAttributeToEveryTriangle) {
    fs::path dir = test_dir();
    std::string ply =
        write(dir / "quad.ply", "ply\nformat ascii 1.0\nelement vertex 4\n"
                                "property float x\nproperty float y\nproperty float z\n"
                                "element face 1\nproperty list uchar int vertex_indices\n"
                                "property float weight_1\nend_header\n"
                                "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3 0.5\n");
    auto scene = scene_of(ply_shape(ply));
    ASSERT_TRUE(scene);
    const auto *mesh = dynamic_cast<const Mesh *>(hit(*scene, 0.5f, 0.5f).shape);
    ASSERT_TRUE(mesh);
    EXPECT_EQ(mesh->face_count(), 2u);
    EXPECT_EQ(mesh->attribute("face_weight")->data, (std::vector<float>{0.5f, 0.5f}));
}

TEST(MeshAttribute, AMissingAttributeIsAnErrorNamingTheShape) {
    fs::path dir = test_dir();
    std::string ply = write(dir / "patch.ply", attribute_ply("ascii"));
    auto textured = [](const std::string &name) {
        return fmt::format(R"(<bsdf type="diffuse"><texture type="mesh_attribute"
            name="reflectance"><string name="name" value="{}"/></texture></bsdf>)",
                           name);
    };
    // A PLY without it: the error names the file and lists what the mesh has.
    std::string msg = load_error(ply_shape(ply, textured("vertex_weight")));
    EXPECT_NE(msg.find("\"vertex_weight\""), std::string::npos) << msg;
    EXPECT_NE(msg.find("patch.ply"), std::string::npos) << msg;
    EXPECT_NE(msg.find("vertex_color, vertex_tint_color"), std::string::npos) << msg;

    // Nested deeper (a blend weight) and through a reference: still found when loading.
    msg = load_error(R"(<bsdf type="blendbsdf" id="b"><texture type="mesh_attribute" name="weight">
            <string name="name" value="face_missing"/></texture>
            <bsdf type="diffuse"/><bsdf type="diffuse"/></bsdf>)" +
                     ply_shape(ply, R"(<ref id="b"/>)"));
    EXPECT_NE(msg.find("face_missing"), std::string::npos) << msg;
    EXPECT_NE(msg.find("patch.ply"), std::string::npos) << msg;

    // OBJ meshes and analytic shapes have no attributes at all.
    std::string obj = write(dir / "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    msg = load_error(
        fmt::format(R"(<shape type="obj"><string name="filename" value="{}"/>{}</shape>)", obj,
                    textured("vertex_color")));
    EXPECT_NE(msg.find("vertex_color"), std::string::npos) << msg;
    EXPECT_NE(msg.find("tri.obj"), std::string::npos) << msg;
    EXPECT_NE(msg.find("none"), std::string::npos) << msg;
    msg = load_error(R"(<shape type="sphere">)" + textured("vertex_color") + "</shape>");
    EXPECT_NE(msg.find("vertex_color"), std::string::npos) << msg;
    EXPECT_NE(msg.find("sphere"), std::string::npos) << msg;

    // The texture alone is fine (no shape yet); evaluating it on a shape without the attribute
    // (a scene built by hand) is the same error, not black.
    auto scene = scene_of(ply_shape(ply));
    SurfaceInteraction si = hit(*scene, 0.5f, 0.2f);
    try {
        make_attribute("vertex_nothing")->eval(si);
        ADD_FAILURE() << "expected an error";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("patch.ply"), std::string::npos) << e.what();
    }
}

TEST(MeshAttribute, RejectsBadParameters) {
    try {
        make_attribute("color");
        ADD_FAILURE() << "expected an error";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("must start with \"vertex_\" or \"face_\""),
                  std::string::npos)
            << e.what();
    }
    Properties all("mesh_attribute");
    all.set_string("name", "face_weight");
    all.set_float("scale", 0.5);
    auto tex = PluginRegistry::instance().create_as<Texture>(ObjectType::Texture, all);
    EXPECT_NE(tex->to_string().find("face_weight"), std::string::npos);
    std::string doc =
        PluginRegistry::instance().descriptor("mesh_attribute", ObjectType::Texture).doc;
    for (const std::string &name : all.requested_names())
        EXPECT_NE(doc.find("| " + name + " "), std::string::npos) << name;
}

TEST(MeshAttribute, HeaderCountsBeyondTheFileAreErrors) {
    fs::path dir = test_dir();
    const char *header = "ply\nformat {} 1.0\nelement vertex {}\nproperty float x\n"
                         "property float y\nproperty float z\nproperty uchar red\n"
                         "property uchar green\nproperty uchar blue\nelement face {}\n"
                         "property list uchar int vertex_indices\nend_header\n";
    for (const char *format : {"ascii", "binary_little_endian"}) {
        for (auto [nv, nf] : {std::pair<const char *, const char *>{"1000000000000000", "1"},
                              {"18446744073709551615", "1"},
                              {"3", "6148914691236517206"},
                              {"3", "4000000000"}}) {
            SCOPED_TRACE(fmt::format("{} {} {}", format, nv, nf));
            std::string body = std::string(format) == "ascii"
                                   ? "0 0 0 1 2 3\n1 0 0 1 2 3\n0 1 0 1 2 3\n3 0 1 2\n"
                                   : std::string(3 * 15 + 13, '\0');
            std::string file =
                write(dir / "huge.ply", fmt::format(fmt::runtime(header), format, nv, nf) + body);
            std::string msg = load_error(ply_shape(file));
            EXPECT_NE(msg.find("huge.ply"), std::string::npos) << msg;
        }
    }
}
