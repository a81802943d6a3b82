// The particle tracer: the same image for any thread count, and the same picture as the path
// tracer on a scene with an area light seen directly and a point light (a two-sample test of
// independent renders of each), plus the directionalarea emitter that only it can render and a
// directional light, and environments (constant, envmap) against the path tracer by the peer
// comparison rule.

#include "test_util.h"

#include <facet/compare.h>
#include <facet/integrator.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/spectrum.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <thread>
#include <unistd.h>

using namespace facet;
using test::identical;
using test::load_temp_scene;
namespace fs = std::filesystem;

namespace {

/// Diffuse floor, back wall, cube and sphere lit by an area light (seen edge-on from the camera,
/// its front face visible from below) and a point light.
std::string box_scene(const std::string &integrator, int size, int spp, uint64_t seed,
                      const std::string &rfilter = "<rfilter type=\"box\"/>") {
    return fmt::format(R"(<scene version="3.0.0">
    {integrator}
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <string name="fov_axis" value="x"/>
        <transform name="to_world">
            <lookat origin="0, 1.1, 4.5" target="0, 0.5, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="independent">
            <integer name="sample_count" value="{spp}"/>
            <integer name="seed" value="{seed}"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="{size}"/>
            <integer name="height" value="{size}"/>
            {rfilter}
        </film>
    </sensor>
    <shape type="rectangle">
        <transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.6, 0.6, 0.6"/></bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="3"/><translate z="-1.5"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.3, 0.5, 0.7"/></bsdf>
    </shape>
    <shape type="cube">
        <transform name="to_world">
            <scale value="0.4"/><rotate y="1" angle="25"/><translate x="-0.6" y="0.4" z="-0.2"/>
        </transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.3, 0.2"/></bsdf>
    </shape>
    <shape type="sphere">
        <point name="center" value="0.7, 0.45, 0.2"/>
        <float name="radius" value="0.45"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.7, 0.7, 0.3"/></bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world">
            <scale value="0.5"/><rotate x="1" angle="70"/><translate x="-0.3" y="2.0" z="0"/>
        </transform>
        <emitter type="area"><rgb name="radiance" value="10, 9, 8"/></emitter>
    </shape>
    <emitter type="point">
        <point name="position" value="1.3, 1.4, 1.2"/>
        <rgb name="intensity" value="1.5, 2.0, 3.0"/>
    </emitter>
</scene>)",
                       fmt::arg("integrator", integrator), fmt::arg("size", size),
                       fmt::arg("spp", spp), fmt::arg("seed", seed), fmt::arg("rfilter", rfilter));
}

const char *PTRACER =
    R"(<integrator type="ptracer"><integer name="max_depth" value="4"/></integrator>)";
const char *PATH = R"(<integrator type="path"><integer name="max_depth" value="4"/></integrator>)";

RenderResult render_with_spp(const Scene &scene, int threads, int spp) {
    RenderOptions opts;
    opts.threads = threads;
    opts.spp = spp;
    opts.progress = false;
    return render(scene, *scene.sensors().at(0), opts);
}

/// Per-pixel mean and variance of the mean of the luminance Y over K independent renders.
struct Stats {
    std::vector<double> mean, var_of_mean;
    double total = 0.0;
};

Stats independent_renders(const std::string &integrator, int size, int spp, int k) {
    Stats s;
    const size_t n = size_t(size) * size_t(size);
    std::vector<double> sum(n, 0.0), sum2(n, 0.0);
    for (int i = 0; i < k; ++i) {
        auto scene = load_temp_scene("agree", box_scene(integrator, size, spp, 1000003u * i));
        Image img = test::render_quiet(*scene, 2).image;
        for (size_t p = 0; p < n; ++p) {
            const float *c = img.data.data() + p * size_t(img.channels);
            const double y = srgb_to_xyz(Color3f(c[0], c[1], c[2])).g;
            sum[p] += y;
            sum2[p] += y * y;
        }
    }
    s.mean.resize(n);
    s.var_of_mean.resize(n);
    for (size_t p = 0; p < n; ++p) {
        s.mean[p] = sum[p] / k;
        const double var = std::max(0.0, (sum2[p] - k * s.mean[p] * s.mean[p]) / (k - 1));
        s.var_of_mean[p] = var / k;
        s.total += s.mean[p];
    }
    return s;
}

} // namespace

TEST(ParticleTracer, BitIdenticalForAnyThreadCount) {
    auto scene =
        load_temp_scene("threads", box_scene(PTRACER, 24, 8, 5, "<rfilter type=\"gaussian\"/>"));
    RenderResult one = test::render_quiet(*scene, 1);
    RenderResult two = test::render_quiet(*scene, 2);
    RenderResult four = test::render_quiet(*scene, 4);
    EXPECT_EQ(one.samples, 24u * 24u * 8u); // light paths: pixels x spp
    EXPECT_FALSE(one.cancelled);
    EXPECT_EQ(one.blocks_done, one.blocks_total);
    EXPECT_TRUE(identical(one.image, two.image));
    EXPECT_TRUE(identical(one.image, four.image));
    double sum = 0.0;
    for (float v : one.image.data) {
        ASSERT_TRUE(std::isfinite(v));
        sum += v;
    }
    EXPECT_GT(sum, 0.0);
    // Another seed, other noise.
    auto other =
        load_temp_scene("seed", box_scene(PTRACER, 24, 8, 6, "<rfilter type=\"gaussian\"/>"));
    EXPECT_FALSE(identical(one.image, test::render_quiet(*other, 2).image));
}

TEST(ParticleTracer, StoppedRenderKeepsTheLightPathsPerPixelItReached) {
    // Far too many light paths to finish: a stop keeps the progressive passes done, says how
    // many paths per pixel they hold, and the image is the render of exactly that many.
    auto scene =
        load_temp_scene("stop", box_scene(PTRACER, 24, 1 << 22, 5, "<rfilter type=\"gaussian\"/>"));
    std::atomic<bool> cancel{false};
    RenderOptions opts;
    opts.threads = 2;
    opts.progress = false;
    opts.cancel = &cancel;
    std::thread stopper([&cancel] {
        std::this_thread::sleep_for(std::chrono::milliseconds(500));
        cancel = true;
    });
    RenderResult stopped = render(*scene, *scene->sensors().at(0), opts);
    stopper.join();
    EXPECT_TRUE(stopped.cancelled);
    EXPECT_FALSE(stopped.timed_out);
    EXPECT_EQ(stopped.spp_target, 1u << 22);
    ASSERT_GE(stopped.spp, 1u);
    EXPECT_LT(stopped.spp, 1u << 22);
    EXPECT_EQ(stopped.samples, 24u * 24u * stopped.spp);
    EXPECT_LT(stopped.blocks_done, stopped.blocks_total);
    auto again = render_with_spp(*scene, 1, int(stopped.spp));
    EXPECT_FALSE(again.cancelled);
    EXPECT_TRUE(identical(stopped.image, again.image))
        << "the stopped render is not the render of " << stopped.spp << " light paths per pixel";
}

TEST(ParticleTracer, AgreesWithThePathTracer) {
    // Eight independent renders of each; per pixel z = |a - b| / sqrt(var_a + var_b) of the means
    // follows (nearly) a t distribution with 14 degrees of freedom: |z| > 4 has a probability of
    // about 0.1 %. A wrong factor anywhere (importance, power, cosines) shifts most pixels.
    const int size = 24, k = 8;
    Stats pt = independent_renders(PTRACER, size, 64, k);
    Stats path = independent_renders(PATH, size, 32, k);
    int outliers = 0, pixels = size * size;
    for (int p = 0; p < pixels; ++p) {
        const double d = std::abs(pt.mean[p] - path.mean[p]);
        const double sd = std::sqrt(pt.var_of_mean[p] + path.var_of_mean[p]);
        if (d > 4.0 * sd + 1e-6) ++outliers;
    }
    EXPECT_LE(outliers, pixels / 100) << "pixels that disagree";
    EXPECT_NEAR(pt.total / path.total, 1.0, 0.02) << "mean brightness ratio";
}

TEST(ParticleTracer, HideEmittersAndMaxDepth) {
    // max_depth 1: only the emitters seen directly (the area light's front face); with
    // hide_emitters nothing at all.
    auto direct = load_temp_scene(
        "depth1", box_scene(R"(<integrator type="ptracer"><integer name="max_depth" value="1"/>
                               </integrator>)",
                            16, 16, 0));
    auto hidden = load_temp_scene(
        "hidden", box_scene(R"(<integrator type="ptracer"><integer name="max_depth" value="1"/>
                               <boolean name="hide_emitters" value="true"/></integrator>)",
                            16, 16, 0));
    Image a = test::render_quiet(*direct, 2).image, b = test::render_quiet(*hidden, 2).image;
    int lit = 0;
    for (size_t i = 0; i < a.data.size(); ++i) {
        if (a.data[i] > 0.f) ++lit;
        EXPECT_EQ(b.data[i], 0.f);
    }
    EXPECT_GT(lit, 0);
    EXPECT_LT(lit, int(a.data.size()) / 4); // the light covers a small part of the image
}

TEST(ParticleTracer, DirectionalAreaLightsTheFloorBelowIt) {
    // A 1.6 x 1.0 rectangle 2 units above a diffuse floor, emitting straight down: the floor
    // under it receives irradiance E = radiance, so it has radiance rho E / pi there, and none
    // elsewhere (max_depth 2: no interreflection). The camera looks down from between the two,
    // so the emitter does not hide the floor from it.
    const char *xml = R"(<scene version="3.0.0">
    <integrator type="ptracer"><integer name="max_depth" value="2"/></integrator>
    <sensor type="orthographic">
        <transform name="to_world">
            <scale x="2" y="2" z="1"/>
            <lookat origin="0, 1, 0" target="0, 0, 0" up="0, 0, -1"/>
        </transform>
        <sampler type="independent"><integer name="sample_count" value="256"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="16"/><integer name="height" value="16"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <shape type="rectangle">
        <transform name="to_world">
            <scale x="0.8" y="0.5" z="1"/><rotate x="1" angle="90"/><translate y="2"/>
        </transform>
        <emitter type="directionalarea"><rgb name="radiance" value="3, 2.5, 2"/></emitter>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf>
    </shape>
</scene>)";
    auto scene = load_temp_scene("dirarea", xml);
    Image img = test::render_quiet(*scene, 2).image;
    // The camera sees x in [-2, 2] and z in [-2, 2] (orthographic, 0.25 per pixel); the beam
    // covers |x| < 0.8, |z| < 0.5 (pixel columns 4.8..11.2, rows 6..10).
    double inside = 0.0;
    int n_inside = 0;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            const float v = img.at(x, y, 0);
            if (x >= 6 && x <= 9 && y >= 7 && y <= 8) {
                inside += v;
                ++n_inside;
            } else if (x <= 3 || x >= 12 || y <= 4 || y >= 11) {
                EXPECT_EQ(v, 0.f) << x << "," << y;
            }
        }
    // rho E / pi = 0.5 * 3 / pi for the red channel; the estimate has 16 x 16 x 256 paths.
    EXPECT_NEAR(inside / n_inside, 0.5 * 3.0 / Pi, 0.03 * 0.5 * 3.0 / Pi);
}

TEST(ParticleTracer, DirectionalLightOnADiffuseFloor) {
    // Sunlight of irradiance 2 at 60 degrees from the normal on a floor of reflectance 0.5:
    // radiance rho E cos / pi everywhere the camera looks.
    const char *xml = R"(<scene version="3.0.0">
    <integrator type="ptracer"><integer name="max_depth" value="2"/></integrator>
    <sensor type="orthographic">
        <transform name="to_world">
            <scale x="2" y="2" z="1"/>
            <lookat origin="0, 1, 0" target="0, 0, 0" up="0, 0, -1"/>
        </transform>
        <sampler type="independent"><integer name="sample_count" value="256"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="16"/><integer name="height" value="16"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <emitter type="directional">
        <vector name="direction" value="0.8660254, -0.5, 0"/>
        <rgb name="irradiance" value="2"/>
    </emitter>
    <shape type="rectangle">
        <transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf>
    </shape>
</scene>)";
    auto scene = load_temp_scene("sun", xml);
    Image img = test::render_quiet(*scene, 2).image;
    double mean = 0.0;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) mean += img.at(x, y, 1) / 256.0;
    EXPECT_NEAR(mean, 0.5 * 2.0 * 0.5 / Pi, 0.03 * 0.5 * 2.0 * 0.5 / Pi);
}

namespace {

/// A diffuse sphere on a diffuse floor under an environment, seen against it.
std::string environment_scene(const std::string &integrator, const std::string &emitter,
                              bool hide_emitters = false) {
    return fmt::format(R"(<scene version="3.0.0">
    <integrator type="{integrator}">
        <integer name="max_depth" value="3"/>
        <boolean name="hide_emitters" value="{hide}"/>
    </integrator>
    <sensor type="perspective">
        <float name="fov" value="90"/>
        <transform name="to_world">
            <lookat origin="0, 1.2, 2.5" target="0, 0.4, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="independent"><integer name="sample_count" value="16"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="24"/><integer name="height" value="24"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <shape type="rectangle">
        <transform name="to_world"><scale value="1.5"/><rotate x="1" angle="-90"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.6, 0.6, 0.6"/></bsdf>
    </shape>
    <shape type="sphere">
        <point name="center" value="0, 0.5, 0"/><float name="radius" value="0.5"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.7, 0.5, 0.3"/></bsdf>
    </shape>
    {emitter}
</scene>)",
                       fmt::arg("integrator", integrator), fmt::arg("emitter", emitter),
                       fmt::arg("hide", hide_emitters ? "true" : "false"));
}

/// K independent renders (seeds 0 .. K-1) at `spp`: their mean (RGB) and the per-sample variance
/// of each pixel in XYZ (the variance of one render times spp), as facet compare takes them.
struct MeanAndVariance {
    Image mean, var_xyz;
    int spp = 0;
};

MeanAndVariance independent_means(const Scene &scene, int spp, int k) {
    const Sensor &sensor = *scene.sensors().at(0);
    MeanAndVariance out;
    std::vector<Image> xyz;
    for (int i = 0; i < k; ++i) {
        RenderOptions opts;
        opts.threads = 2;
        opts.progress = false;
        opts.spp = spp;
        opts.seed = uint64_t(i) * 7919u;
        Image img = render(scene, sensor, opts).image;
        if (i == 0) {
            out.mean = Image(img.width, img.height, 3);
            out.var_xyz = Image(img.width, img.height, 3);
        }
        Image x(img.width, img.height, 3);
        for (int y = 0; y < img.height; ++y)
            for (int px = 0; px < img.width; ++px) {
                const Color3f c(img.at(px, y, 0), img.at(px, y, 1), img.at(px, y, 2));
                const Color3f v = srgb_to_xyz(c);
                for (int ch = 0; ch < 3; ++ch) {
                    out.mean.at(px, y, ch) += c[ch] / float(k);
                    x.at(px, y, ch) = v[ch];
                }
            }
        xyz.push_back(std::move(x));
    }
    for (size_t p = 0; p < out.var_xyz.data.size(); ++p) {
        double sum = 0.0, sum2 = 0.0;
        for (const Image &x : xyz) {
            sum += x.data[p];
            sum2 += double(x.data[p]) * x.data[p];
        }
        const double m = sum / k, var = std::max(0.0, (sum2 - k * m * m) / (k - 1));
        out.var_xyz.data[p] = float(var * spp);
    }
    out.spp = spp * k;
    return out;
}

/// The particle tracer's image of the environment scene agrees with the path tracer's by the
/// peer rule (facet compare): z = |ptracer - path| sqrt(N / var) per pixel and XYZ channel with
/// N the light paths per pixel, where var holds both renders' noise (the path tracer's scaled
/// to N samples), and 99.75 % of the channels must pass the Sidak-corrected level.
void expect_agreement(const std::string &emitter, const std::string &mode = "") {
    LoadOptions opts;
    opts.mode = mode;
    auto pt = load_temp_scene("env-pt", environment_scene("ptracer", emitter), opts);
    auto path = load_temp_scene("env-path", environment_scene("path", emitter), opts);
    // Directly visible environment pixels receive a few of the emitter connections of each
    // render: enough light paths per render keep those counts away from the small, skewed
    // Poisson counts that would make the variance estimate of 16 renders too low.
    MeanAndVariance a = independent_means(*pt, 128, 16);
    MeanAndVariance b = independent_means(*path, 512, 4);
    Image var = a.var_xyz;
    for (size_t p = 0; p < var.data.size(); ++p)
        var.data[p] += b.var_xyz.data[p] * float(a.spp) / float(b.spp);
    PeerComparison cmp = compare_with_reference(a.mean, b.mean, var, a.spp);
    std::printf("ptracer vs path: %.2f %% of the pixel-channels agree, brightness %+.2f %%\n",
                100.0 * cmp.fraction, 100.0 * cmp.brightness_difference());
    EXPECT_TRUE(cmp.passed_rule) << "agreement " << 100.0 * cmp.fraction << " %";
    EXPECT_EQ(cmp.non_finite, 0u);
    EXPECT_NEAR(cmp.brightness_difference(), 0.0, 0.02);
    // Sky pixels above the floor see the environment directly: the ptracer counts it there.
    EXPECT_GT(a.mean.at(12, 0, 1), 0.f);
}

} // namespace

TEST(ParticleTracer, ConstantEnvironmentAgreesWithThePathTracer) {
    expect_agreement(R"(<emitter type="constant"><rgb name="radiance" value="0.8, 1, 1.3"/>
                        </emitter>)");
}

TEST(ParticleTracer, EnvironmentMapAgreesWithThePathTracer) {
    expect_agreement(fmt::format(R"(<emitter type="envmap">
        <string name="filename" value="{}/tests/chi2/envmap_sky.exr"/>
        <transform name="to_world"><rotate y="1" angle="40"/></transform>
    </emitter>)",
                                 FACET_SOURCE_DIR));
}

TEST(ParticleTracer, EnvironmentMapAgreesWithThePathTracerInSpectral) {
    // The sky seen directly is the map's radiance at the light path's wavelengths (the record
    // of the connection's escaped ray carries them; it once rendered black).
    expect_agreement(fmt::format(R"(<emitter type="envmap">
        <string name="filename" value="{}/tests/chi2/envmap_sky.exr"/>
    </emitter>)",
                                 FACET_SOURCE_DIR),
                     "scalar_spectral");
}

TEST(ParticleTracer, HiddenEnvironmentLeavesTheSkyBlack) {
    // hide_emitters: the sky pixels (the top rows look over the floor) get nothing, the lit
    // floor and sphere still do.
    auto scene = load_temp_scene(
        "env-hidden", environment_scene("ptracer", R"(<emitter type="constant"/>)", true));
    Image img = test::render_quiet(*scene, 2).image;
    for (int x = 0; x < img.width; ++x)
        for (int c = 0; c < 3; ++c) EXPECT_EQ(img.at(x, 0, c), 0.f) << x;
    EXPECT_GT(img.at(12, 12, 1), 0.f); // the sphere
    EXPECT_GT(img.at(3, 16, 1), 0.f);  // the floor
}
