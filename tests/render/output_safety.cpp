// A finished render is never lost and a bad output is refused before rendering: signals during
// the write of the output (deferred until the file is complete, then exit 128 + the signal), and
// check_output (a directory, a read-only folder, a long name, TIFF, AOV names) before the render.

#include "test_util.h"

#include <facet/image.h>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <fcntl.h>
#include <filesystem>
#include <set>
#include <spawn.h>
#include <string>
#include <thread>
#include <unistd.h>
#include <vector>

extern char **environ;

namespace {

namespace fs = std::filesystem;
using facet::test::FACET;
using facet::test::lines;
using facet::test::read_file;
using Clock = std::chrono::steady_clock;

/// A diffuse sphere under a constant sky; `res` x `res`/2 pixels.
const char *SCENE = R"(<scene version="3.0.0">
    <default name="spp" value="1"/>
    <default name="res" value="32"/>
    <default name="aovs" value="dd:depth"/>
    <default name="timeout" value="-1"/>
    <integrator type="aov">
        <string name="aovs" value="$aovs"/>
        <float name="timeout" value="$timeout"/>
        <integrator type="path"><integer name="max_depth" value="3"/></integrator>
    </integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world">
            <lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="$res"/>
            <integer name="height" value="$res"/>
        </film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="1, 0.9, 0.8"/></emitter>
    <shape type="sphere">
        <bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.5, 0.7"/></bsdf>
    </shape>
</scene>
)";

class OutputSafety : public facet::test::ScratchFolderTest {
protected:
    OutputSafety() : ScratchFolderTest("output_safety", SCENE) {}

    /// `facet render` of a scene that would render for minutes is refused before rendering: exit
    /// 1, one "facet: error:" line containing `expected`, within a few seconds, nothing written.
    void expect_refused(const std::string &args, const std::string &expected) {
        const std::set<std::string> before = files();
        const auto start = std::chrono::steady_clock::now();
        facet::test::CommandResult r = run("render scene.xml -D res=2048 -D spp=100000 " + args);
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        EXPECT_EQ(r.code, 1) << args << "\n" << r.err;
        EXPECT_EQ(r.out.find("Rendering"), std::string::npos) << "it rendered: " << r.out;
        const std::vector<std::string> err = facet::test::lines(r.err);
        ASSERT_EQ(err.size(), 1u) << r.err;
        EXPECT_EQ(err[0].rfind("facet: error: ", 0), 0u) << err[0];
        EXPECT_NE(err[0].find(expected), std::string::npos) << err[0];
        EXPECT_LT(seconds, 5.0) << "refused only after " << seconds << " s";
        EXPECT_EQ(files(), before) << "a file was left behind";
    }
};

std::string attribute(const std::string &path, const std::string &name) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) return "<cannot open>";
    return in->spec().get_string_attribute(name, "<missing>");
}

TEST(InterruptHandler, DefersEverySignalDuringTheWrite) {
    std::atomic<bool> flag{false};
    facet::install_interrupt_handler(&flag);
    ::raise(SIGTERM); // while rendering: the flag, and SIGTERM's default action is back
    EXPECT_TRUE(flag.load());
    struct sigaction now;
    sigaction(SIGTERM, nullptr, &now);
    EXPECT_EQ(now.sa_handler, SIG_DFL);
    facet::defer_interrupts();
    // From the write on, nothing is fatal: this process survives them all.
    for (int sig : {SIGTERM, SIGTERM, SIGINT, SIGINT, SIGHUP, SIGHUP}) ::raise(sig);
    EXPECT_EQ(facet::interrupt_signal(), SIGTERM) << "the first signal is the one reported";
    facet::uninstall_interrupt_handler();
    EXPECT_EQ(facet::interrupt_signal(), SIGTERM);
}

TEST_F(OutputSafety, WriteImageTakesTheLongestFileNames) {
    // The longest name a file can have: its temporary name is shortened, and two such names
    // with the same start still get temporary files of their own.
    facet::Image img(4, 2, 3);
    for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = float(i) / 24.f;
    for (const std::string ext : {".exr", ".png", ".pfm"}) {
        const std::string a = std::string(255 - ext.size() - 1, 'a') + "1" + ext;
        const std::string b = std::string(255 - ext.size() - 1, 'a') + "2" + ext;
        ASSERT_EQ(a.size(), 255u);
        facet::check_output_file(path(a));
        facet::write_image(path(a), img);
        facet::write_image(path(b), img);
        EXPECT_EQ(facet::read_image(path(a)).width, 4) << ext;
        EXPECT_EQ(files(), (std::set<std::string>{"scene.xml", a, b})) << ext;
        fs::remove(path(a));
        fs::remove(path(b));
    }
}

/// Lowers the process's file size limit to `bytes` with SIGXFSZ ignored (a write past it then
/// fails with EFBIG, as a full disk fails one), and restores both, whatever happens in between.
struct FileSizeLimit {
    struct rlimit saved {};
    struct sigaction saved_action {};
    bool set = false;
    explicit FileSizeLimit(rlim_t bytes) {
        struct sigaction ignore {};
        ignore.sa_handler = SIG_IGN;
        if (getrlimit(RLIMIT_FSIZE, &saved) != 0 || sigaction(SIGXFSZ, &ignore, &saved_action) != 0)
            return;
        struct rlimit lower = saved;
        lower.rlim_cur = bytes;
        set = setrlimit(RLIMIT_FSIZE, &lower) == 0;
        if (!set) sigaction(SIGXFSZ, &saved_action, nullptr);
    }
    ~FileSizeLimit() {
        if (!set) return;
        setrlimit(RLIMIT_FSIZE, &saved);
        sigaction(SIGXFSZ, &saved_action, nullptr);
    }
};

TEST_F(OutputSafety, AWriteThatFailsHalfwayKeepsTheOldFile) {
    // A disk that fills up while the image is written (here: a file size limit, which fails the
    // write past it as a full disk does): "cannot write image" with the reason, the existing
    // file unchanged, no temporary file left. The EXR writer streams its blocks into the file
    // as OpenEXR compresses them, so the failure comes in the middle of its output.
    facet::Image old_img(8, 8, 3);
    for (size_t i = 0; i < old_img.data.size(); ++i) old_img.data[i] = 0.25f;
    auto noise = [](int size) { // ZIP cannot shrink it below the limit
        facet::Image img(size, size, 3);
        uint32_t state = 1;
        for (float &v : img.data) {
            state = state * 1664525u + 1013904223u;
            v = float(state >> 8) / float(1u << 24);
        }
        return img;
    };
    // 1024² pixels: OpenEXR compresses on its pool of threads, whose write fails.
    for (const auto &[name, size] :
         {std::pair<std::string, int>{"out.exr", 512}, {"big.exr", 1024}, {"out.png", 512}}) {
        SCOPED_TRACE(name);
        const facet::Image img = noise(size);
        facet::write_image(path(name), old_img);
        const std::string before = read_file(path(name));
        std::string error;
        {
            const FileSizeLimit limit(64 * 1024);
            if (!limit.set) GTEST_SKIP() << "cannot lower this process's file size limit";
            try {
                facet::write_image(path(name), img);
            } catch (const facet::Error &e) {
                error = e.what();
            }
        }
        EXPECT_NE(error.find("cannot write image"), std::string::npos) << error;
        EXPECT_NE(error.find("File too large"), std::string::npos) << error;
        EXPECT_NE(error.find("the existing file is unchanged"), std::string::npos) << error;
        EXPECT_EQ(read_file(path(name)), before) << "the old file was changed";
        EXPECT_EQ(files(), (std::set<std::string>{"scene.xml", name})) << "a file was left";
        fs::remove(path(name));
    }
}

TEST_F(OutputSafety, CheckOutputFileNamesWhatIsWrong) {
    auto error_of = [](const std::string &p) -> std::string {
        try {
            facet::check_output_file(p);
        } catch (const facet::Error &e) {
            return e.what();
        }
        return "";
    };
    fs::create_directories(m_dir / "folder.exr");
    EXPECT_NE(error_of(path("folder.exr")).find("is a directory"), std::string::npos);
    EXPECT_NE(error_of(path("none/x.exr")).find("does not exist"), std::string::npos);
    EXPECT_NE(error_of(path(std::string(256, 'x'))).find("more than the 255"), std::string::npos);
    ASSERT_EQ(::mkfifo(path("fifo.exr").c_str(), 0644), 0);
    EXPECT_NE(error_of(path("fifo.exr")).find("not a regular file"), std::string::npos);
    EXPECT_EQ(error_of(path("fine.exr")), "");
    EXPECT_EQ(files(), (std::set<std::string>{"scene.xml", "folder.exr", "fifo.exr"}));
}

/// A `facet render` started in the background (stdout and stderr to files in `dir`).
struct Child {
    pid_t pid = 0;
    fs::path out, err;

    Child(const fs::path &dir, std::vector<std::string> args) {
        out = dir / ".child.out";
        err = dir / ".child.err";
        args.insert(args.begin(), FACET);
        std::vector<char *> argv;
        for (auto &a : args) argv.push_back(a.data());
        argv.push_back(nullptr);
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_addopen(&actions, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                         0644);
        posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                         0644);
        posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
        // The child runs in the test's own folder (relative names resolve there).
        posix_spawn_file_actions_addchdir_np(&actions, dir.c_str());
        if (posix_spawn(&pid, FACET.c_str(), &actions, nullptr, argv.data(), environ) != 0) pid = 0;
        posix_spawn_file_actions_destroy(&actions);
    }

    /// Waits (at most `limit`) for the exit; returns the wait status (-1: killed after `limit`).
    int wait(std::chrono::seconds limit = std::chrono::seconds(120)) {
        int status = 0;
        const auto start = Clock::now();
        while (waitpid(pid, &status, WNOHANG) == 0) {
            if (Clock::now() - start > limit) {
                kill(pid, SIGKILL);
                waitpid(pid, &status, 0);
                return -1;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
        }
        return status;
    }

    /// Stops the process (SIGSTOP) and says whether `file` exists while it is stopped; if not,
    /// it runs on.
    bool stopped_while_exists(const fs::path &file) {
        kill(pid, SIGSTOP);
        int status = 0;
        waitpid(pid, &status, WUNTRACED);
        if (!WIFSTOPPED(status)) return false; // it had exited: reaped here
        if (fs::exists(file)) return true;
        kill(pid, SIGCONT);
        return false;
    }
};

/// What one attempt at a signal during the write gave.
struct WriteSignal {
    bool landed = false; ///< the signal(s) reached facet while its temporary file existed
    int status = 0;
    std::string out, err;
};

/// Renders `res` x `res` pixels to `image` (a PNG: encoding, writing and the pixel-exact read-back
/// take a while) and, while the temporary file of the output exists (facet stopped with SIGSTOP
/// to be sure of that), sends `sig` (`times` times, letting facet run in between).
WriteSignal signal_during_write(const fs::path &dir, const std::string &image, int sig, int res,
                                int times = 1) {
    WriteSignal r;
    Child child(dir, {"render", "scene.xml", "-D", "res=" + std::to_string(res), "-D", "spp=1",
                      "-t", "2", "-o", image});
    if (child.pid == 0) {
        ADD_FAILURE() << "cannot start facet";
        return r;
    }
    const fs::path tmp = dir / ("." + image + ".tmp-" + std::to_string(child.pid));
    // The temporary name is also created (and removed) by the check before the render: wait for
    // the render first.
    const auto start = Clock::now();
    while (read_file(child.out).find("Rendering") == std::string::npos &&
           Clock::now() - start < std::chrono::seconds(60))
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    bool landed = false;
    while (!landed && Clock::now() - start < std::chrono::seconds(60)) {
        if (waitpid(child.pid, &r.status, WNOHANG) != 0) break; // the write was missed
        if (fs::exists(tmp)) landed = child.stopped_while_exists(tmp);
        if (!landed) std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    for (int i = 0; landed && i < times; ++i) {
        if (i > 0) {
            // Let facet take the first signal, then stop it again inside the write.
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
            landed = child.stopped_while_exists(tmp);
            if (!landed) break;
        }
        kill(child.pid, sig);
        kill(child.pid, SIGCONT);
    }
    r.landed = landed;
    if (landed || waitpid(child.pid, &r.status, WNOHANG) == 0) r.status = child.wait();
    r.out = read_file(child.out);
    r.err = read_file(child.err);
    fs::remove(child.out);
    fs::remove(child.err);
    return r;
}

/// Up to `attempts` renders until the signal lands in the write (a miss: the write was over
/// between seeing the temporary file and stopping facet).
WriteSignal signal_during_write_retried(const fs::path &dir, const std::string &image, int sig,
                                        int times = 1) {
    WriteSignal r;
    for (int attempt = 0; attempt < 4 && !r.landed; ++attempt) {
        fs::remove(dir / image);
        r = signal_during_write(dir, image, sig, 640 << (attempt / 2), times);
    }
    return r;
}

void expect_complete_output_after(const WriteSignal &r, int sig, const fs::path &image,
                                  const std::set<std::string> &files) {
    ASSERT_TRUE(r.landed) << "the signal never reached facet during the write";
    ASSERT_TRUE(WIFEXITED(r.status))
        << "facet died from signal " << (WIFSIGNALED(r.status) ? WTERMSIG(r.status) : 0)
        << "\nstderr:\n"
        << r.err;
    EXPECT_EQ(WEXITSTATUS(r.status), 128 + sig) << r.err;
    // One line says which signal and what was written.
    const std::vector<std::string> err = lines(r.err);
    ASSERT_FALSE(err.empty());
    const std::string &last = err.back();
    EXPECT_NE(last.find(facet::interrupt_signal_name(sig)), std::string::npos) << last;
    EXPECT_NE(last.find("while writing"), std::string::npos) << last;
    EXPECT_NE(last.find("wrote the complete image (1 of 1 spp)"), std::string::npos) << last;
    EXPECT_NE(last.find(image.filename().string()), std::string::npos) << last;
    // The output is whole and no temporary file is left.
    ASSERT_TRUE(fs::exists(image));
    facet::Image img = facet::read_image(image.string());
    EXPECT_GE(img.width, 640);
    EXPECT_EQ(img.height, img.width);
    EXPECT_EQ(files, (std::set<std::string>{"scene.xml", image.filename().string()}));
}

TEST_F(OutputSafety, SigtermDuringTheWriteFinishesItThenExits143) {
    WriteSignal r = signal_during_write_retried(m_dir, "term.png", SIGTERM);
    expect_complete_output_after(r, SIGTERM, m_dir / "term.png", files());
}

TEST_F(OutputSafety, SigintDuringTheWriteFinishesItThenExits130) {
    WriteSignal r = signal_during_write_retried(m_dir, "int.png", SIGINT);
    expect_complete_output_after(r, SIGINT, m_dir / "int.png", files());
}

TEST_F(OutputSafety, SighupDuringTheWriteFinishesItThenExits129) {
    WriteSignal r = signal_during_write_retried(m_dir, "hup.png", SIGHUP);
    expect_complete_output_after(r, SIGHUP, m_dir / "hup.png", files());
}

TEST_F(OutputSafety, ARepeatedSignalDuringTheWriteIsNotFatalEither) {
    WriteSignal r = signal_during_write_retried(m_dir, "twice.png", SIGINT, 2);
    expect_complete_output_after(r, SIGINT, m_dir / "twice.png", files());
    EXPECT_NE(r.err.find("still writing the image"), std::string::npos) << r.err;
}

TEST_F(OutputSafety, SigtermDuringTheWriteOfAMergeFinishesItThenExits143) {
    // The merge of a split render is its last step: a Slurm time limit landing in its write
    // lost the whole render (the merge died, the temporary file stayed).
    bool landed = false;
    int status = 0;
    std::string err;
    for (int attempt = 0; attempt < 4 && !landed; ++attempt) {
        const std::string res = std::to_string(640 << (attempt / 2));
        for (int i = 0; i < 2; ++i) {
            facet::test::CommandResult r =
                run("render scene.xml -q -t 2 -D res=" + res + " -D spp=1 --passes 2 --pass " +
                    std::to_string(i) + " -o part" + std::to_string(i) + ".exr");
            ASSERT_EQ(r.code, 0) << r.err;
        }
        fs::remove(m_dir / "merged.png");
        Child child(m_dir, {"merge", "part0.exr", "part1.exr", "-o", "merged.png"});
        ASSERT_NE(child.pid, 0) << "cannot start facet";
        const fs::path tmp = m_dir / (".merged.png.tmp-" + std::to_string(child.pid));
        const auto start = Clock::now();
        while (!landed && Clock::now() - start < std::chrono::seconds(60)) {
            if (waitpid(child.pid, &status, WNOHANG) != 0) break; // the write was missed
            if (fs::exists(tmp)) landed = child.stopped_while_exists(tmp);
            if (!landed) std::this_thread::sleep_for(std::chrono::microseconds(200));
        }
        if (landed) {
            kill(child.pid, SIGTERM);
            kill(child.pid, SIGCONT);
            status = child.wait();
        }
        err = read_file(child.err);
        fs::remove(child.out);
        fs::remove(child.err);
    }
    ASSERT_TRUE(landed) << "the signal never reached the merge during its write";
    ASSERT_TRUE(WIFEXITED(status))
        << "the merge died from signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0) << "\n"
        << err;
    EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM) << err;
    const std::vector<std::string> err_lines = lines(err);
    ASSERT_FALSE(err_lines.empty());
    EXPECT_NE(err_lines.back().find("SIGTERM"), std::string::npos) << err;
    EXPECT_NE(err_lines.back().find("wrote the merged image to merged.png"), std::string::npos)
        << err;
    facet::Image img = facet::read_image(path("merged.png"));
    EXPECT_GE(img.width, 640);
    EXPECT_EQ(img.height, img.width);
    EXPECT_EQ(files(),
              (std::set<std::string>{"scene.xml", "part0.exr", "part1.exr", "merged.png"}));
}

TEST_F(OutputSafety, TimeoutAndSignalWriteThePartialImageTheSameWay) {
    // The integrator's timeout stops a render of far too many samples: the passes done are
    // written as a Ctrl-C writes them (same attributes), and the exit is a success.
    facet::test::CommandResult r =
        run("render scene.xml -q -D res=64 -D spp=1000000 -D timeout=0.5 -o timeout.exr");
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string image = path("timeout.exr");
    const int spp = std::stoi(attribute(image, "facet:spp"));
    EXPECT_GE(spp, 1);
    EXPECT_LT(spp, 1000000);
    EXPECT_EQ(attribute(image, "facet:spp_target"), "1000000");
    EXPECT_NE(attribute(image, "facet:blocks"), "<missing>");
    EXPECT_EQ(files(), (std::set<std::string>{"scene.xml", "timeout.exr"}));

    Child child(m_dir,
                {"render", "scene.xml", "-D", "res=64", "-D", "spp=1000000", "-o", "signal.exr"});
    ASSERT_NE(child.pid, 0);
    const auto start = Clock::now();
    while (read_file(child.out).find("Rendering") == std::string::npos &&
           Clock::now() - start < std::chrono::seconds(60))
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    kill(child.pid, SIGINT);
    const int status = child.wait();
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 130);
    const std::string signalled = path("signal.exr");
    EXPECT_EQ(attribute(signalled, "facet:spp_target"), "1000000");
    EXPECT_NE(attribute(signalled, "facet:blocks"), "<missing>");
    EXPECT_LT(std::stoi(attribute(signalled, "facet:spp")), 1000000);
    fs::remove(child.out);
    fs::remove(child.err);
}

// ---------------------------------------------------------------------------------------------
// check_output: refused before rendering, not after it

TEST_F(OutputSafety, AnOutputThatIsADirectoryIsRefusedBeforeRendering) {
    // `-o a_folder` writes the scene's name into the folder (as Mitsuba does), so the output
    // that is a directory is the one that name gives: scene.exr, next to scene.xml.
    fs::create_directories(m_dir / "scene.exr");
    expect_refused("", "is a directory");
    fs::create_directories(m_dir / "out" / "scene.exr");
    expect_refused("-o out", "is a directory");
}

TEST_F(OutputSafety, AMissingFolderIsRefusedBeforeRendering) {
    expect_refused("-o nowhere/out.exr", "does not exist");
}

TEST_F(OutputSafety, AReadOnlyFolderIsRefusedBeforeRendering) {
    fs::create_directories(m_dir / "ro");
    fs::permissions(m_dir / "ro", fs::perms::owner_read | fs::perms::owner_exec);
    // Permissions do not bind root: a folder of a read-only file system (sysfs) does.
    auto takes_files = [](const std::string &folder) {
        const std::string probe = folder + "/.facet-probe";
        const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT, 0644);
        if (fd < 0) return false;
        ::close(fd);
        ::unlink(probe.c_str());
        return true;
    };
    std::string folder = (m_dir / "ro").string();
    if (takes_files(folder)) folder = "/sys";
    if (!fs::is_directory(folder) || takes_files(folder))
        GTEST_SKIP() << "no read-only folder for this user (permissions do not bind it and /sys "
                        "is missing or writable)";
    expect_refused("-o " + folder + "/out.exr", "cannot create a file in the folder");
    fs::permissions(m_dir / "ro", fs::perms::owner_all);
}

TEST_F(OutputSafety, AnOverlongNameIsRefusedBeforeRendering) {
    expect_refused("-o " + std::string(260, 'n') + ".exr", "more than the 255");
}

TEST_F(OutputSafety, AnAovNamedLikeAColourChannelIsRefusedBeforeRendering) {
    // Mitsuba refuses duplicate channel names too; the AOV would hide the red channel.
    expect_refused("-D aovs=R:depth -o out.exr", "AOV \"R\" has the name of a colour channel");
    expect_refused("-D aovs=d:depth,d:depth -o out.exr", "AOV \"d\" has the name of another AOV");
    // The raw sums of a part of a split render are channels too.
    expect_refused("-D aovs=facet.weight:depth --pass 0 --passes 2 -o part.exr",
                   "AOV \"facet.weight\" has the name of a raw channel");
}

TEST_F(OutputSafety, ALongValidNameIsWritten) {
    // 250 bytes fit a file name; ".NAME.tmp-PID" does not, and is shortened.
    const std::string name = std::string(246, 'l') + ".png";
    ASSERT_EQ(name.size(), 250u);
    facet::test::CommandResult r = run("render scene.xml -q -o " + name);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(facet::read_image(path(name)).width, 32);
    EXPECT_EQ(files(), (std::set<std::string>{"scene.xml", name}));
}

TEST_F(OutputSafety, TiffOutputsAreWrittenAndReadBack) {
    for (const std::string name : {"out.tif", "out.tiff"}) {
        facet::test::CommandResult r = run("render scene.xml -q -o " + name);
        ASSERT_EQ(r.code, 0) << name << ": " << r.err;
        facet::Image tif = facet::read_image(path(name));
        EXPECT_EQ(tif.width, 32);
        EXPECT_EQ(tif.channels, 3);
    }
    // The same 8-bit pixels as a PNG of the same render.
    ASSERT_EQ(run("render scene.xml -q -o out.png").code, 0);
    facet::Image tif = facet::read_image(path("out.tif")), png = facet::read_image(path("out.png"));
    EXPECT_TRUE(facet::test::identical(tif, png));
    EXPECT_EQ(files(), (std::set<std::string>{"scene.xml", "out.tif", "out.tiff", "out.png"}));
}

} // namespace
