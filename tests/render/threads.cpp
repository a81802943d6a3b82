// Thread counts beyond the hardware's are capped, with one warning: -t 10000000 used to crash
// inside TBB and -t 1000000 to take half a gigabyte.
#include "test_util.h"

#include <facet/logger.h>
#include <facet/render.h>

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <regex>

using namespace facet;

namespace {

const char *SCENE = R"(<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="3"/></integrator>
    <sensor type="perspective">
        <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="16"/><integer name="height" value="16"/>
        </film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
    <shape type="sphere"><bsdf type="diffuse"/></shape>
</scene>
)";

RenderResult render_with(const Scene &scene, int threads, int pass_index = 0, int passes = 1) {
    RenderOptions opts;
    opts.threads = threads;
    opts.progress = false;
    opts.pass_index = pass_index;
    opts.pass_count = passes;
    return render(scene, *scene.sensors().at(0), opts);
}

class ThreadsCli : public test::ScratchFolderTest {
protected:
    ThreadsCli() : ScratchFolderTest("threads", SCENE) {}
};

} // namespace

TEST(Threads, CappedAtTheHardwareThreads) {
    const int hw = hardware_threads();
    EXPECT_GE(hw, 1);
    EXPECT_EQ(capped_thread_count(0), hw);
    EXPECT_EQ(capped_thread_count(1), 1);
    EXPECT_EQ(capped_thread_count(hw), hw);
    EXPECT_EQ(capped_thread_count(hw + 1), hw);
    EXPECT_EQ(capped_thread_count(10'000'000), hw);
    EXPECT_THROW(capped_thread_count(-1), Error);
    RenderOptions opts;
    opts.threads = 10'000'000;
    EXPECT_EQ(render_thread_count(opts), hw);
}

TEST(Threads, RenderOptionsBeyondTheHardwareWarnOnceAndRenderTheSameImage) {
    auto scene = test::load_temp_scene("threads", SCENE);
    const RenderResult reference = render_with(*scene, 0, -1, 2);
    const size_t warnings = Logger::warning_count();
    // Ten million threads crashed inside TBB; every part of a render in parts counts once.
    const RenderResult capped = render_with(*scene, 10'000'000, -1, 2);
    EXPECT_EQ(Logger::warning_count(), warnings + 1);
    EXPECT_TRUE(test::identical(reference.image, capped.image));
}

TEST_F(ThreadsCli, DashTBeyondTheHardwareWarnsOnceAndSaysTheThreadsUsed) {
    const int hw = hardware_threads();
    test::CommandResult r = run("render scene.xml -t 1000000 -o out.exr");
    ASSERT_EQ(r.code, 0) << r.err;
    // One warning line, facet's own (no "TBB Warning: ..." of its own), naming the option.
    std::vector<std::string> warnings;
    for (const std::string &line : test::lines(r.err))
        if (line.rfind("[I] ", 0) != 0) warnings.push_back(line);
    ASSERT_EQ(warnings.size(), 1u) << r.err;
    EXPECT_EQ(warnings[0].rfind("[W] -t 1000000: ", 0), 0u) << warnings[0];
    EXPECT_EQ(r.err.find("TBB"), std::string::npos) << r.err;
    // The threads used, not the threads asked for.
    EXPECT_TRUE(std::regex_search(r.out, std::regex(fmt::format(", {} threads?\n", hw)))) << r.out;
    // A million threads took 543 MB; a render of this scene needs a small fraction of that.
    rusage ru{};
    getrusage(RUSAGE_CHILDREN, &ru);
    EXPECT_LT(ru.ru_maxrss, 200 * 1024) << "kB";
}
