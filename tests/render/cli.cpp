// The `facet` command as a user runs it: outputs, naming, -D, one-line errors, plugin listing,
// determinism across thread counts, Ctrl-C and atomic writes.

#include "test_util.h"

#include <facet/image.h>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <spawn.h>
#include <sstream>
#include <string>
#include <thread>
#include <unistd.h>
#include <vector>

extern char **environ;

namespace fs = std::filesystem;

namespace {

using facet::test::FACET;

/// A small scene: a diffuse sphere under a constant sky, seen by a perspective camera.
const char *TINY_SCENE = R"(<scene version="3.0.0">
    <default name="spp" value="4"/>
    <default name="res" value="32"/>
    <default name="sampler" value="independent"/>
    <integrator type="path">
        <integer name="max_depth" value="4"/>
    </integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world">
            <lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/>
        </transform>
        <sampler type="$sampler">
            <integer name="sample_count" value="$spp"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="$res"/>
            <integer name="height" value="$res"/>
        </film>
    </sensor>
    <emitter type="constant">
        <rgb name="radiance" value="1, 0.9, 0.8"/>
    </emitter>
    <shape type="sphere">
        <bsdf type="diffuse">
            <rgb name="reflectance" value="0.2, 0.5, 0.7"/>
        </bsdf>
    </shape>
</scene>
)";

using Result = facet::test::CommandResult;
using facet::test::lines;
using facet::test::read_file;
using facet::test::write_file;

class CliTest : public facet::test::ScratchFolderTest {
protected:
    CliTest() : ScratchFolderTest("cli", TINY_SCENE) {}

    /// Expects a failure reported as exactly one "facet: error: ..." line; returns that line.
    std::string expect_one_line_error(const std::string &args) {
        Result r = run(args);
        EXPECT_NE(r.code, 0) << args;
        auto err = lines(r.err);
        EXPECT_EQ(err.size(), 1u) << args << "\nstderr:\n" << r.err;
        if (err.empty()) return "";
        EXPECT_EQ(err[0].rfind("facet: error: ", 0), 0u) << err[0];
        return err[0];
    }
};

std::string attribute(const std::string &path, const std::string &name) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) return "<cannot open>";
    return in->spec().get_string_attribute(name, "<missing>");
}

TEST_F(CliTest, RenderWritesExrNextToTheScene) {
    Result r = run("render scene.xml");
    ASSERT_EQ(r.code, 0) << r.err;
    ASSERT_TRUE(fs::exists(m_dir / "scene.exr"));
    facet::Image img = facet::read_image((m_dir / "scene.exr").string());
    EXPECT_EQ(img.width, 32);
    EXPECT_EQ(img.height, 32);
    EXPECT_GE(img.channels, 3);
    // The summary names the size, spp, threads and time.
    EXPECT_NE(r.out.find("32x32"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("4 spp"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("thread"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(" s"), std::string::npos) << r.out;
    // Metadata: spp, render time, scene, seed.
    std::string exr = (m_dir / "scene.exr").string();
    EXPECT_EQ(attribute(exr, "facet:spp"), "4");
    EXPECT_EQ(attribute(exr, "facet:seed"), "0");
    EXPECT_NE(attribute(exr, "facet:scene").find("scene.xml"), std::string::npos);
    EXPECT_NE(attribute(exr, "facet:render_time"), "<missing>");
    EXPECT_EQ(files(), (std::set<std::string>{"scene.xml", "scene.exr"}));
}

TEST_F(CliTest, SceneFileAloneMeansRender) {
    fs::create_directories(m_dir / "sub");
    fs::rename(m_dir / "scene.xml", m_dir / "sub" / "box.xml");
    Result r = run("sub/box.xml -q");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(m_dir / "sub" / "box.exr")); // next to the scene, not in the cwd
    EXPECT_FALSE(fs::exists(m_dir / "box.exr"));
    EXPECT_TRUE(r.out.empty()) << "-q printed: " << r.out;
}

TEST_F(CliTest, OutputNames) {
    ASSERT_EQ(run("render scene.xml -q -o out").code, 0);
    EXPECT_TRUE(fs::exists(m_dir / "out.exr")); // the film's extension is added
    ASSERT_EQ(run("render scene.xml -q -o picture.png").code, 0);
    ASSERT_TRUE(fs::exists(m_dir / "picture.png"));
    auto in = OIIO::ImageInput::open((m_dir / "picture.png").string());
    ASSERT_TRUE(in);
    EXPECT_EQ(in->format_name(), std::string("png"));
    EXPECT_EQ(in->spec().width, 32);
    EXPECT_EQ(in->spec().format, OIIO::TypeDesc::UINT8);
    in->close();
    EXPECT_EQ(files(), (std::set<std::string>{"scene.xml", "out.exr", "picture.png"}));
}

TEST_F(CliTest, SeveralScenesRenderOneAfterTheOther) {
    // Mitsuba's `mitsuba a.xml b.xml`: each scene to its own image, the image it gets alone.
    std::string red = read_file(m_dir / "scene.xml");
    const std::string albedo = "0.2, 0.5, 0.7";
    red.replace(red.find(albedo), albedo.size(), "0.9, 0.1, 0.1");
    write_file(m_dir / "red.xml", red);
    Result r = run("render scene.xml red.xml -t 2");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("Rendering scene.xml"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("Rendering red.xml"), std::string::npos) << r.out;
    ASSERT_EQ(run("render red.xml -q -t 2 -o alone.exr").code, 0);
    const facet::Image both = facet::read_image(path("red.exr"));
    EXPECT_EQ(both.data, facet::read_image(path("alone.exr")).data);
    EXPECT_NE(both.data, facet::read_image(path("scene.exr")).data);
    // -o a folder takes each scene's name.
    fs::create_directories(m_dir / "out");
    fs::create_directories(m_dir / "seq");
    ASSERT_EQ(run("render scene.xml red.xml -q -o out/").code, 0);
    EXPECT_EQ(facet::read_image(path("out/red.exr")).data, both.data);
    EXPECT_TRUE(fs::exists(m_dir / "out" / "scene.exr"));
    // -o one file for several scenes is refused before anything renders.
    const std::string err = expect_one_line_error("render scene.xml red.xml -o one.exr");
    EXPECT_NE(err.find("-o must name a folder"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(m_dir / "one.exr"));
    // Two scenes of one name would write one image: refused before anything renders.
    fs::create_directories(m_dir / "other");
    write_file(m_dir / "other" / "scene.xml", red);
    fs::create_directories(m_dir / "same");
    std::string same = expect_one_line_error("render scene.xml red.xml other/scene.xml -o same/");
    EXPECT_NE(same.find("\"scene.xml\" and \"other/scene.xml\" would both write same/scene.*"),
              std::string::npos)
        << same;
    EXPECT_TRUE(fs::is_empty(m_dir / "same"));
    same = expect_one_line_error("render scene.xml ./scene.xml");
    EXPECT_NE(same.find("would both write"), std::string::npos) << same;
    // A missing scene is refused before anything renders; the first error while loading or
    // rendering ends the sequence, and the scenes before it keep their images.
    r = run("render scene.xml missing.xml red.xml -q -o seq/");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("\"missing.xml\" does not exist (nothing was rendered)"),
              std::string::npos)
        << r.err;
    EXPECT_TRUE(fs::is_empty(m_dir / "seq"));
    write_file(m_dir / "broken.xml", "<scene version=\"3.0.0\"><shape type=\"sphere\">");
    r = run("render scene.xml broken.xml red.xml -q -o seq/");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("broken.xml:1:"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::exists(m_dir / "seq" / "scene.exr"));
    EXPECT_FALSE(fs::exists(m_dir / "seq" / "red.exr"));
}

TEST_F(CliTest, DefineSetsSceneParameters) {
    Result r = run("render scene.xml -q -D res=16 -D spp=2 -o small.exr");
    ASSERT_EQ(r.code, 0) << r.err;
    facet::Image img = facet::read_image((m_dir / "small.exr").string());
    EXPECT_EQ(img.width, 16);
    EXPECT_EQ(img.height, 16);
    EXPECT_EQ(attribute((m_dir / "small.exr").string(), "facet:spp"), "2");
}

TEST_F(CliTest, ThreadsBelowOneBecomeOneWithAWarning) {
    Result r = run("render scene.xml -q -t 0 -o t0.exr");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(m_dir / "t0.exr"));
    EXPECT_NE(r.err.find("1 thread"), std::string::npos) << r.err;
}

TEST_F(CliTest, MissingSceneFileIsOneLineError) {
    std::string line = expect_one_line_error("render nosuch.xml");
    EXPECT_NE(line.find("nosuch.xml"), std::string::npos) << line;
}

TEST_F(CliTest, MalformedXmlNamesFileLineAndColumn) {
    write_file(m_dir / "bad.xml",
               "<scene version=\"3.0.0\">\n    <shape type=\"sphere\">\n</scene>\n");
    std::string line = expect_one_line_error("render bad.xml");
    EXPECT_TRUE(std::regex_search(line, std::regex(R"(bad\.xml:\d+:\d+)"))) << line;
    EXPECT_FALSE(fs::exists(m_dir / "bad.exr"));
}

TEST_F(CliTest, UnknownPluginListsTheKnownOnes) {
    std::string text = TINY_SCENE;
    text.replace(text.find("type=\"diffuse\""), 14, "type=\"difuse\"");
    write_file(m_dir / "typo.xml", text);
    std::string line = expect_one_line_error("render typo.xml");
    EXPECT_NE(line.find("difuse"), std::string::npos) << line;
    EXPECT_NE(line.find("diffuse"), std::string::npos) << line;
    EXPECT_TRUE(std::regex_search(line, std::regex(R"(typo\.xml:\d+:\d+)"))) << line;
}

TEST_F(CliTest, UnusedDefineIsAnError) {
    std::string line = expect_one_line_error("render scene.xml -D nosuchparam=3");
    EXPECT_NE(line.find("nosuchparam"), std::string::npos) << line;
    EXPECT_FALSE(fs::exists(m_dir / "scene.exr"));
    // --lenient makes it a warning.
    Result r = run("render scene.xml -q --lenient -D nosuchparam=3");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("nosuchparam"), std::string::npos) << r.err;
}

TEST_F(CliTest, MisspeltParameterIsAnError) {
    std::string text = TINY_SCENE;
    text.replace(text.find("<shape type=\"sphere\">"), 21,
                 "<shape type=\"sphere\">\n        <float name=\"radiuss\" value=\"2\"/>");
    write_file(m_dir / "param.xml", text);
    std::string line = expect_one_line_error("render param.xml");
    EXPECT_NE(line.find("radiuss"), std::string::npos) << line;
}

TEST_F(CliTest, DefineWithoutEqualsIsAnError) {
    std::string line = expect_one_line_error("render scene.xml -D spp");
    EXPECT_NE(line.find("key=value"), std::string::npos) << line;
    EXPECT_FALSE(fs::exists(m_dir / "scene.exr"));
}

TEST_F(CliTest, UnknownOptionIsAnError) {
    std::string line = expect_one_line_error("render scene.xml --no-such-option");
    EXPECT_NE(line.find("no-such-option"), std::string::npos) << line;
}

TEST_F(CliTest, PluginsListsEveryKind) {
    Result r = run("plugins");
    ASSERT_EQ(r.code, 0) << r.err;
    for (const char *name : {"diffuse", "path", "sphere", "perspective", "hdrfilm", "independent",
                             "gaussian", "area", "constant"})
        EXPECT_TRUE(
            std::regex_search(r.out, std::regex(std::string(R"((^|\n)\s+)") + name + R"(\s)")))
            << name << " missing from:\n"
            << r.out;
    EXPECT_NE(r.out.find("bsdfs"), std::string::npos);
    EXPECT_NE(r.out.find("integrators"), std::string::npos);

    Result bsdfs = run("plugins bsdf");
    ASSERT_EQ(bsdfs.code, 0) << bsdfs.err;
    EXPECT_NE(bsdfs.out.find("diffuse"), std::string::npos);
    EXPECT_EQ(bsdfs.out.find("perspective"), std::string::npos) << bsdfs.out;
    // A plugin that does not render in every mode says which it renders in (every built-in one
    // renders in all: the registry tests' plugin, exported with the plain macro, does not).
    Result integrators = run("plugins integrator");
    ASSERT_EQ(integrators.code, 0) << integrators.err;
    EXPECT_TRUE(std::regex_search(integrators.out, std::regex(R"(\n\s+depth\s[^\n(]*\n)")))
        << integrators.out;
    Result partial = run(std::string("plugins bsdf -a ") + FACET_TEST_PLUGIN_DIR);
    ASSERT_EQ(partial.code, 0) << partial.err;
    EXPECT_TRUE(std::regex_search(
        partial.out,
        std::regex(R"(\n\s+testgood\s[^\n]*\(only scalar_rgb, scalar_mono\)[^\n]*\n)")))
        << partial.out;
    EXPECT_TRUE(
        std::regex_search(bsdfs.out, std::regex(R"(\n\s+principled\s+[^\n]*'s principled\)\n)")))
        << bsdfs.out;
    EXPECT_TRUE(std::regex_search(
        bsdfs.out, std::regex(R"(\n\s+diffuse\s+Smooth diffuse \(Lambertian\) reflection\n)")))
        << bsdfs.out;
}

TEST_F(CliTest, PluginsPrintsOnePluginsTable) {
    Result r = run("plugins diffuse");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(std::regex_search(r.out, std::regex(R"(\|\s*Parameter\s*\|\s*Type\s*\|)")))
        << r.out;
    EXPECT_TRUE(std::regex_search(r.out, std::regex(R"(\|\s*reflectance\s*\|)"))) << r.out;
    EXPECT_NE(r.out.find("\nmodes: scalar_rgb, scalar_mono, scalar_spectral, "
                         "scalar_spectral_polarized\n"),
              std::string::npos)
        << r.out;

    std::string line = expect_one_line_error("plugins difuse");
    EXPECT_NE(line.find("diffuse"), std::string::npos) << line; // the suggestion
}

TEST_F(CliTest, SameImageForAnyThreadCount) {
    ASSERT_EQ(run("render scene.xml -q -D spp=8 -t 1 -o one.exr").code, 0);
    ASSERT_EQ(run("render scene.xml -q -D spp=8 -t 2 -o two.exr").code, 0);
    facet::Image a = facet::read_image((m_dir / "one.exr").string());
    facet::Image b = facet::read_image((m_dir / "two.exr").string());
    ASSERT_EQ(a.width, b.width);
    ASSERT_EQ(a.channels, b.channels);
    EXPECT_TRUE(a.data == b.data) << "-t 1 and -t 2 give different pixels";
    // A different seed gives a different image, so the comparison above means something.
    ASSERT_EQ(run("render scene.xml -q -D spp=8 -t 2 --seed 1 -o seed.exr").code, 0);
    facet::Image c = facet::read_image((m_dir / "seed.exr").string());
    EXPECT_FALSE(a.data == c.data);
}

TEST_F(CliTest, CropAndPassWriteTheDataWindowAndWhatAMergeNeeds) {
    Result r = run("render scene.xml -D spp=4 --crop 4 2 20 10 --pass 1 --passes 3 -o part.exr");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("16x8 pixels (crop 4 2 20 10 of 32x32)"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("part 1 of 3"), std::string::npos) << r.out;
    const std::string part = (m_dir / "part.exr").string();
    {
        auto in = OIIO::ImageInput::open(part);
        ASSERT_TRUE(in);
        const OIIO::ImageSpec &spec = in->spec();
        EXPECT_EQ(spec.x, 4);
        EXPECT_EQ(spec.y, 2);
        EXPECT_EQ(spec.width, 16);
        EXPECT_EQ(spec.height, 8);
        EXPECT_EQ(spec.full_x, 0);
        EXPECT_EQ(spec.full_y, 0);
        EXPECT_EQ(spec.full_width, 32);
        EXPECT_EQ(spec.full_height, 32);
    }
    EXPECT_EQ(attribute(part, "facet:spp"), "4");
    EXPECT_EQ(attribute(part, "facet:spp_total"), "12");
    EXPECT_EQ(attribute(part, "facet:sample_offset"), "4");
    EXPECT_EQ(attribute(part, "facet:pass_index"), "1");
    EXPECT_EQ(attribute(part, "facet:pass_count"), "3");
    EXPECT_EQ(attribute(part, "facet:crop"), "4 2 20 10");
    EXPECT_EQ(attribute(part, "facet:film_size"), "32 32");
    const std::string hash = attribute(part, "facet:scene_hash");
    EXPECT_EQ(hash.size(), 16u) << hash;

    // The other parts of the same render carry the same scene identity; another -D does not.
    ASSERT_EQ(run("render scene.xml -q -D spp=4 --pass 0 --passes 3 -o p0.exr").code, 0);
    EXPECT_EQ(attribute((m_dir / "p0.exr").string(), "facet:scene_hash"), hash);
    EXPECT_EQ(attribute((m_dir / "p0.exr").string(), "facet:crop"), "0 0 32 32");
    ASSERT_EQ(run("render scene.xml -q -D spp=5 --pass 0 --passes 3 -o p5.exr").code, 0);
    EXPECT_NE(attribute((m_dir / "p5.exr").string(), "facet:scene_hash"), hash);

    // The crop's pixels are those of the full image.
    ASSERT_EQ(run("render scene.xml -q -D spp=4 --pass 1 --passes 3 -o full.exr").code, 0);
    facet::Image crop = facet::read_image(part),
                 full = facet::read_image((m_dir / "full.exr").string());
    ASSERT_EQ(crop.width, 16);
    for (int y = 0; y < crop.height; ++y)
        for (int x = 0; x < crop.width; ++x)
            for (int c = 0; c < 3; ++c)
                ASSERT_EQ(crop.at(x, y, c), full.at(x + 4, y + 2, c)) << x << "," << y;
}

TEST_F(CliTest, SppIsTheNumberOfSamplesTaken) {
    // stratified takes a square number of samples: 10 become 16, in the banner and the EXR.
    Result r = run("render scene.xml -D sampler=stratified -D res=8 --spp 10 -o strat.exr");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("16 spp (the sampler rounds 10 up to 16)"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("10 spp"), std::string::npos) << r.out;
    EXPECT_EQ(attribute((m_dir / "strat.exr").string(), "facet:spp"), "16");
    // The same through the scene's sample_count.
    ASSERT_EQ(run("render scene.xml -q -D sampler=ldsampler -D res=8 -D spp=5 -o ld.exr").code, 0);
    EXPECT_EQ(attribute((m_dir / "ld.exr").string(), "facet:spp"), "8");
    // --spp 0 and negative counts: facet's own message, not the option parser's range text.
    for (const char *bad : {"0", "-3"}) {
        std::string line = expect_one_line_error(std::string("render scene.xml --spp ") + bad);
        EXPECT_NE(line.find("at least 1"), std::string::npos) << line;
        EXPECT_EQ(line.find("[0 - "), std::string::npos) << line;
    }
}

TEST_F(CliTest, SummaryTimesAndVersion) {
    Result r = run("render scene.xml -D res=8 -o t.exr");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(std::regex_search(
        r.out, std::regex(R"(Times: load [0-9.]+ s \(acceleration structure [0-9.]+ s\), render )"
                          R"([0-9.]+ s)")))
        << r.out;
    EXPECT_EQ(r.out.find("writing the image"), std::string::npos) << r.out; // -v only
    r = run("render scene.xml -v -D res=8 -o t.exr");
    ASSERT_EQ(r.code, 0) << r.err;
    for (const char *phase : {"scene file and plugins", "acceleration structure", "sampling",
                              "developing the film", "writing the image", "samples/s"})
        EXPECT_NE(r.out.find(phase), std::string::npos) << phase << "\n" << r.out;
    r = run("--version");
    EXPECT_EQ(r.code, 0);
    EXPECT_TRUE(std::regex_search(r.out, std::regex(R"(^facet [0-9]+\.[0-9]+\.[0-9]+ \(Embree )")))
        << r.out;
}

TEST_F(CliTest, BadCropOrPassIsOneLineError) {
    std::string line = expect_one_line_error("render scene.xml --crop 0 0 40 10");
    EXPECT_NE(line.find("32x32"), std::string::npos) << line;
    line = expect_one_line_error("render scene.xml --crop 8 0 8 10");
    EXPECT_NE(line.find("exclusive"), std::string::npos) << line;
    expect_one_line_error("render scene.xml --crop 1 2 3");
    line = expect_one_line_error("render scene.xml --pass 2 --passes 2");
    EXPECT_NE(line.find("0 <= I < N"), std::string::npos) << line;
    line = expect_one_line_error("render scene.xml --pass 1");
    EXPECT_NE(line.find("--passes"), std::string::npos) << line;
}

TEST_F(CliTest, ModeScalarRgbIsTheDefault) {
    ASSERT_EQ(run("render scene.xml -q -o plain.exr").code, 0);
    Result r = run("render scene.xml -q -m scalar_rgb -o moded.exr");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err, "");
    EXPECT_TRUE(facet::test::identical(facet::read_image(path("plain.exr")),
                                       facet::read_image(path("moded.exr"))));
    EXPECT_EQ(attribute(path("plain.exr"), "facet:mode"), "scalar_rgb");
    EXPECT_EQ(attribute(path("moded.exr"), "facet:mode"), "scalar_rgb");
    ASSERT_EQ(run("render scene.xml -q --mode scalar_rgb -o long_name.exr").code, 0);
    EXPECT_EQ(attribute(path("long_name.exr"), "facet:mode"), "scalar_rgb");
}

TEST_F(CliTest, ModeLlvmRgbRendersAsScalarRgbWithOneNote) {
    Result plain = run("render scene.xml -o plain.exr");
    ASSERT_EQ(plain.code, 0) << plain.err;
    // As Mitsuba users type it: `mitsuba -m llvm_rgb scene.xml`. One line more than without -m.
    Result r = run("-m llvm_rgb scene.xml -o vectorised.exr");
    ASSERT_EQ(r.code, 0) << r.err;
    std::vector<std::string> expected = lines(plain.err);
    expected.insert(expected.begin(), "[I] mode \"llvm_rgb\": facet renders it as scalar_rgb "
                                      "(facet has no vectorised or differentiable modes)");
    EXPECT_EQ(lines(r.err), expected);
    EXPECT_TRUE(facet::test::identical(facet::read_image(path("plain.exr")),
                                       facet::read_image(path("vectorised.exr"))));
    EXPECT_EQ(attribute(path("vectorised.exr"), "facet:mode"), "scalar_rgb");
    // -q: only warnings and errors.
    r = run("render scene.xml -q -m cuda_ad_rgb -o quiet.exr");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err, "");
}

TEST_F(CliTest, ModeFacetDoesNotRenderIsRefusedBeforeTheSceneLoads) {
    // The scene file does not exist: the mode is refused first.
    std::string line = expect_one_line_error("render missing.xml -m scalar_rgb_polarized");
    EXPECT_EQ(line, "facet: error: facet does not render the mode \"scalar_rgb_polarized\"; the "
                    "modes it renders: scalar_rgb, scalar_mono, scalar_spectral, "
                    "scalar_spectral_polarized");
    line = expect_one_line_error("render scene.xml more.xml --mode llvm_ad_mono_polarized");
    EXPECT_NE(line.find("(nor scalar_mono_polarized, its scalar form)"), std::string::npos) << line;
    EXPECT_EQ(files(), std::set<std::string>{"scene.xml"});
}

TEST_F(CliTest, UnknownModeListsTheModes) {
    std::string line = expect_one_line_error("render scene.xml -m foo");
    EXPECT_EQ(
        line,
        "facet: error: unknown mode \"foo\"; the modes facet renders: scalar_rgb, scalar_mono, "
        "scalar_spectral, scalar_spectral_polarized");
    line = expect_one_line_error("render scene.xml -m scalar_rbg");
    EXPECT_NE(line.find("did you mean \"scalar_rgb\"?"), std::string::npos) << line;
    EXPECT_EQ(files(), std::set<std::string>{"scene.xml"});
    // --help names the modes.
    Result r = run("render --help");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(
        std::regex_search(r.out, std::regex(R"(-m,--mode MODE\s+Colour mode[^\n]*scalar_rgb)")))
        << r.out;
}

TEST_F(CliTest, InfoPrintsTheResolvedMode) {
    Result r = run("info scene.xml");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("\nmode: scalar_rgb\n"), std::string::npos) << r.out;
    r = run("info scene.xml -m llvm_ad_rgb");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("\nmode: scalar_rgb\n"), std::string::npos) << r.out;
    EXPECT_EQ(lines(r.err).size(), 1u) << r.err;
    EXPECT_NE(r.err.find("facet renders it as scalar_rgb"), std::string::npos) << r.err;
    r = run("info scene.xml -m cuda_mono");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("\nmode: scalar_mono\n"), std::string::npos) << r.out;
    r = run("info scene.xml -m llvm_spectral");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("\nmode: scalar_spectral\n"), std::string::npos) << r.out;
    r = run("info scene.xml -m scalar_spectral_polarized");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("\nmode: scalar_spectral_polarized\n"), std::string::npos) << r.out;
    const std::string line = expect_one_line_error("info scene.xml -m scalar_rgb_polarized");
    EXPECT_NE(line.find("facet does not render the mode \"scalar_rgb_polarized\""),
              std::string::npos)
        << line;
}

/// Starts `facet render scene.xml -D res=<res> -D spp=<spp> -t 2 -o <image>`, waits until it
/// renders, lets it run for `run_for`, sends `sig` and waits for it to exit. Returns the exit
/// status, the seconds from the signal to the exit and stderr.
struct Stopped {
    int status = 0;
    double stop_seconds = 0.0;
    std::string err;
};

Stopped render_and_stop(const fs::path &dir, const std::string &image, int sig,
                        std::chrono::milliseconds run_for) {
    fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
    std::string scene = (dir / "scene.xml").string();
    std::vector<std::string> args = {FACET,         "render", scene, "-D", "res=192", "-D",
                                     "spp=1000000", "-t",     "2",   "-o", image};
    std::vector<char *> argv;
    for (auto &a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    pid_t pid = 0;
    Stopped result;
    if (posix_spawn(&pid, FACET.c_str(), &actions, nullptr, argv.data(), environ) != 0) {
        ADD_FAILURE() << "cannot start facet";
        return result;
    }
    posix_spawn_file_actions_destroy(&actions);

    using clock = std::chrono::steady_clock;
    // Wait until the render has started (the scene is loaded and the handler installed).
    auto start = clock::now();
    while (read_file(out).find("Rendering") == std::string::npos &&
           clock::now() - start < std::chrono::seconds(120))
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    std::this_thread::sleep_for(run_for);
    EXPECT_EQ(kill(pid, sig), 0);

    auto sent = clock::now();
    while (waitpid(pid, &result.status, WNOHANG) == 0) {
        if (clock::now() - sent > std::chrono::seconds(60)) {
            kill(pid, SIGKILL);
            waitpid(pid, &result.status, 0);
            ADD_FAILURE() << "facet did not stop within 60 s of the signal";
            break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    result.stop_seconds = std::chrono::duration<double>(clock::now() - sent).count();
    result.err = read_file(err);
    fs::remove(out);
    fs::remove(err);
    return result;
}

/// Every pixel of a render of the tiny scene is lit (the sphere or the sky behind it).
size_t black_pixels(const facet::Image &img) {
    size_t black = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) black += img.at(x, y, 2) > 0.f ? 0 : 1;
    return black;
}

TEST_F(CliTest, InterruptWritesTheWholeImageAtTheSppReached) {
    // A million samples per pixel: far too many to finish. Ctrl-C keeps the passes done.
    const std::string image = (m_dir / "long.exr").string();
    Stopped r = render_and_stop(m_dir, image, SIGINT, std::chrono::milliseconds(2500));
    ASSERT_TRUE(WIFEXITED(r.status)) << "facet died from a signal";
    EXPECT_EQ(WEXITSTATUS(r.status), 130);
    EXPECT_LT(r.stop_seconds, 1.0) << "the stop took too long";
    EXPECT_NE(r.err.find("stopping"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("partial"), std::string::npos) << r.err;

    ASSERT_TRUE(fs::exists(image));
    facet::Image img = facet::read_image(image);
    EXPECT_EQ(img.width, 192);
    EXPECT_EQ(black_pixels(img), 0u) << "a stopped render covers the whole image";
    const int spp = std::stoi(attribute(image, "facet:spp"));
    EXPECT_GE(spp, 1);
    EXPECT_LT(spp, 1000000);
    EXPECT_EQ(attribute(image, "facet:spp_target"), "1000000");
    EXPECT_EQ(files(), (std::set<std::string>{"scene.xml", "long.exr"}));
}

TEST_F(CliTest, TerminateWritesTheWholeImageToo) {
    // `timeout 10 facet render ...` sends SIGTERM.
    const std::string image = (m_dir / "term.exr").string();
    Stopped r = render_and_stop(m_dir, image, SIGTERM, std::chrono::milliseconds(2500));
    ASSERT_TRUE(WIFEXITED(r.status)) << "facet died from a signal";
    EXPECT_EQ(WEXITSTATUS(r.status), 128 + SIGTERM);
    EXPECT_LT(r.stop_seconds, 1.0) << "the stop took too long";
    EXPECT_NE(r.err.find("terminated"), std::string::npos) << r.err;
    ASSERT_TRUE(fs::exists(image));
    EXPECT_EQ(black_pixels(facet::read_image(image)), 0u);
    EXPECT_GE(std::stoi(attribute(image, "facet:spp")), 1);
}

} // namespace
