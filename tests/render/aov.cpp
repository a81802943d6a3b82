// The aov and depth integrators on a scene whose answers are known: an orthographic camera
// looking straight down at a plane 3 units away, with a sphere on part of the image.

#include "test_util.h"

#include <facet/image.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

using namespace facet;
using test::channel;

namespace {

std::string scene(const std::string &integrator) {
    return R"(<scene version="3.0.0">)" + integrator + R"(
    <sensor type="orthographic">
        <transform name="to_world"><scale value="2"/><lookat origin="0, 3, 0" target="0, 0, 0" up="0, 0, -1"/></transform>
        <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="20"/><integer name="height" value="20"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <emitter type="constant"/>
    <shape type="rectangle">
        <transform name="to_world"><scale value="5"/><rotate x="1" angle="-90"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.4, 0.6"/></bsdf>
    </shape>
    <shape type="sphere">
        <point name="center" x="1.5" y="0" z="1.5"/><float name="radius" value="0.3"/>
    </shape>
</scene>)";
}

Image render_scene(const std::string &integrator) { return test::render_xml(scene(integrator)); }

} // namespace

TEST(DepthIntegrator, DistanceToThePlane) {
    Image img = render_scene(R"(<integrator type="depth"/>)");
    // Pixels at the image centre see the plane 3 units below the camera.
    for (int y = 8; y < 12; ++y)
        for (int x = 8; x < 12; ++x)
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(img.at(x, y, c), 3.f, 1e-3f);
}

TEST(AovIntegrator, ChannelsAndValues) {
    Image img = render_scene(R"(<integrator type="aov">
        <string name="aovs" value="alb:albedo, dd:depth, nn:sh_normal, pp:position, id:shape_index"/>
        <integrator type="path"/>
    </integrator>)");
    std::vector<std::string> expected = {"R",    "G",    "B",    "alb.R", "alb.G", "alb.B", "dd",
                                         "nn.X", "nn.Y", "nn.Z", "pp.X",  "pp.Y",  "pp.Z",  "id"};
    for (const std::string &name : expected) EXPECT_GE(channel(img, name), 0) << name;
    int alb = channel(img, "alb.R"), dd = channel(img, "dd"), nn = channel(img, "nn.X"),
        pp = channel(img, "pp.X"), id = channel(img, "id");
    ASSERT_TRUE(alb >= 0 && dd >= 0 && nn >= 0 && pp >= 0 && id >= 0);
    // The centre pixels see the plane: albedo of its BSDF, depth 3, normal +Y, y = 0, shape 0.
    for (int y = 8; y < 12; ++y)
        for (int x = 8; x < 12; ++x) {
            EXPECT_NEAR(img.at(x, y, alb), 0.2f, 1e-4f);
            EXPECT_NEAR(img.at(x, y, alb + 2), 0.6f, 1e-4f);
            EXPECT_NEAR(img.at(x, y, dd), 3.f, 1e-3f);
            EXPECT_NEAR(img.at(x, y, nn + 1), 1.f, 1e-4f);
            EXPECT_NEAR(img.at(x, y, pp + 1), 0.f, 1e-4f);
            EXPECT_EQ(img.at(x, y, id), 0.f);
        }
    // Somewhere the sphere (shape 1, default albedo 0.5) is seen, closer than the plane.
    bool sphere_seen = false;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            if (img.at(x, y, id) == 1.f) {
                sphere_seen = true;
                EXPECT_LT(img.at(x, y, dd), 3.f);
                EXPECT_NEAR(img.at(x, y, alb), 0.5f, 1e-4f);
            }
    EXPECT_TRUE(sphere_seen);
}

TEST(AovIntegrator, UnknownTypeIsAnError) {
    try {
        render_scene(
            R"(<integrator type="aov"><string name="aovs" value="x:normals"/></integrator>)");
        FAIL();
    } catch (const std::exception &e) {
        EXPECT_NE(std::string(e.what()).find("unknown AOV type \"normals\""), std::string::npos)
            << e.what();
    }
}
