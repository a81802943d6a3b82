// Hostile scenes through the `facet` command: each must end with exit code 1 and one located
// "facet: error: scene.xml:line:col: ..." line, quickly and without large allocations (it used
// to be a segfault, an Embree abort, gigabytes of memory or an unexplained std::bad_alloc).

#include "test_util.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

using facet::test::FACET;
using facet::test::read_file;

struct Case {
    const char *name;
    std::string xml;          ///< the whole scene
    const char *message;      ///< part of the error line
    int line;                 ///< of the location in scene.xml
    std::string defines = ""; ///< extra command-line options
};

std::string repeat(const std::string &s, int n) {
    std::string out;
    for (int i = 0; i < n; ++i) out += s;
    return out;
}

/// A small scene; `sensor_ops` place the camera (line 3), `film` adds to the film (line 4),
/// `body` follows from line 5 on.
std::string scene(const std::string &body,
                  const std::string &sensor_ops =
                      "<lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/>",
                  const std::string &film = "") {
    return "<scene version=\"3.0.0\">\n<sensor type=\"perspective\">\n<transform "
           "name=\"to_world\">" +
           sensor_ops +
           "</transform>\n<film type=\"hdrfilm\"><integer name=\"width\" value=\"16\"/>"
           "<integer name=\"height\" value=\"16\"/>" +
           film +
           "</film><sampler type=\"independent\"><integer name=\"sample_count\" "
           "value=\"4\"/></sampler></sensor>\n" +
           body + "\n<emitter type=\"constant\"/></scene>\n";
}

std::vector<Case> cases() {
    const std::string group =
        "<shape type=\"shapegroup\" id=\"g\"><shape type=\"sphere\"/></shape>";
    return {
        {"deep_nesting",
         scene("<shape type=\"sphere\">" + repeat("<bsdf type=\"twosided\">", 5000) +
               "<bsdf type=\"diffuse\"/>" + repeat("</bsdf>", 5000) + "</shape>"),
         "nested more than 256 objects deep", 5},
        {"twosided_26",
         scene("<shape type=\"sphere\">" + repeat("<bsdf type=\"twosided\">", 26) +
               "<bsdf type=\"diffuse\"/>" + repeat("</bsdf>", 26) + "</shape>"),
         "components, more than the 1024", 5},
        {"camera_scale_0", scene("<shape type=\"sphere\"/>", "<scale value=\"0\"/>"),
         "to_world is singular", 3},
        {"camera_far_away",
         scene("<shape type=\"sphere\"/>",
               "<lookat origin=\"1e30, 0, 0\" target=\"0, 0, 0\" up=\"0, 1, 0\"/>"),
         "to_world has an entry", 3},
        {"nested_instance",
         scene(group + "\n<shape type=\"shapegroup\" id=\"g2\"><shape type=\"instance\">"
                       "<ref id=\"g\"/></shape></shape>\n<shape type=\"instance\"><ref "
                       "id=\"g2\"/></shape>"),
         "cannot contain an instance", 6},
        {"instance_scale_0",
         scene(group + "\n<shape type=\"instance\"><ref id=\"g\"/><transform "
                       "name=\"to_world\"><scale value=\"0\"/></transform></shape>"),
         "instance: to_world is singular", 6},
        {"shape_far_away",
         scene("<shape type=\"sphere\"><transform name=\"to_world\"><translate "
               "x=\"1e30\"/></transform></shape>"),
         "bounding box reaches", 5},
        {"gaussian_huge",
         scene("", "<translate z=\"5\"/>",
               "<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"1e30\"/></rfilter>"),
         "stddev must be a number of pixels in [0.00390625, 16]", 4},
        {"nan_reflectance",
         scene("<shape type=\"sphere\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" "
               "value=\"nan\"/></bsdf></shape>"),
         "contains NaN", 5},
        {"inf_radiance",
         scene("<shape type=\"sphere\"><emitter type=\"area\"><rgb name=\"radiance\" "
               "value=\"inf\"/></emitter></shape>"),
         "contains an infinite", 5},
        {"nan_from_define",
         scene("<shape type=\"sphere\"><bsdf type=\"diffuse\"><float name=\"reflectance\" "
               "value=\"$r\"/></bsdf></shape>"),
         "contains NaN", 5, "-D r=nan"},
    };
}

} // namespace

TEST(HostileCli, EveryClassEndsInOneLocatedErrorLine) {
    fs::path dir = fs::temp_directory_path() / ("facet_hostile_cli_" + std::to_string(getpid()));
    fs::create_directories(dir);
    for (const Case &c : cases()) {
        SCOPED_TRACE(c.name);
        std::ofstream(dir / "scene.xml") << c.xml;
        std::string cmd = "cd '" + dir.string() + "' && '" + FACET +
                          "' render -q -t 2 -o out.exr scene.xml " + c.defines +
                          " > out.txt 2> err.txt < /dev/null";
        auto start = std::chrono::steady_clock::now();
        int status = std::system(cmd.c_str());
        double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        ASSERT_TRUE(WIFEXITED(status)) << "killed by a signal";
        EXPECT_EQ(WEXITSTATUS(status), 1);
        std::string err = read_file(dir / "err.txt");
        EXPECT_EQ(err.find("facet: error: scene.xml:" + std::to_string(c.line) + ":"), 0u) << err;
        EXPECT_NE(err.find(c.message), std::string::npos) << err;
        EXPECT_EQ(err.find('\n'), err.size() - 1) << "more than one line: " << err;
        EXPECT_FALSE(fs::exists(dir / "out.exr"));
        // Generous for a loaded machine: the failures come while loading (about 2 s idle).
        EXPECT_LT(seconds, 30.0);
        struct rusage usage;
        getrusage(RUSAGE_CHILDREN, &usage);
        EXPECT_LT(usage.ru_maxrss, 2L * 1024 * 1024) << "kB of peak memory";
    }
    fs::remove_all(dir);
}

TEST(HostileCli, FilmTooLarge) {
    fs::path dir = fs::temp_directory_path() / ("facet_hostile_film_" + std::to_string(getpid()));
    fs::create_directories(dir);
    std::ofstream(dir / "scene.xml")
        << "<scene version=\"3.0.0\">\n<sensor type=\"perspective\">\n<film type=\"hdrfilm\">"
           "<integer name=\"width\" value=\"1000000\"/><integer name=\"height\" "
           "value=\"1000000\"/></film></sensor></scene>\n";
    std::string cmd = "cd '" + dir.string() + "' && '" + FACET +
                      "' render -q scene.xml -o out.exr > out.txt 2> err.txt < /dev/null";
    int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 1);
    std::string err = read_file(dir / "err.txt");
    // It was "facet: error: std::bad_alloc".
    EXPECT_EQ(err.find("facet: error: scene.xml:3:"), 0u) << err;
    EXPECT_NE(err.find("1000000x1000000 pixels, more than"), std::string::npos) << err;
    fs::remove_all(dir);
}

// Errors that come from the command line rather than the scene name the option they come from,
// also for a scene name the file system refuses (it was an uncaught "File name too long").
TEST(HostileCli, OptionErrorsNameTheirOption) {
    fs::path dir = fs::temp_directory_path() / ("facet_hostile_opts_" + std::to_string(getpid()));
    fs::create_directories(dir);
    std::ofstream(dir / "scene.xml") << scene("<shape type=\"sphere\"/>");
    const struct {
        std::string args, message;
    } cases[] = {
        {"scene.xml --passes 600000000", "the sampler's sample_count 4, --passes 600000000: "},
        {"scene.xml --spp 4096 --passes 3000000 --pass 0",
         "--spp 4096, --passes 3000000: 3000000 passes of 4096 samples per pixel are too many"},
        {std::string(300, 'n') + ".xml", "File name too long"},
    };
    for (const auto &c : cases) {
        SCOPED_TRACE(c.args);
        std::string cmd = "cd '" + dir.string() + "' && '" + FACET + "' render -q -o out.exr " +
                          c.args + " > out.txt 2> err.txt < /dev/null";
        int status = std::system(cmd.c_str());
        ASSERT_TRUE(WIFEXITED(status)) << "killed by a signal";
        EXPECT_EQ(WEXITSTATUS(status), 1);
        std::string err = read_file(dir / "err.txt");
        EXPECT_EQ(err.find("facet: error: "), 0u) << err;
        EXPECT_NE(err.find(c.message), std::string::npos) << err;
        EXPECT_EQ(err.find('\n'), err.size() - 1) << "more than one line: " << err;
        EXPECT_FALSE(fs::exists(dir / "out.exr"));
    }
    fs::remove_all(dir);
}
