// The moment integrator: its first-moment channels are the nested integrator's samples in XYZ,
// and E[x²] - E[x]² is the per-sample variance, checked against the scatter of independent
// renders.

#include "test_util.h"

#include <facet/integrator.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/spectrum.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <unistd.h>

using namespace facet;
using test::load_temp_scene;
namespace fs = std::filesystem;

namespace {

std::string scene_xml(const std::string &integrator, int spp, uint64_t seed) {
    return fmt::format(R"(<scene version="3.0.0">
    {integrator}
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 1.5, 5" target="0, 0.3, 0" up="0, 1, 0"/></transform>
        <sampler type="independent">
            <integer name="sample_count" value="{spp}"/>
            <integer name="seed" value="{seed}"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="16"/><integer name="height" value="16"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="0.3, 0.4, 0.5"/></emitter>
    <shape type="sphere">
        <point name="center" x="0" y="0.5" z="0"/><float name="radius" value="0.5"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.3, 0.2"/></bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="0.6"/><rotate x="1" angle="90"/><translate y="2"/></transform>
        <emitter type="area"><rgb name="radiance" value="8, 8, 8"/></emitter>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><rotate x="1" angle="-90"/><scale value="3"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf>
    </shape>
</scene>)",
                       fmt::arg("integrator", integrator), fmt::arg("spp", spp),
                       fmt::arg("seed", seed));
}

const char *PATH = R"(<integrator type="path"><integer name="max_depth" value="4"/></integrator>)";
const char *MOMENT = R"(<integrator type="moment">
    <integrator type="path"><integer name="max_depth" value="4"/></integrator>
</integrator>)";

Image render_image(const Scene &scene) { return test::render_quiet(scene, 2).image; }

} // namespace

TEST(Moment, ChannelsAndFirstMoment) {
    auto scene = load_temp_scene("names", scene_xml(MOMENT, 8, 0));
    Image img = render_image(*scene);
    ASSERT_EQ(img.channels, 9);
    EXPECT_EQ(img.channel_names,
              (std::vector<std::string>{"R", "G", "B", "_arg_0.X", "_arg_0.Y", "_arg_0.Z",
                                        "m2__arg_0.X", "m2__arg_0.Y", "m2__arg_0.Z"}));
    // The image is the nested path tracer's, sample for sample; the first moments are its XYZ.
    auto plain = load_temp_scene("plain", scene_xml(PATH, 8, 0));
    Image ref = render_image(*plain);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            Color3f rgb(img.at(x, y, 0), img.at(x, y, 1), img.at(x, y, 2));
            EXPECT_EQ(rgb.r, ref.at(x, y, 0));
            EXPECT_EQ(rgb.b, ref.at(x, y, 2));
            Color3f xyz = srgb_to_xyz(rgb);
            EXPECT_NEAR(img.at(x, y, 3), xyz.r, 1e-4f * (1.f + xyz.r));
            EXPECT_NEAR(img.at(x, y, 4), xyz.g, 1e-4f * (1.f + xyz.g));
            EXPECT_NEAR(img.at(x, y, 5), xyz.b, 1e-4f * (1.f + xyz.b));
            // E[x²] >= E[x]² (Jensen), up to rounding.
            for (int c = 0; c < 3; ++c)
                EXPECT_GE(img.at(x, y, 6 + c) * (1.f + 1e-5f) + 1e-7f,
                          img.at(x, y, 3 + c) * img.at(x, y, 3 + c));
        }
}

TEST(Moment, VarianceMatchesIndependentRenders) {
    // Per-sample variance from the moments of one render, over spp, against the variance of the
    // pixel value over k independent renders of spp samples, summed over the image. The
    // estimates must be precise enough for the tolerance: over eight seed sets the ratio had a
    // standard deviation of 0.022 with these sizes (0.12 with k = 16 and 32 moment samples, too
    // noisy for any useful bound), so 0.1 is more than four standard deviations.
    const int spp = 32, k = 256, n = 16 * 16, moment_spp = 512;
    auto scene = load_temp_scene("moments", scene_xml(MOMENT, moment_spp, 12345));
    Image m = render_image(*scene);
    std::vector<double> sum(n, 0.0), sum2(n, 0.0);
    for (int i = 0; i < k; ++i) {
        auto s = load_temp_scene("indep", scene_xml(PATH, spp, 1000003u * (i + 1)));
        Image img = render_image(*s);
        for (int p = 0; p < n; ++p) {
            const float *c = img.data.data() + size_t(p) * size_t(img.channels);
            const double y = srgb_to_xyz(Color3f(c[0], c[1], c[2])).g;
            sum[p] += y;
            sum2[p] += y * y;
        }
    }
    double from_moments = 0.0, from_renders = 0.0;
    for (int p = 0; p < n; ++p) {
        const float *c = m.data.data() + size_t(p) * size_t(m.channels);
        from_moments += std::max(0.0, double(c[7]) - double(c[4]) * double(c[4])) / spp;
        const double mean = sum[p] / k;
        from_renders += std::max(0.0, (sum2[p] - k * mean * mean) / (k - 1));
    }
    ASSERT_GT(from_renders, 0.0);
    EXPECT_NEAR(from_moments / from_renders, 1.0, 0.1);
}

TEST(Moment, NeedsSamplingIntegrators) {
    EXPECT_THROW(load_temp_scene("none", scene_xml(R"(<integrator type="moment"/>)", 4, 0)),
                 std::exception);
    EXPECT_THROW(load_temp_scene("ptracer", scene_xml(R"(<integrator type="moment">
        <integrator type="ptracer"/></integrator>)",
                                                      4, 0)),
                 std::exception);
}
