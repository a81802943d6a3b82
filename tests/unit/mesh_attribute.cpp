// Vertex colours of a PLY mesh read through the mesh_attribute texture: at a vertex the texture
// gives that vertex's colour, inside a triangle the barycentric blend.

#include <facet/bsdf.h>
#include <facet/scene.h>
#include <facet/texture.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

using namespace facet;
namespace fs = std::filesystem;

TEST(MeshAttribute, VertexColorsOfAPly) {
    fs::path dir = fs::temp_directory_path() / "facet-mesh-attribute";
    fs::create_directories(dir);
    fs::path ply = dir / "tri.ply";
    std::ofstream(ply) << "ply\nformat ascii 1.0\nelement vertex 3\n"
                          "property float x\nproperty float y\nproperty float z\n"
                          "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                          "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                          "0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n3 0 1 2\n";
    std::string xml = R"(<scene version="3.0.0">
        <shape type="ply">
            <string name="filename" value=")" +
                      ply.string() + R"("/>
            <bsdf type="diffuse">
                <texture type="mesh_attribute" name="reflectance" id="colors">
                    <string name="name" value="vertex_color"/>
                </texture>
            </bsdf>
        </shape>
    </scene>)";
    LoadOptions opts;
    auto scene = std::dynamic_pointer_cast<Scene>(load_string(xml, opts));
    ASSERT_TRUE(scene);
    // The diffuse albedo is the texture nested in the BSDF, evaluated at hits on the triangle.
    auto check = [&](float x, float y, const Color3f &expected) {
        SurfaceInteraction si;
        ASSERT_TRUE(scene->ray_intersect(Ray(Point3f(x, y, 1.f), Vector3f(0, 0, -1)), si));
        Color3f albedo = si.bsdf()->eval_diffuse_reflectance(si);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(albedo[c], expected[c], 2e-3f) << x << ", " << y;
    };
    check(0.01f, 0.01f, Color3f(0.98f, 0.01f, 0.01f));
    check(0.98f, 0.01f, Color3f(0.01f, 0.98f, 0.01f));
    check(0.25f, 0.25f, Color3f(0.5f, 0.25f, 0.25f));
}
