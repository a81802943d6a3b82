// Instancing: a scene that places a shapegroup three times with `instance` must look like the
// same scene with the shapes copied under the composed transforms. Geometry is compared through
// the aov integrator (depth and normals, no randomness beyond the shared pixel jitter), shading
// through the image means of a path-traced render.

#include "test_util.h"

#include <facet/image.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace facet;
using test::channel;
using test::render_xml;

namespace {

const char *SENSOR = R"(
    <sensor type="perspective">
        <float name="fov" value="50"/>
        <transform name="to_world"><lookat origin="0, 4, 9" target="0, 0.5, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="16"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="48"/><integer name="height" value="32"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
    <shape type="rectangle">
        <transform name="to_world"><scale value="10"/><rotate x="1" angle="-90"/></transform>
    </shape>
)";

const char *MEMBERS = R"(
        <shape type="sphere">
            <point name="center" x="0" y="0.5" z="0"/><float name="radius" value="0.5"/>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.2, 0.2"/></bsdf>
        </shape>
        <shape type="cube">
            <transform name="to_world"><scale value="0.3"/><translate x="0.9" y="0.3" z="0"/></transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.7, 0.3"/></bsdf>
        </shape>
)";

const char *PLACEMENTS[] = {
    R"(<translate x="-2.5"/>)",
    R"(<rotate y="1" angle="40"/>)",
    R"(<scale value="0.8"/><rotate y="1" angle="-70"/><translate x="2.5" z="0.5"/>)",
};

std::string instanced_scene(const std::string &integrator) {
    std::string xml = "<scene version=\"3.0.0\">" + integrator + SENSOR +
                      "<shape type=\"shapegroup\" id=\"group\">" + MEMBERS + "</shape>";
    for (const char *p : PLACEMENTS)
        xml += std::string(
                   "<shape type=\"instance\"><ref id=\"group\"/><transform name=\"to_world\">") +
               p + "</transform></shape>";
    return xml + "</scene>";
}

/// The same members written out per placement: the sphere becomes a sphere with a to_world, the
/// cube's own transform is followed by the placement.
std::string copied_scene(const std::string &integrator) {
    std::string xml = "<scene version=\"3.0.0\">" + integrator + SENSOR;
    for (const char *p : PLACEMENTS) {
        xml += std::string(R"(<shape type="sphere"><transform name="to_world">)") +
               R"(<scale value="0.5"/><translate y="0.5"/>)" + p + R"(</transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.2, 0.2"/></bsdf></shape>)";
        xml += std::string(R"(<shape type="cube"><transform name="to_world">)") +
               R"(<scale value="0.3"/><translate x="0.9" y="0.3" z="0"/>)" + p + R"(</transform>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.7, 0.3"/></bsdf></shape>)";
    }
    return xml + "</scene>";
}

} // namespace

TEST(Instancing, GeometryMatchesCopiedShapes) {
    const std::string aov =
        R"(<integrator type="aov"><string name="aovs" value="dd:depth, nn:sh_normal"/></integrator>)";
    Image a = render_xml(instanced_scene(aov)), b = render_xml(copied_scene(aov));
    ASSERT_EQ(a.channel_names, b.channel_names);
    int depth = channel(a, "dd"), nx = channel(a, "nn.X");
    ASSERT_GE(depth, 0);
    ASSERT_GE(nx, 0);
    int pixels = a.width * a.height, agree = 0, covered = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            float da = a.at(x, y, depth), db = b.at(x, y, depth);
            bool ok = std::abs(da - db) <= 1e-3f * std::max(1.f, db);
            for (int c = 0; c < 3; ++c)
                ok &= std::abs(a.at(x, y, nx + c) - b.at(x, y, nx + c)) < 1e-3f;
            agree += ok;
        }
    // Pixels straddling an edge may average slightly different hit sets; nearly all must agree.
    EXPECT_GE(agree, int(0.98 * pixels)) << agree << " of " << pixels << " pixels agree";
    // And the instances are actually there: the groups cover a good part of the image.
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            covered += a.at(x, y, depth) > 0.f && a.at(x, y, depth) < 8.5f;
    EXPECT_GT(covered, pixels / 10);
}

TEST(Instancing, ShadingMatchesCopiedShapes) {
    const std::string path =
        R"(<integrator type="path"><integer name="max_depth" value="4"/></integrator>)";
    Image a = render_xml(instanced_scene(path)), b = render_xml(copied_scene(path));
    for (int c = 0; c < 3; ++c) {
        double ma = 0, mb = 0;
        for (int y = 0; y < a.height; ++y)
            for (int x = 0; x < a.width; ++x) {
                ma += a.at(x, y, c);
                mb += b.at(x, y, c);
            }
        ma /= a.width * a.height;
        mb /= b.width * b.height;
        EXPECT_NEAR(ma, mb, 0.01 * mb) << "channel " << c;
    }
}
