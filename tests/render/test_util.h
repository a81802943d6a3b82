#pragma once

// Helpers the render tests share: scenes from XML text, renders without a progress line, image
// comparisons, files, and the `facet` command run in a scratch folder per test.

#include <facet/image.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

namespace facet::test {

namespace fs = std::filesystem;

/// The `facet` command of this build tree.
inline const std::string FACET = FACET_BINARY_DIR "/bin/facet";

inline std::string read_file(const fs::path &path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

inline void write_file(const fs::path &path, const std::string &text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
}

/// The non-empty lines of `text`.
inline std::vector<std::string> lines(const std::string &text) {
    std::vector<std::string> result;
    std::stringstream ss(text);
    for (std::string line; std::getline(ss, line);)
        if (!line.empty()) result.push_back(line);
    return result;
}

/// Writes `xml` to <name>.xml in a temporary folder, loads it with the XML loader (as a scene
/// file, so relative paths resolve against that folder) and removes the folder.
inline std::shared_ptr<Scene> load_temp_scene(const std::string &name, const std::string &xml,
                                              const LoadOptions &opts = {}) {
    fs::path dir = fs::temp_directory_path() / fmt::format("facet-render-test-{}", ::getpid());
    fs::create_directories(dir);
    fs::path file = dir / (name + ".xml");
    std::ofstream(file) << xml;
    auto scene = load_scene(file.string(), opts);
    fs::remove_all(dir);
    return scene;
}

/// Renders the first sensor of `scene` without a progress line (threads 0: all cores; block
/// size 0: the integrator's).
inline RenderResult render_quiet(const Scene &scene, int threads = 0, uint64_t seed = 0,
                                 int block_size = 0) {
    RenderOptions opts;
    opts.threads = threads;
    opts.seed = seed;
    opts.block_size = block_size;
    opts.progress = false;
    return render(scene, *scene.sensors().at(0), opts);
}

/// Loads the scene in `xml` (no file: relative paths resolve against the working folder) and
/// renders its first sensor.
inline Image render_xml(const std::string &xml) {
    auto scene = std::dynamic_pointer_cast<Scene>(load_string(xml));
    return render_quiet(*scene).image;
}

/// Same size, channels and bits.
inline bool identical(const Image &a, const Image &b) {
    return a.width == b.width && a.height == b.height && a.channels == b.channels &&
           a.data.size() == b.data.size() &&
           std::memcmp(a.data.data(), b.data.data(), a.data.size() * sizeof(float)) == 0;
}

/// Index of the channel called `name`, or -1.
inline int channel(const Image &img, const std::string &name) {
    for (size_t i = 0; i < img.channel_names.size(); ++i)
        if (img.channel_names[i] == name) return int(i);
    return -1;
}

struct CommandResult {
    int code = -1;
    std::string out, err;
};

/// Runs `<prefix> facet <args>` through the shell in `dir` (prefix: environment variables,
/// ulimit, ...), stdin from /dev/null; stdout and stderr are captured.
inline CommandResult run_facet(const fs::path &dir, const std::string &args,
                               const std::string &prefix = "") {
    fs::path out = dir / ".stdout", err = dir / ".stderr";
    std::string cmd = "cd '" + dir.string() + "' && " + prefix + " '" + FACET + "' " + args +
                      " > '" + out.string() + "' 2> '" + err.string() + "' < /dev/null";
    int status = std::system(cmd.c_str());
    CommandResult r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = read_file(out);
    r.err = read_file(err);
    fs::remove(out);
    fs::remove(err);
    return r;
}

/// A fixture with a scratch folder per test (<tmp>/facet_<tag>_<test>_<pid>) holding scene.xml;
/// the folder is removed after a test that passed, kept for a look after one that failed.
class ScratchFolderTest : public ::testing::Test {
protected:
    ScratchFolderTest(std::string tag, std::string scene)
        : m_tag(std::move(tag)), m_scene(std::move(scene)) {}

    void SetUp() override {
        const auto *info = ::testing::UnitTest::GetInstance()->current_test_info();
        m_dir = fs::temp_directory_path() /
                ("facet_" + m_tag + "_" + info->name() + "_" + std::to_string(getpid()));
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
        write_file(m_dir / "scene.xml", m_scene);
    }
    void TearDown() override {
        if (!HasFailure()) fs::remove_all(m_dir);
    }

    /// `facet <args>` in the test folder.
    CommandResult run(const std::string &args, const std::string &prefix = "") {
        return run_facet(m_dir, args, prefix);
    }

    /// Every file in the test folder (temporary files of interrupted or failed writes would
    /// show here).
    std::set<std::string> files() const {
        std::set<std::string> names;
        for (const auto &e : fs::directory_iterator(m_dir))
            names.insert(e.path().filename().string());
        return names;
    }

    std::string path(const std::string &name) const { return (m_dir / name).string(); }

    fs::path m_dir;

private:
    std::string m_tag, m_scene;
};

} // namespace facet::test
