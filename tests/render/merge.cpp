// A scene of many meshes renders the same with its meshes under a `merge` as without: the
// merged meshes hold the members' world-space vertices, normals and uvs bit for bit, the hit
// distances and barycentrics of a triangle do not depend on which Embree geometry holds it, and
// the emitters keep their order, so the path tracer draws the same random numbers for every
// path. The images are compared bit for bit.

#include <facet/image.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <string>

using namespace facet;

namespace {

std::string shapes() {
    std::string s;
    // A floor and a back wall (rectangles), nine cubes in two materials, a ply triangle each.
    s += R"(<shape type="rectangle"><transform name="to_world"><scale value="6"/>
            <rotate x="1" angle="-90"/></transform><ref id="grey"/></shape>)";
    s += R"(<shape type="rectangle"><transform name="to_world"><scale value="6"/>
            <translate z="-3"/></transform><ref id="grey"/></shape>)";
    for (int i = 0; i < 9; ++i) {
        float x = -2.4f + 0.6f * float(i), h = 0.15f + 0.05f * float(i % 4);
        s += "<shape type=\"cube\"><transform name=\"to_world\"><scale value=\"" +
             std::to_string(h) + "\"/><rotate y=\"1\" angle=\"" + std::to_string(17 * i) +
             "\"/><translate x=\"" + std::to_string(x) + "\" y=\"" + std::to_string(h) +
             "\"/></transform><ref id=\"" + (i % 3 ? "red" : "rough") + "\"/></shape>";
    }
    s += R"(<shape type="rectangle"><transform name="to_world"><scale value="0.8"/>
            <rotate x="1" angle="90"/><translate y="3"/></transform>
            <emitter type="area"><rgb name="radiance" value="12"/></emitter></shape>)";
    return s;
}

std::string scene_xml(bool merged) {
    std::string xml = R"(<scene version="3.0.0">
        <integrator type="path"><integer name="max_depth" value="5"/></integrator>
        <sensor type="perspective">
            <float name="fov" value="45"/>
            <transform name="to_world"><lookat origin="0, 2.5, 7" target="0, 0.4, 0" up="0, 1, 0"/></transform>
            <sampler type="independent"><integer name="sample_count" value="8"/></sampler>
            <film type="hdrfilm"><integer name="width" value="48"/><integer name="height" value="32"/>
                <rfilter type="box"/></film>
        </sensor>
        <emitter type="constant"><rgb name="radiance" value="0.2"/></emitter>
        <bsdf type="diffuse" id="grey"><rgb name="reflectance" value="0.6"/></bsdf>
        <bsdf type="diffuse" id="red"><rgb name="reflectance" value="0.7, 0.2, 0.1"/></bsdf>
        <bsdf type="roughconductor" id="rough"><float name="alpha" value="0.2"/></bsdf>)";
    xml += merged ? "<shape type=\"merge\">" + shapes() + "</shape>" : shapes();
    return xml + "</scene>";
}

} // namespace

TEST(Merge, RendersLikeSeparateMeshes) {
    auto separate = std::dynamic_pointer_cast<Scene>(load_string(scene_xml(false)));
    auto merged = std::dynamic_pointer_cast<Scene>(load_string(scene_xml(true)));
    // Grey rectangles, red cubes, rough cubes and the light: 12 shapes become 4.
    EXPECT_EQ(separate->shapes().size(), 12u);
    EXPECT_EQ(merged->shapes().size(), 4u);
    RenderOptions opts;
    opts.progress = false;
    Image a = render(*separate, *separate->sensors().at(0), opts).image;
    Image b = render(*merged, *merged->sensors().at(0), opts).image;
    ASSERT_EQ(a.width, b.width);
    ASSERT_EQ(a.height, b.height);
    ASSERT_EQ(a.channel_names, b.channel_names);
    size_t differ = 0, lit = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < 3; ++c) {
                differ += a.at(x, y, c) != b.at(x, y, c);
                lit += a.at(x, y, c) > 0.f;
            }
    EXPECT_EQ(differ, 0u) << "pixel-channels that differ";
    EXPECT_GT(lit, size_t(a.width * a.height)); // a real image, not a black one
}
