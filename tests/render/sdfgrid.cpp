// sdfgrid in whole renders: a sphere's SDF sampled on a grid (written here at run time) against
// the analytic sphere, through the aov integrator (depth and shading normals per pixel, both
// normal modes) and through path-traced image means; and the example scene in scenes/sdfgrid.

#include "test_util.h"

#include <facet/image.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <string>
#include <unistd.h>

using namespace facet;
using test::channel;
using test::render_xml;

namespace {

/// The SDF of the sphere of radius 0.35 at the centre of the unit cube, 40³ samples.
std::string sphere_vol() {
    static std::string path = [] {
        std::string dir = std::string(::testing::TempDir()) + "facet_sdfgrid_render_" +
                          std::to_string(::getpid());
        ::mkdir(dir.c_str(), 0755);
        std::string p = dir + "/sphere.vol";
        const int n = 40;
        std::string bytes = "VOL";
        bytes.push_back(char(3));
        auto i32 = [&](int32_t v) { bytes.append(reinterpret_cast<const char *>(&v), 4); };
        auto f32 = [&](float v) { bytes.append(reinterpret_cast<const char *>(&v), 4); };
        i32(1);
        i32(n);
        i32(n);
        i32(n);
        i32(1);
        for (float b : {0.f, 0.f, 0.f, 1.f, 1.f, 1.f}) f32(b);
        for (int z = 0; z < n; ++z)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    double px = double(x) / (n - 1) - 0.5, py = double(y) / (n - 1) - 0.5,
                           pz = double(z) / (n - 1) - 0.5;
                    f32(float(std::sqrt(px * px + py * py + pz * pz) - 0.35));
                }
        std::ofstream(p, std::ios::binary) << bytes;
        return p;
    }();
    return path;
}

const char *SENSOR = R"(
    <sensor type="perspective">
        <float name="fov" value="35"/>
        <transform name="to_world"><lookat origin="1, 2.5, 6" target="0, 0.7, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="16"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="48"/><integer name="height" value="40"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="0.5"/></emitter>
    <shape type="rectangle">
        <transform name="to_world"><scale value="10"/><rotate x="1" angle="-90"/></transform>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="0.7"/><rotate x="1" angle="90"/><translate x="1" y="3" z="1"/></transform>
        <emitter type="area"><rgb name="radiance" value="8"/></emitter>
    </shape>
)";

// The grid's unit cube scaled by 2 and moved so that the sphere (radius 0.7) sits at (0, 0.7, 0).
std::string grid_scene(const std::string &integrator, const std::string &normals) {
    return std::string("<scene version=\"3.0.0\">") + integrator + SENSOR +
           "<shape type=\"sdfgrid\"><string name=\"filename\" value=\"" + sphere_vol() +
           "\"/><string name=\"normals\" value=\"" + normals +
           "\"/><transform name=\"to_world\"><scale value=\"2\"/><translate x=\"-1\" y=\"-0.3\" "
           "z=\"-1\"/></transform><bsdf type=\"roughplastic\"/></shape></scene>";
}

std::string sphere_scene(const std::string &integrator) {
    return std::string("<scene version=\"3.0.0\">") + integrator + SENSOR +
           R"(<shape type="sphere"><point name="center" x="0" y="0.7" z="0"/>
              <float name="radius" value="0.7"/><bsdf type="roughplastic"/></shape></scene>)";
}

} // namespace

TEST(SDFGrid, SphereGridMatchesSphereGeometry) {
    const std::string aov =
        R"(<integrator type="aov"><string name="aovs" value="dd:depth, nn:sh_normal"/></integrator>)";
    Image b = render_xml(sphere_scene(aov));
    for (const char *normals : {"analytic", "smooth"}) {
        SCOPED_TRACE(normals);
        Image a = render_xml(grid_scene(aov, normals));
        ASSERT_EQ(a.channel_names, b.channel_names);
        int depth = channel(a, "dd"), nx = channel(a, "nn.X");
        ASSERT_GE(depth, 0);
        ASSERT_GE(nx, 0);
        int on_sphere = 0, agree = 0;
        for (int y = 0; y < a.height; ++y)
            for (int x = 0; x < a.width; ++x) {
                float da = a.at(x, y, depth), db = b.at(x, y, depth);
                // Pixels whose sphere depth is nearer than the floor behind it.
                if (!(db > 0.f && db < 6.8f)) continue;
                ++on_sphere;
                bool ok = std::abs(da - db) <= 2e-3f * db;
                for (int c = 0; c < 3; ++c)
                    ok &= std::abs(a.at(x, y, nx + c) - b.at(x, y, nx + c)) < 0.02f;
                agree += ok;
            }
        // Pixels on the silhouette average sphere and floor differently; the rest agree.
        EXPECT_GT(on_sphere, 200);
        EXPECT_GE(agree, int(0.95 * on_sphere)) << agree << " of " << on_sphere;
    }
}

TEST(SDFGrid, SphereGridShadesLikeSphere) {
    const std::string path =
        R"(<integrator type="path"><integer name="max_depth" value="4"/></integrator>)";
    Image a = render_xml(grid_scene(path, "smooth")), b = render_xml(sphere_scene(path));
    for (int c = 0; c < 3; ++c) {
        double ma = 0, mb = 0;
        for (int y = 0; y < a.height; ++y)
            for (int x = 0; x < a.width; ++x) {
                ma += a.at(x, y, c);
                mb += b.at(x, y, c);
            }
        EXPECT_NEAR(ma, mb, 0.02 * mb) << "channel " << c;
    }
}

TEST(SDFGrid, ExampleSceneRenders) {
    LoadOptions opts;
    opts.params["spp"] = "4";
    opts.params["res"] = "48";
    for (const char *normals : {"smooth", "analytic"}) {
        opts.params["normals"] = normals;
        auto scene = load_scene(std::string(FACET_SOURCE_DIR) + "/scenes/sdfgrid/scene.xml", opts);
        RenderOptions ro;
        ro.progress = false;
        Image img = render(*scene, *scene->sensors().at(0), ro).image;
        // The torus is in front of the camera: the centre column must show it, not the floor
        // alone; everything finite.
        double sum = 0;
        for (int y = 0; y < img.height; ++y)
            for (int x = 0; x < img.width; ++x)
                for (int c = 0; c < 3; ++c) {
                    ASSERT_TRUE(std::isfinite(img.at(x, y, c)));
                    sum += img.at(x, y, c);
                }
        EXPECT_GT(sum, 0.0);
        // The torus's red-orange: red well above blue somewhere in the middle of the image.
        int reddish = 0;
        for (int y = img.height / 4; y < 3 * img.height / 4; ++y)
            for (int x = 0; x < img.width / 2; ++x)
                reddish += img.at(x, y, 0) > 2.f * img.at(x, y, 2) + 0.02f;
        EXPECT_GT(reddish, 20) << normals;
    }
}
