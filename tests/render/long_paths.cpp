// Paths that would bounce for hours (a closed mirror with Russian roulette off): a stop (the
// integrator's timeout, SIGTERM, SIGINT) ends the render within moments with a finite image,
// and the samples it cut short never reach the image.
#include "test_util.h"

#include <facet/integrator.h>
#include <facet/plugin.h>
#include <facet/render.h>

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <fcntl.h>
#include <spawn.h>
#include <thread>
#include <unistd.h>

extern char **environ;

using namespace facet;
namespace fs = std::filesystem;

namespace {

/// The camera inside a closed perfect mirror with a point light: Russian roulette never starts
/// (rr_depth 2^32 - 1) and nothing ends a path, so camera and light paths bounce some 2^32 times.
std::string mirror_scene(const std::string &integrator, const std::string &extra) {
    return fmt::format(R"(<scene version="3.0.0">
    <integrator type="{}">
        <integer name="max_depth" value="-1"/>
        <integer name="rr_depth" value="4294967295"/>
        {}
    </integrator>
    <sensor type="perspective">
        <float name="fov" value="60"/>
        <sampler type="independent">
            <integer name="sample_count" value="4"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="8"/>
            <integer name="height" value="8"/>
        </film>
    </sensor>
    <emitter type="point">
        <point name="position" x="0.3" y="0.2" z="0.1"/>
        <rgb name="intensity" value="1"/>
    </emitter>
    <shape type="sphere">
        <float name="radius" value="2"/>
        <bsdf type="twosided">
            <bsdf type="conductor">
                <string name="material" value="none"/>
            </bsdf>
        </bsdf>
    </shape>
</scene>
)",
                       integrator, extra);
}

struct Finished {
    int status = -1;
    double seconds = 0.0; ///< from the start (or the signal) to the exit
    std::string out, err;
};

/// Runs `facet render scene.xml -q? -t 2 -o out.exr` in `dir`; with `sig`, sends it once the
/// render has started (plus 300 ms). Kills facet (and fails) when it has not ended 30 s later.
Finished run_facet(const fs::path &dir, int sig = 0) {
    fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
    std::vector<std::string> args = {test::FACET, "render", (dir / "scene.xml").string(), "-t",
                                     "2",         "-o",     (dir / "out.exr").string()};
    std::vector<char *> argv;
    for (auto &a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    pid_t pid = 0;
    Finished r;
    const int spawned =
        posix_spawn(&pid, test::FACET.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (spawned != 0) {
        ADD_FAILURE() << "cannot start facet";
        return r;
    }
    using clock = std::chrono::steady_clock;
    auto start = clock::now();
    if (sig != 0) {
        while (test::read_file(out).find("Rendering") == std::string::npos &&
               clock::now() - start < std::chrono::seconds(60))
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        EXPECT_EQ(kill(pid, sig), 0);
        start = clock::now();
    }
    while (waitpid(pid, &r.status, WNOHANG) == 0) {
        if (clock::now() - start > std::chrono::seconds(30)) {
            kill(pid, SIGKILL);
            waitpid(pid, &r.status, 0);
            ADD_FAILURE() << "facet did not stop within 30 s";
            break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    r.seconds = std::chrono::duration<double>(clock::now() - start).count();
    r.out = test::read_file(out);
    r.err = test::read_file(err);
    return r;
}

class LongPaths : public ::testing::Test {
protected:
    void SetUp() override {
        m_dir = fs::temp_directory_path() / fmt::format("facet-long-paths-{}", ::getpid());
        fs::create_directories(m_dir);
    }
    void TearDown() override { fs::remove_all(m_dir); }

    /// Every pixel of the written image is finite.
    void expect_finite_image() {
        const fs::path image = m_dir / "out.exr";
        ASSERT_TRUE(fs::exists(image)) << "no image written";
        Image img = read_image(image.string());
        EXPECT_EQ(img.width, 8);
        for (float v : img.data) ASSERT_TRUE(std::isfinite(v));
    }

    fs::path m_dir;
};

TEST_F(LongPaths, TimeoutEndsAnEndlessCameraPath) {
    test::write_file(m_dir / "scene.xml",
                     mirror_scene("path", R"(<float name="timeout" value="1"/>)"));
    Finished r = run_facet(m_dir);
    ASSERT_TRUE(WIFEXITED(r.status)) << r.err;
    EXPECT_EQ(WEXITSTATUS(r.status), 0) << r.err; // a timeout is a request: success
    EXPECT_LT(r.seconds, 10.0);
    EXPECT_NE(r.out.find("Timeout reached"), std::string::npos) << r.out;
    expect_finite_image();
}

TEST_F(LongPaths, TimeoutEndsAnEndlessLightPath) {
    test::write_file(m_dir / "scene.xml",
                     mirror_scene("ptracer", R"(<float name="timeout" value="1"/>)"));
    Finished r = run_facet(m_dir);
    ASSERT_TRUE(WIFEXITED(r.status)) << r.err;
    EXPECT_EQ(WEXITSTATUS(r.status), 0) << r.err;
    EXPECT_LT(r.seconds, 10.0);
    EXPECT_NE(r.out.find("Timeout reached"), std::string::npos) << r.out;
    expect_finite_image();
}

TEST_F(LongPaths, SigtermEndsAnEndlessCameraPath) {
    test::write_file(m_dir / "scene.xml", mirror_scene("path", ""));
    Finished r = run_facet(m_dir, SIGTERM);
    ASSERT_TRUE(WIFEXITED(r.status)) << "facet died from a signal: " << r.err;
    EXPECT_EQ(WEXITSTATUS(r.status), 128 + SIGTERM) << r.err;
    EXPECT_LT(r.seconds, 5.0) << "the stop took too long";
    EXPECT_NE(r.err.find("terminated"), std::string::npos) << r.err;
    expect_finite_image();
}

TEST_F(LongPaths, FirstSigintEndsAnEndlessLightPath) {
    test::write_file(m_dir / "scene.xml", mirror_scene("ptracer", ""));
    Finished r = run_facet(m_dir, SIGINT);
    ASSERT_TRUE(WIFEXITED(r.status)) << "facet died from a signal: " << r.err;
    EXPECT_EQ(WEXITSTATUS(r.status), 128 + SIGINT) << r.err;
    EXPECT_LT(r.seconds, 5.0) << "the stop took too long";
    expect_finite_image();
}

TEST_F(LongPaths, NonsenseDepthsAreLocatedErrors) {
    for (const char *bad : {R"(<integer name="rr_depth" value="4294967296"/>)",
                            R"(<integer name="rr_depth" value="0"/>)"}) {
        std::string xml = mirror_scene("path", bad);
        // The scene's own rr_depth goes: the bad one is the only one.
        xml.replace(xml.find(R"(<integer name="rr_depth" value="4294967295"/>)"), 45, "");
        test::write_file(m_dir / "scene.xml", xml);
        Finished r = run_facet(m_dir);
        EXPECT_EQ(WEXITSTATUS(r.status), 1) << bad;
        EXPECT_NE(r.err.find("scene.xml:5:"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("rr_depth must be a value in [1, 4294967295]"), std::string::npos)
            << r.err;
    }
    std::string xml = mirror_scene("ptracer", "");
    xml.replace(xml.find(R"(value="-1")"), 10, R"(value="10000000000")");
    test::write_file(m_dir / "scene.xml", xml);
    Finished r = run_facet(m_dir);
    EXPECT_EQ(WEXITSTATUS(r.status), 1);
    EXPECT_NE(r.err.find("scene.xml:3:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("max_depth must be -1 (unbounded) or a value in [0, 4294967295]"),
              std::string::npos)
        << r.err;
}

/// Test integrator: radiance 1, except that sample g_endless_from on (counted over the whole
/// render, one thread) runs until render_should_stop() and then returns a value no image may
/// show.
std::atomic<uint64_t> g_samples{0};
uint64_t g_endless_from = 0;
class EndlessIntegrator final : public SamplingIntegrator {
public:
    explicit EndlessIntegrator(const Properties &p) : SamplingIntegrator(p) {}
    Color3f sample(const Scene &, Sampler &, const Ray &, float *) const override {
        if (g_samples++ < g_endless_from) return Color3f(1.f);
        for (uint32_t i = 0;; ++i)
            if (render_should_stop(i)) return Color3f(1e6f);
    }
};

const PluginDescriptor *endless_descriptor() {
    static const PluginDescriptor desc{
        FACET_ABI_VERSION,
        ObjectType::Integrator,
        "test_endless",
        "test integrator",
        "| timeout | float | -1 | |\n| samples_per_pass | integer | | |\n| block_size | integer | "
        "0 | |\n",
        [](const Properties &p) -> Object * { return new EndlessIntegrator(p); }};
    return &desc;
}

TEST(LongPathsApi, CutShortSamplesNeverReachTheImage) {
    PluginRegistry::instance().register_static(endless_descriptor());
    // 8 x 8 pixels in one block, passes of 1, 1, 2, ... samples: the first two passes (128
    // samples) and all but the last sample of the third return 1; the last one of the block runs
    // until the timeout, after the block loop's last own check. Its pass must be dropped.
    auto scene = test::load_temp_scene("endless",
                                       R"(<scene version="3.0.0">
    <integrator type="test_endless"><float name="timeout" value="0.3"/></integrator>
    <sensor type="perspective">
        <sampler type="independent"><integer name="sample_count" value="64"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="8"/><integer name="height" value="8"/>
            <rfilter type="box"/>
        </film>
    </sensor>
</scene>)");
    g_samples = 0;
    g_endless_from = 64 + 64 + 128 - 1;
    RenderOptions opts;
    opts.threads = 1;
    opts.progress = false;
    RenderResult r = render(*scene, *scene->sensors().at(0), opts);
    EXPECT_TRUE(r.timed_out);
    EXPECT_EQ(r.spp, 2u);
    EXPECT_EQ(g_samples.load(), g_endless_from + 1) << "more samples after the stop";
    ASSERT_EQ(r.image.width, 8);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) EXPECT_EQ(r.image.at(x, y, 0), 1.f) << x << "," << y;
}

TEST(LongPathsApi, ShouldStopIsFalseOutsideARender) {
    EXPECT_FALSE(render_should_stop());
    for (uint32_t i = 0; i < 64; ++i) EXPECT_FALSE(render_should_stop(i));
}

} // namespace
