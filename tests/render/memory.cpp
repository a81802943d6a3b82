// The peak memory of `facet render` (the child's maximum resident set size, from wait4()): a
// render to EXR (written with OpenEXR alone) stays small; one to PNG pays for loading
// OpenImageIO, OpenColorIO and their dependencies (most of its peak) and for nothing large
// beyond that.

#include "test_util.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <fcntl.h>
#include <spawn.h>
#include <string>
#include <vector>

extern char **environ;

namespace {

using namespace facet::test;

/// A 64x64 Cornell-like box: a sphere under an area light, diffuse walls.
const char *SCENE = R"(<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="4"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/>
        </transform>
        <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="64"/>
        </film>
        <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
    </sensor>
    <shape type="sphere"><float name="radius" value="0.5"/><bsdf type="diffuse"/></shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="0.3"/><rotate x="1" angle="90"/>
            <translate y="1"/></transform>
        <emitter type="area"><rgb name="radiance" value="10"/></emitter>
    </shape>
    <shape type="cube">
        <transform name="to_world"><scale value="1.1"/></transform>
        <bsdf type="diffuse"/><boolean name="flip_normals" value="true"/>
    </shape>
</scene>)";

class PeakMemory : public ScratchFolderTest {
protected:
    PeakMemory() : ScratchFolderTest("memory", SCENE) {}

    /// Runs `facet render scene.xml -o <output> -t 2 -q` in the test folder; returns its
    /// maximum resident set size in MiB (and checks it succeeded and wrote the file).
    double render_peak_mib(const std::string &output) {
        const std::string scene = path("scene.xml"), out = path(output);
        std::vector<std::string> args = {FACET, "render", scene, "-o", out, "-t", "2", "-q"};
        std::vector<char *> argv;
        for (std::string &a : args) argv.push_back(a.data());
        argv.push_back(nullptr);
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
        pid_t pid = 0;
        const int err = posix_spawn(&pid, FACET.c_str(), &actions, nullptr, argv.data(), environ);
        posix_spawn_file_actions_destroy(&actions);
        if (err != 0) {
            ADD_FAILURE() << "cannot run " << FACET << ": " << std::strerror(err);
            return 0.0;
        }
        int status = 0;
        rusage usage{};
        EXPECT_EQ(wait4(pid, &status, 0, &usage), pid);
        EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "status " << status;
        EXPECT_TRUE(fs::is_regular_file(out)) << out;
        return double(usage.ru_maxrss) / 1024.0; // kB on Linux
    }
};

#if defined(__SANITIZE_ADDRESS__)
#define FACET_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer) ||                         \
    __has_feature(thread_sanitizer)
#define FACET_TEST_SANITIZED 1
#endif
#endif

#ifdef FACET_TEST_SANITIZED
#define SKIP_IF_SANITIZED()                                                                        \
    GTEST_SKIP() << "a sanitizer's shadow memory and quarantine dominate the resident size"
#else
#define SKIP_IF_SANITIZED()
#endif

} // namespace

// A render to EXR never loads OpenImageIO: the process, Embree, TBB, the plugins and OpenEXR
// (12-13 MiB on the Cornell box, against 15 MiB for Mitsuba 3 there).
TEST_F(PeakMemory, RenderToExrStaysUnder30MiB) {
    SKIP_IF_SANITIZED();
    const double mib = render_peak_mib("out.exr");
    EXPECT_GT(mib, 1.0);
    EXPECT_LE(mib, 30.0) << "peak resident size of a 64x64 render to .exr";
}

// OpenImageIO 2.4 and the ~260 libraries it links take ~120 MiB once loaded (their relocated
// pages, symbol tables touched by the dynamic loader, and a 25 MiB string table OpenImageIO
// builds as it loads): 142 MiB in all. A copy of the image or a conversion buffer in the write
// or its verification would show on top of that.
TEST_F(PeakMemory, RenderToPngAddsOnlyTheImageLibrary) {
    SKIP_IF_SANITIZED();
    const double mib = render_peak_mib("out.png");
    EXPECT_GT(mib, 1.0);
    EXPECT_LE(mib, 180.0) << "peak resident size of a 64x64 render to .png";
}
