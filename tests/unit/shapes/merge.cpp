// The merge shape: which nested meshes become one (Mitsuba 3's rule: the same BSDF object, no
// emitter or sensor, no mesh attributes, the same vertex-normal and texture-coordinate layout;
// facet adds flip_normals), how many shapes the scene then holds, that the merged mesh carries
// every member's triangles, normals and uvs, and the errors.
#include <facet/mesh.h>
#include <facet/scene.h>
#include <facet/shapegroup.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <string>

using namespace facet;

namespace {

std::shared_ptr<Scene> scene_of(const std::string &body) {
    return std::dynamic_pointer_cast<Scene>(
        load_string("<scene version=\"3.0.0\"><bsdf type=\"diffuse\" id=\"a\"/>"
                    "<bsdf type=\"diffuse\" id=\"b\"/>" +
                    body + "</scene>"));
}

std::string ply(const std::string &extra = "") {
    return "<shape type=\"ply\"><string name=\"filename\" value=\"" +
           std::string(FACET_SOURCE_DIR) +
           "/tests/data/plugin_docs/triangle.ply\"/><boolean name=\"face_normals\" "
           "value=\"true\"/>" +
           extra + "</shape>";
}

std::string cube(const std::string &extra = "", float x = 0.f) {
    return "<shape type=\"cube\"><transform name=\"to_world\"><translate x=\"" + std::to_string(x) +
           "\"/></transform>" + extra + "</shape>";
}

std::string rect(const std::string &extra = "") {
    return "<shape type=\"rectangle\">" + extra + "</shape>";
}

std::string merge(const std::string &children, const std::string &id = "") {
    return "<shape type=\"merge\"" + (id.empty() ? std::string() : " id=\"" + id + "\"") + ">" +
           children + "</shape>";
}

const std::string A = "<ref id=\"a\"/>", B = "<ref id=\"b\"/>";

size_t faces(const Shape &shape) {
    auto mesh = dynamic_cast<const Mesh *>(&shape);
    return mesh ? mesh->face_count() : 0;
}

} // namespace

TEST(Merge, MitsubaCounts) {
    // The cases of Mitsuba 3's test_merge.py.
    EXPECT_EQ(scene_of(merge(ply()))->shapes().size(), 1u);
    EXPECT_EQ(scene_of(merge(ply("<bsdf type=\"diffuse\"/>")))->shapes().size(), 1u);
    EXPECT_EQ(scene_of(merge(ply() + ply()))->shapes().size(), 2u) << "no BSDF: not merged";
    EXPECT_EQ(scene_of(merge(ply("<bsdf type=\"diffuse\"/>") + ply()))->shapes().size(), 2u);
    EXPECT_EQ(scene_of(merge(ply(A) + ply(A)))->shapes().size(), 1u) << "same BSDF: merged";
    EXPECT_EQ(scene_of(merge(ply(A) + "<shape type=\"sphere\">" + A + "</shape>"))->shapes().size(),
              2u)
        << "a sphere is not a mesh";
}

TEST(Merge, GroupsByBsdfAndLayout) {
    // Cubes have normals and uvs, rectangles only uvs, the face-normal ply neither.
    auto scene = scene_of(merge(cube(A, 0) + rect(B) + cube(A, 3) + cube(B, 6) + rect(B) + ply(A) +
                                cube(A, 9) + ply(A)));
    const auto &shapes = scene->shapes();
    ASSERT_EQ(shapes.size(), 4u); // cubes A, rectangles B, cube B, plies A
    EXPECT_EQ(faces(*shapes[0]), 3u * 12u);
    EXPECT_EQ(faces(*shapes[1]), 2u * 2u);
    EXPECT_EQ(faces(*shapes[2]), 12u);
    EXPECT_EQ(faces(*shapes[3]), 2u * faces(*scene_of(ply())->shapes()[0]));
    EXPECT_EQ(shapes[0]->bsdf(), shapes[3]->bsdf());
    EXPECT_NE(shapes[0]->bsdf(), shapes[1]->bsdf());
    auto merged = dynamic_cast<const Mesh *>(shapes[0].get());
    ASSERT_NE(merged, nullptr);
    EXPECT_EQ(merged->vertex_count(), 3u * 24u);
    EXPECT_TRUE(merged->has_vertex_normals());
    EXPECT_TRUE(merged->has_uvs());
    // The members keep their world positions: the box spans the three cubes.
    EXPECT_FLOAT_EQ(merged->bbox().min.x, -1.f);
    EXPECT_FLOAT_EQ(merged->bbox().max.x, 10.f);
    EXPECT_FALSE(dynamic_cast<const Mesh *>(shapes[3].get())->has_vertex_normals());
}

TEST(Merge, EmittersAttributesAndFlipsStayApart) {
    const std::string light =
        "<emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter>";
    auto scene = scene_of(merge(rect(A + light) + rect(A + light) + rect(A)));
    EXPECT_EQ(scene->shapes().size(), 3u);
    EXPECT_EQ(scene->emitters().size(), 2u);
    EXPECT_EQ(scene_of(merge(rect(A) + rect(A + "<boolean name=\"flip_normals\" value=\"true\"/>")))
                  ->shapes()
                  .size(),
              2u);
    EXPECT_EQ(scene_of(merge(rect(A) + rect(A) +
                             rect(A + "<boolean name=\"flip_normals\" "
                                      "value=\"true\"/>")))
                  ->shapes()
                  .size(),
              2u);
}

TEST(Merge, NestedMergesShapeGroupsAndIds) {
    auto scene = scene_of(merge(merge(cube(A, 0) + cube(A, 3)) + cube(A, 6), "boxes"));
    ASSERT_EQ(scene->shapes().size(), 1u);
    EXPECT_EQ(faces(*scene->shapes()[0]), 36u);
    EXPECT_EQ(scene->shapes()[0]->id(), "boxes");

    auto grouped =
        scene_of("<shape type=\"shapegroup\" id=\"g\">" + merge(cube(A, 0) + cube(A, 3) + rect(B)) +
                 "</shape><shape type=\"instance\"><ref id=\"g\"/></shape>");
    ASSERT_EQ(grouped->shapes().size(), 2u); // the group and its instance
    auto group = dynamic_cast<const ShapeGroup *>(grouped->shapes()[0].get());
    ASSERT_NE(group, nullptr);
    EXPECT_EQ(group->shapes().size(), 2u);
}

TEST(Merge, Errors) {
    auto error_of = [](const std::string &body) -> std::string {
        try {
            scene_of(body);
        } catch (const Error &e) {
            return e.what();
        }
        return "no error";
    };
    EXPECT_NE(error_of(merge("<bsdf type=\"diffuse\"/>")).find("only shapes"), std::string::npos);
    EXPECT_NE(error_of(merge("")).find("no shapes"), std::string::npos);
    // merge takes no parameters: an unused one is an error, as for every plugin.
    EXPECT_NE(
        error_of("<shape type=\"merge\"><float name=\"scale\" value=\"2\"/>" + cube(A) + "</shape>")
            .find("scale"),
        std::string::npos);
}
