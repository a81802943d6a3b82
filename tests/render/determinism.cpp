// The render loop: bit-identical images for any thread count, seeds that matter, cancellation,
// dropped NaN samples and AOV channels.
#include "test_util.h"

#include <facet/integrator.h>
#include <facet/plugin.h>
#include <facet/render.h>
#include <facet/sampler.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <csignal>
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

std::string scene_xml(const std::string &integrator, int size, int spp,
                      const std::string &rfilter) {
    return fmt::format(R"(<scene version="3.0.0">
    {integrator}
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world">
            <lookat origin="0, 1.5, 5" target="0, 0.3, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="independent">
            <integer name="sample_count" value="{spp}"/>
            <integer name="seed" value="3"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="{size}"/>
            <integer name="height" value="{size}"/>
            {rfilter}
        </film>
    </sensor>
    <emitter type="constant">
        <rgb name="radiance" value="0.3, 0.4, 0.5"/>
    </emitter>
    <emitter type="point">
        <point name="position" x="2" y="3" z="2"/>
        <rgb name="intensity" value="20, 18, 15"/>
    </emitter>
    <shape type="sphere">
        <point name="center" x="0" y="0.5" z="0"/>
        <float name="radius" value="0.5"/>
        <bsdf type="diffuse">
            <rgb name="reflectance" value="0.8, 0.3, 0.2"/>
        </bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world">
            <rotate x="1" angle="-90"/>
            <scale value="3"/>
        </transform>
        <bsdf type="diffuse">
            <rgb name="reflectance" value="0.5"/>
        </bsdf>
    </shape>
</scene>)",
                       fmt::arg("integrator", integrator), fmt::arg("size", size),
                       fmt::arg("spp", spp), fmt::arg("rfilter", rfilter));
}

const char *PATH = R"(<integrator type="path"><integer name="max_depth" value="6"/></integrator>)";

/// The render loop in blocks of 8 pixels unless told otherwise.
RenderResult render_with(const Scene &scene, int threads, uint64_t seed = 0, int block_size = 8) {
    return test::render_quiet(scene, threads, seed, block_size);
}

/// Test integrator: radiance 1 for most samples and NaN or infinity for the others (decided by
/// the sampler, so it varies within a pixel); AOVs "test.half" = 0.5 and "test.dz" = -ray.d.z.
class InvalidSamplesIntegrator final : public SamplingIntegrator {
public:
    explicit InvalidSamplesIntegrator(const Properties &) {}
    Color3f sample(const Scene &, Sampler &sampler, const Ray &ray, float *aovs) const override {
        aovs[0] = 0.5f;
        aovs[1] = -ray.d.z; // the camera looks down -z
        float u = sampler.next_1d();
        if (u < 0.2f) return Color3f(std::nanf(""), 1.f, 1.f);
        if (u < 0.3f) return Color3f(1.f, Infinity, 1.f);
        return Color3f(1.f, 2.f, 4.f); // powers of two: the filtered mean is exact
    }
    std::vector<std::string> aov_names() const override { return {"test.half", "test.dz"}; }
};

const PluginDescriptor *invalid_samples_descriptor() {
    static const PluginDescriptor desc{
        FACET_ABI_VERSION,
        ObjectType::Integrator,
        "test_invalid_samples",
        "test integrator",
        "",
        [](const Properties &p) -> Object * { return new InvalidSamplesIntegrator(p); }};
    return &desc;
}

/// Test integrator that raises a cancel flag at the first sample whose index is at least
/// g_cancel_at_sample, and returns radiance 1.
std::atomic<bool> *g_cancel_flag = nullptr;
uint32_t g_cancel_at_sample = 0;
class CancellingIntegrator final : public SamplingIntegrator {
public:
    explicit CancellingIntegrator(const Properties &) {}
    Color3f sample(const Scene &, Sampler &sampler, const Ray &, float *) const override {
        if (g_cancel_flag && sampler.sample_index() >= g_cancel_at_sample)
            g_cancel_flag->store(true);
        return Color3f(1.f);
    }
};

const PluginDescriptor *cancelling_descriptor() {
    static const PluginDescriptor desc{
        FACET_ABI_VERSION,
        ObjectType::Integrator,
        "test_cancelling",
        "test integrator",
        "",
        [](const Properties &p) -> Object * { return new CancellingIntegrator(p); }};
    return &desc;
}

/// Test integrator that takes 2 ms per sample and returns radiance 1 (for the timeout).
class SlowIntegrator final : public SamplingIntegrator {
public:
    explicit SlowIntegrator(const Properties &p) : SamplingIntegrator(p) {}
    Color3f sample(const Scene &, Sampler &, const Ray &, float *) const override {
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
        return Color3f(1.f);
    }
};

const PluginDescriptor *slow_descriptor() {
    static const PluginDescriptor desc{
        FACET_ABI_VERSION,
        ObjectType::Integrator,
        "test_slow",
        "test integrator",
        "| timeout | float | -1 | |\n| samples_per_pass | integer | | |\n| block_size | integer | "
        "0 | |\n",
        [](const Properties &p) -> Object * { return new SlowIntegrator(p); }};
    return &desc;
}

} // namespace

TEST(RenderLoop, BitIdenticalForAnyThreadCount) {
    auto scene = load_temp_scene("threads", scene_xml(PATH, 32, 16, ""));
    RenderResult one = render_with(*scene, 1);
    RenderResult two = render_with(*scene, 2);
    RenderResult three = render_with(*scene, 3);
    RenderResult four = render_with(*scene, 4);
    ASSERT_EQ(one.image.width, 32);
    ASSERT_EQ(one.image.height, 32);
    ASSERT_EQ(one.image.channels, 3);
    EXPECT_EQ(one.blocks_total, 16u * 5u); // 16 blocks x passes of 1, 1, 2, 4 and 8 samples
    EXPECT_EQ(one.blocks_done, 16u * 5u);
    EXPECT_EQ(one.spp, 16u);
    EXPECT_FALSE(one.cancelled);
    EXPECT_EQ(one.samples, 32u * 32u * 16u);
    EXPECT_TRUE(identical(one.image, two.image));
    EXPECT_TRUE(identical(one.image, three.image));
    EXPECT_TRUE(identical(one.image, four.image));

    // Not a trivially constant image: lit and unlit parts, all finite and non-negative.
    float lo = Infinity, hi = 0.f;
    for (float v : one.image.data) {
        ASSERT_TRUE(std::isfinite(v));
        ASSERT_GE(v, 0.f);
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    }
    EXPECT_GT(hi, 2.f * lo + 0.05f);
}

TEST(RenderLoop, SeedSelectsTheNoise) {
    auto scene = load_temp_scene("seed", scene_xml(PATH, 16, 4, "<rfilter type=\"box\"/>"));
    RenderResult a = render_with(*scene, 2, 0);
    RenderResult b = render_with(*scene, 2, 0);
    RenderResult c = render_with(*scene, 2, 1);
    EXPECT_TRUE(identical(a.image, b.image));
    EXPECT_FALSE(identical(a.image, c.image));
    // Different noise, same picture: the means agree within a few percent.
    double ma = 0, mc = 0;
    for (size_t i = 0; i < a.image.data.size(); ++i) {
        ma += a.image.data[i];
        mc += c.image.data[i];
    }
    EXPECT_NEAR(ma / mc, 1.0, 0.1);
}

TEST(RenderLoop, EveryBitOfTheSamplersSeedSelectsTheNoise) {
    // The sampler's seed enters both the pixel seeds and each sample's stream: its high 32
    // bits must not cancel between the two.
    const std::string xml = scene_xml(PATH, 16, 4, "<rfilter type=\"box\"/>");
    const std::string seed3 = R"(<integer name="seed" value="3"/>)";
    ASSERT_NE(xml.find(seed3), std::string::npos);
    std::string high = xml;
    high.replace(high.find(seed3), seed3.size(), R"(<integer name="seed" value="4294967299"/>)");
    auto a = load_temp_scene("seed-low", xml), b = load_temp_scene("seed-high", high);
    EXPECT_FALSE(identical(render_with(*a, 2).image, render_with(*b, 2).image));
}

TEST(RenderLoop, SppOverride) {
    auto scene = load_temp_scene("spp", scene_xml(PATH, 8, 4, ""));
    RenderOptions opts;
    opts.progress = false;
    opts.spp = 3;
    RenderResult r = render(*scene, *scene->sensors().at(0), opts);
    EXPECT_EQ(r.samples, 8u * 8u * 3u);
    opts.spp = -1;
    EXPECT_THROW(render(*scene, *scene->sensors().at(0), opts), Error);
}

TEST(RenderLoop, CancelBeforeStartRendersNothing) {
    auto scene = load_temp_scene("cancel", scene_xml(PATH, 16, 2, ""));
    std::atomic<bool> cancel{true};
    RenderOptions opts;
    opts.progress = false;
    opts.cancel = &cancel;
    RenderResult r = render(*scene, *scene->sensors().at(0), opts);
    EXPECT_TRUE(r.cancelled);
    EXPECT_EQ(r.blocks_done, 0u);
    EXPECT_EQ(r.samples, 0u);
    ASSERT_EQ(r.image.width, 16);
    for (float v : r.image.data) EXPECT_EQ(v, 0.f);
}

TEST(RenderLoop, InvalidSamplesAreDroppedAndAovsDeveloped) {
    PluginRegistry::instance().register_static(invalid_samples_descriptor());
    auto scene = load_temp_scene("nan", scene_xml("<integrator type=\"test_invalid_samples\"/>", 8,
                                                  16, "<rfilter type=\"tent\"/>"));
    const size_t warnings = Logger::warning_count();
    RenderResult r = render_with(*scene, 2);
    EXPECT_GT(Logger::warning_count(), warnings); // reported
    ASSERT_EQ(r.image.channels, 5);
    EXPECT_EQ(r.image.channel_names,
              (std::vector<std::string>{"R", "G", "B", "test.half", "test.dz"}));
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            // Every pixel only averages the valid samples.
            EXPECT_FLOAT_EQ(r.image.at(x, y, 0), 1.f);
            EXPECT_FLOAT_EQ(r.image.at(x, y, 1), 2.f);
            EXPECT_FLOAT_EQ(r.image.at(x, y, 2), 4.f);
            EXPECT_FLOAT_EQ(r.image.at(x, y, 3), 0.5f);
            // The camera looks down -z: -d.z is largest in the middle of the image.
            float dz = r.image.at(x, y, 4);
            EXPECT_GT(dz, 0.f);
            EXPECT_LE(dz, 1.f);
        }
    EXPECT_GT(r.image.at(4, 4, 4), r.image.at(0, 0, 4));
}

TEST(RenderLoop, CancelAbandonsThePassInFlight) {
    PluginRegistry::instance().register_static(cancelling_descriptor());
    auto scene = load_temp_scene("cancel_mid", scene_xml("<integrator type=\"test_cancelling\"/>",
                                                         8, 4, "<rfilter type=\"box\"/>"));
    std::atomic<bool> cancel{false};
    g_cancel_flag = &cancel;
    RenderOptions opts;
    opts.threads = 1;
    opts.block_size = 4;
    opts.progress = false;
    opts.cancel = &cancel;
    // Cancelled at the first sample: the first pass is abandoned, nothing reaches the film.
    g_cancel_at_sample = 0;
    RenderResult r = render(*scene, *scene->sensors().at(0), opts);
    EXPECT_TRUE(r.cancelled);
    EXPECT_EQ(r.blocks_total, 4u * 3u); // passes of 1, 1 and 2 samples
    EXPECT_EQ(r.blocks_done, 0u);
    EXPECT_EQ(r.spp, 0u);
    EXPECT_EQ(r.spp_target, 4u);
    EXPECT_EQ(r.samples, 0u);
    for (float v : r.image.data) EXPECT_EQ(v, 0.f);
    // Cancelled in the first block of the second pass: the image is the whole first pass,
    // every pixel at 1 spp (the blocks of the second pass done by then are not kept).
    cancel = false;
    g_cancel_at_sample = 1;
    r = render(*scene, *scene->sensors().at(0), opts);
    g_cancel_flag = nullptr;
    EXPECT_TRUE(r.cancelled);
    EXPECT_EQ(r.blocks_done, 4u);
    EXPECT_EQ(r.spp, 1u);
    EXPECT_EQ(r.samples, 8u * 8u);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) EXPECT_EQ(r.image.at(x, y, 0), 1.f) << x << "," << y;
}

TEST(RenderLoop, InterruptHandlerSetsTheFlagOnce) {
    std::atomic<bool> flag{false};
    struct sigaction before;
    sigaction(SIGINT, nullptr, &before);
    install_interrupt_handler(&flag);
    ::raise(SIGINT);
    EXPECT_TRUE(flag.load());
    // After the first signal the default action is back, so a second Ctrl-C quits.
    struct sigaction now;
    sigaction(SIGINT, nullptr, &now);
    EXPECT_EQ(now.sa_handler, SIG_DFL);
    flag = false;
    install_interrupt_handler(&flag);
    ::raise(SIGHUP);
    EXPECT_TRUE(flag.load());
    uninstall_interrupt_handler();
    sigaction(SIGINT, nullptr, &now);
    EXPECT_EQ(now.sa_handler, before.sa_handler);
}

TEST(RenderLoop, TimeoutDevelopsTheWholePassesDone) {
    PluginRegistry::instance().register_static(slow_descriptor());
    // 4x4 pixels x 2 ms per sample: a pass takes 32 ms per sample per pixel, so after 0.3 s
    // some passes are done (1 + 1 + 2 + 4 spp take ~0.26 s) and far from all 1024 spp. The
    // only block is 64 x 64 pixels: the stop must come from inside it.
    auto scene = load_temp_scene(
        "timeout", scene_xml(R"(<integrator type="test_slow"><float name="timeout" value="0.3"/>
                                <integer name="block_size" value="64"/></integrator>)",
                             4, 1024, "<rfilter type=\"box\"/>"));
    RenderOptions opts;
    opts.threads = 1;
    opts.progress = false;
    RenderResult r = render(*scene, *scene->sensors().at(0), opts);
    EXPECT_TRUE(r.timed_out);
    EXPECT_TRUE(r.cancelled);
    EXPECT_LT(r.seconds, 0.3 + 1.0);
    EXPECT_GE(r.spp, 1u);
    EXPECT_LT(r.spp, 1024u);
    EXPECT_EQ(r.spp_target, 1024u);
    EXPECT_EQ(r.samples, 16u * r.spp);
    // A whole number of passes: 1, 2, 4, 8, ... samples per pixel, on every pixel.
    EXPECT_EQ(r.spp & (r.spp - 1), 0u) << r.spp;
    ASSERT_EQ(r.image.width, 4);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) EXPECT_EQ(r.image.at(x, y, 0), 1.f) << x << "," << y;
}

TEST(RenderLoop, LargeRenderStopsWithinASecondOfTheTimeout) {
    auto scene = load_temp_scene(
        "stop", scene_xml(R"(<integrator type="path"><float name="timeout" value="1"/>
                             <integer name="block_size" value="256"/></integrator>)",
                          96, 1000000, ""));
    RenderOptions opts;
    opts.threads = 2;
    opts.progress = false;
    RenderResult r = render(*scene, *scene->sensors().at(0), opts);
    EXPECT_TRUE(r.timed_out);
    EXPECT_LT(r.seconds, 1.0 + 1.0);
    EXPECT_GE(r.seconds, 1.0);
    ASSERT_GE(r.spp, 1u) << "not one pass in a second";
    // Full coverage: every pixel sees the lit scene or the sky.
    for (int y = 0; y < 96; ++y)
        for (int x = 0; x < 96; ++x) ASSERT_GT(r.image.at(x, y, 2), 0.f) << x << "," << y;
}

// The time to first pixels `facet render -v` prints: the process's CPU time when the first
// block was done, so it lies between the CPU times read before and after the render; and the
// first of the 36 blocks (of 4 passes) is done long before the render's last CPU second.
TEST(RenderLoop, FirstBlockCpuTimeIsTakenWhenTheFirstBlockIsDone) {
    auto scene = load_temp_scene("first", scene_xml(PATH, 48, 8, ""));
    const double before = process_cpu_seconds();
    RenderResult r = render_with(*scene, 2, 0, 16);
    const double after = process_cpu_seconds();
    EXPECT_EQ(r.blocks_done, 9u * 4u);
    EXPECT_GE(r.first_block_cpu_seconds, before);
    EXPECT_LE(r.first_block_cpu_seconds, after);
}

TEST(RenderLoop, ProgressiveRenderIsDeterministicAndConverges) {
    // The same image for any thread count, and the passes build up the same picture as a
    // render in one pass of all samples (samples_per_pass = spp).
    auto progressive = load_temp_scene("prog", scene_xml(PATH, 24, 37, "<rfilter type=\"box\"/>"));
    RenderResult a = render_with(*progressive, 1, 0, 5), b = render_with(*progressive, 2, 0, 5);
    EXPECT_TRUE(identical(a.image, b.image));
    EXPECT_EQ(a.spp, 37u);
    auto one_pass = load_temp_scene(
        "onepass", scene_xml(R"(<integrator type="path"><integer name="max_depth" value="6"/>
                     <integer name="samples_per_pass" value="37"/></integrator>)",
                             24, 37, "<rfilter type=\"box\"/>"));
    RenderResult c = render_with(*one_pass, 2, 0, 5);
    EXPECT_EQ(c.blocks_total, 25u);
    // The same samples in other groups: equal to float rounding.
    double max_rel = 0.0;
    for (size_t i = 0; i < a.image.data.size(); ++i)
        max_rel = std::max(max_rel, std::abs(double(a.image.data[i]) - c.image.data[i]) /
                                        std::max(1e-3, double(c.image.data[i])));
    EXPECT_LT(max_rel, 2e-6);
}

TEST(RenderLoop, BlockSizeParameterIsHonouredAndDoesNotChangeTheImage) {
    // Pixels seed their own sample streams, so with a box filter (no sample reaches a
    // neighbouring block) the block size cannot change the image.
    auto with_block = [](int block_size) {
        return load_temp_scene(
            "block", scene_xml(fmt::format(R"(<integrator type="path"><integer name="block_size"
                               value="{}"/></integrator>)",
                                           block_size),
                               24, 4, "<rfilter type=\"box\"/>"));
    };
    auto s5 = with_block(5), s0 = with_block(0);
    RenderResult a = render_with(*s5, 2, 0, /*block_size=*/0); // the integrator's block_size
    EXPECT_EQ(a.blocks_total, 25u * 3u);        // ceil(24 / 5)^2 blocks x passes of 1, 1, 2 spp
    RenderResult b = render_with(*s0, 2, 0, 0); // 0: 32, one block
    EXPECT_EQ(b.blocks_total, 1u * 3u);
    RenderResult c = render_with(*s5, 2, 0, 7); // RenderOptions override the parameter
    EXPECT_EQ(c.blocks_total, 16u * 3u);
    EXPECT_TRUE(identical(a.image, b.image));
    EXPECT_TRUE(identical(a.image, c.image));
    EXPECT_THROW(with_block(-1), Error);
}

TEST(RenderLoop, SamplesPerPass) {
    auto scene = load_temp_scene(
        "passes", scene_xml(R"(<integrator type="path"><integer name="samples_per_pass" value="2"/>
                     <integer name="max_depth" value="6"/><integer name="block_size" value="8"/></integrator>)",
                            16, 6, "<rfilter type=\"box\"/>"));
    RenderResult one = render_with(*scene, 1, 0, 0), two = render_with(*scene, 3, 0, 0);
    EXPECT_EQ(one.blocks_total, 4u * 3u); // 4 blocks x 3 passes
    EXPECT_EQ(one.samples, 16u * 16u * 6u);
    EXPECT_TRUE(identical(one.image, two.image));
    // The passes render the same picture as one pass (other noise).
    auto single = load_temp_scene("single", scene_xml(PATH, 16, 6, "<rfilter type=\"box\"/>"));
    RenderResult ref = render_with(*single, 2, 0, 0);
    double ma = 0, mb = 0;
    for (size_t i = 0; i < ref.image.data.size(); ++i) {
        ma += one.image.data[i];
        mb += ref.image.data[i];
    }
    EXPECT_NEAR(ma / mb, 1.0, 0.05);
    // The sample count must be a multiple of samples_per_pass.
    RenderOptions opts;
    opts.progress = false;
    opts.spp = 5;
    EXPECT_THROW(render(*scene, *scene->sensors().at(0), opts), Error);
}
