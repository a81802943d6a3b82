// The particle tracer: the same image for any thread count, and the same picture as the path
// tracer on a scene with an area light seen directly and a point light (a two-sample test of
// independent renders of each), plus the directionalarea emitter that only it can render and a
// directional light.

#include <facet/integrator.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/spectrum.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

using namespace facet;
namespace fs = std::filesystem;

namespace {

std::shared_ptr<Scene> load_temp_scene(const std::string &name, const std::string &xml) {
    fs::path dir = fs::temp_directory_path() / fmt::format("facet-ptracer-{}", ::getpid());
    fs::create_directories(dir);
    fs::path file = dir / (name + ".xml");
    std::ofstream(file) << xml;
    auto scene = load_scene(file.string());
    fs::remove_all(dir);
    return scene;
}

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

RenderResult render_with(const Scene &scene, int threads) {
    RenderOptions opts;
    opts.threads = threads;
    opts.progress = false;
    return render(scene, *scene.sensors().at(0), opts);
}

bool identical(const Image &a, const Image &b) {
    return a.data.size() == b.data.size() &&
           std::memcmp(a.data.data(), b.data.data(), a.data.size() * sizeof(float)) == 0;
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
        Image img = render_with(*scene, 2).image;
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
    RenderResult one = render_with(*scene, 1);
    RenderResult two = render_with(*scene, 2);
    RenderResult four = render_with(*scene, 4);
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
    EXPECT_FALSE(identical(one.image, render_with(*other, 2).image));
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
    Image a = render_with(*direct, 2).image, b = render_with(*hidden, 2).image;
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
    Image img = render_with(*scene, 2).image;
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
    Image img = render_with(*scene, 2).image;
    double mean = 0.0;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) mean += img.at(x, y, 1) / 256.0;
    EXPECT_NEAR(mean, 0.5 * 2.0 * 0.5 / Pi, 0.03 * 0.5 * 2.0 * 0.5 / Pi);
}
