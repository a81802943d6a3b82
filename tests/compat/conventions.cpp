// Peer-style scenes for three Mitsuba 3 conventions that a self-consistent renderer can miss: each
// test writes a Mitsuba 3 scene (and its inputs), renders it with `facet render` and checks the
// image with `facet compare --mean-sigmas 4`, the compat rule, against a reference written here.
// There is no Mitsuba image of these scenes: each scene is built so that Mitsuba's convention
// fixes its image exactly (a constant), and the reference is that value.
//  - An RGBA bitmap: Mitsuba drops alpha and keeps the stored colour (no premultiplication).
//  - A conductor's inline eta and k spectra: weighted by D65 like every non-emitter spectrum
//    (Mitsuba 3.8 renders the reflectance below at normal incidence).
//  - Ray offsets: a spawned ray leaves the surface by (1 + max |p_i|) · 1500 · 2^-24 along the
//    geometric normal, which steps over a sheet closer than that.
// The reference variance is zero (the rule's floor applies); the test spp keeps the number of
// samples small enough that the floor also covers the last digit of a reference given to three
// decimals, and far too small to hide the differences these scenes are about.

#include <facet/image.h>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <unistd.h>

namespace fs = std::filesystem;
using facet::Image;

namespace {

const std::string FACET = FACET_BINARY_DIR "/bin/facet";

struct Verdict {
    bool pass = false;
    double agreeing = -1.0, sigmas = -1.0;
    std::string out;
};

class Conventions : public ::testing::Test {
protected:
    void SetUp() override {
        const auto *info = ::testing::UnitTest::GetInstance()->current_test_info();
        m_dir = fs::temp_directory_path() /
                (std::string("facet_conventions_") + info->name() + "_" + std::to_string(getpid()));
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    void TearDown() override {
        if (!HasFailure()) fs::remove_all(m_dir);
    }

    std::string path(const std::string &name) const { return (m_dir / name).string(); }

    void write_text(const std::string &name, const std::string &text) const {
        std::ofstream(path(name)) << text;
    }

    static std::string run(const std::string &cmd) {
        std::string out_path = fs::temp_directory_path() /
                               ("facet_conventions_out_" + std::to_string(getpid()) + ".txt");
        int status = std::system((cmd + " > '" + out_path + "' 2>&1 < /dev/null").c_str());
        std::ifstream in(out_path);
        std::stringstream ss;
        ss << in.rdbuf();
        fs::remove(out_path);
        if (!WIFEXITED(status)) ADD_FAILURE() << cmd << " did not exit";
        return ss.str();
    }

    /// Renders `scene` at `spp` and compares the image with the constant `rgb`.
    Verdict render_and_compare(const std::string &scene, int spp, const std::array<float, 3> &rgb,
                               int width, int height) {
        const std::string image = path("render.exr");
        std::string log = run("'" + FACET + "' render '" + path(scene) +
                              "' -D spp=" + std::to_string(spp) + " -q -o '" + image + "'");
        EXPECT_TRUE(fs::exists(image)) << log;
        Image mean(width, height, 3), var(width, height, 3);
        mean.channel_names = var.channel_names = {"R", "G", "B"};
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
                for (int c = 0; c < 3; ++c) mean.at(x, y, c) = rgb[size_t(c)];
        facet::write_image(path("ref_mean.exr"), mean);
        facet::write_image(path("ref_var.exr"), var);
        Verdict v;
        v.out = run("'" + FACET + "' compare '" + image + "' '" + path("ref_mean.exr") + "' '" +
                    path("ref_var.exr") + "' --spp " + std::to_string(spp) + " --mean-sigmas 4");
        std::smatch m;
        static const std::regex verdict(R"((PASS|FAIL) agreeing=([0-9.]+)%)");
        static const std::regex sigmas(R"(([0-9.]+|nan|inf) sigma at most)");
        if (std::regex_search(v.out, m, verdict)) {
            v.pass = m[1] == "PASS";
            v.agreeing = std::stod(m[2]);
        } else {
            ADD_FAILURE() << "no verdict in:\n" << v.out;
        }
        if (std::regex_search(v.out, m, sigmas)) v.sigmas = std::stod(m[1]);
        return v;
    }

    fs::path m_dir;
};

/// An orthographic camera looking down -z at the square [-1, 1]² of the plane z = 0 (from z = 2),
/// a box filter, float32 output.
std::string camera(int width, int height, const std::string &extra = "") {
    return R"(
    <sensor type="orthographic">
        <transform name="to_world">
            <lookat origin="0, 0, 2" target="0, 0, 0" up="0, 1, 0"/>
        </transform>)" +
           extra + R"(
        <sampler type="independent">
            <integer name="sample_count" value="$spp"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value=")" +
           std::to_string(width) + R"("/>
            <integer name="height" value=")" +
           std::to_string(height) + R"("/>
            <string name="component_format" value="float32"/>
            <rfilter type="box"/>
        </film>
    </sensor>)";
}

double srgb_to_linear(double v) {
    return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

} // namespace

TEST_F(Conventions, RgbaBitmapKeepsItsStoredColour) {
    // One colour, (200, 120, 40), under alpha falling from 255 to 0 across the texture: Mitsuba
    // reads the colour as stored and drops alpha, so the diffuse square (lit by a white
    // environment; every sample is its reflectance) is that colour's sRGB decoding everywhere.
    const int tw = 32, th = 8;
    std::vector<unsigned char> texels(size_t(tw) * th * 4);
    for (int y = 0; y < th; ++y)
        for (int x = 0; x < tw; ++x) {
            unsigned char *t = &texels[(size_t(y) * tw + size_t(x)) * 4];
            t[0] = 200;
            t[1] = 120;
            t[2] = 40;
            t[3] = (unsigned char)(255 - (255 * x) / (tw - 1));
        }
    auto out = OIIO::ImageOutput::create(path("leaf.png"));
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(tw, th, 4, OIIO::TypeDesc::UINT8);
    spec.alpha_channel = 3;
    spec.attribute("oiio:UnassociatedAlpha", 1); // store the bytes as given
    ASSERT_TRUE(out->open(path("leaf.png"), spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, texels.data()));
    out->close();

    const int w = 16, h = 16;
    write_text("scene.xml", R"(<scene version="3.0.0">
    <default name="spp" value="4"/>
    <integrator type="direct">
        <integer name="emitter_samples" value="0"/>
        <integer name="bsdf_samples" value="1"/>
    </integrator>)" + camera(w, h) +
                                R"(
    <emitter type="constant">
        <rgb name="radiance" value="1"/>
    </emitter>
    <shape type="rectangle">
        <transform name="to_world">
            <scale value="1.5"/>
        </transform>
        <bsdf type="diffuse">
            <texture type="bitmap" name="reflectance">
                <string name="filename" value="leaf.png"/>
                <string name="filter_type" value="nearest"/>
            </texture>
        </bsdf>
    </shape>
</scene>
)");
    // The texture is stored in half precision (`format` auto, as Mitsuba): the reference is
    // given to float precision, the floor of the rule covers the rounding (< 2.5e-4).
    const std::array<float, 3> colour = {float(srgb_to_linear(200 / 255.0)),
                                         float(srgb_to_linear(120 / 255.0)),
                                         float(srgb_to_linear(40 / 255.0))};
    Verdict v = render_and_compare("scene.xml", 4, colour, w, h);
    EXPECT_TRUE(v.pass) << v.out;
    EXPECT_EQ(v.agreeing, 100.0) << v.out;
}

TEST_F(Conventions, ConductorInlineSpectraAreWeightedByD65) {
    // An orthographic camera sees the conductor at normal incidence, mirroring a white
    // environment: every pixel is the normal-incidence reflectance, (0.986, 0.708, 0.404) in
    // Mitsuba 3.8 (given to three decimals; without the D65 weighting it is
    // (0.974, 0.703, 0.372)).
    const int w = 8, h = 8;
    write_text("scene.xml", R"(<scene version="3.0.0">
    <default name="spp" value="16"/>
    <integrator type="path">
        <integer name="max_depth" value="3"/>
    </integrator>)" + camera(w, h) +
                                R"(
    <emitter type="constant">
        <rgb name="radiance" value="1"/>
    </emitter>
    <shape type="rectangle">
        <transform name="to_world">
            <scale value="1.5"/>
        </transform>
        <bsdf type="conductor">
            <spectrum name="eta" value="300:1.8, 400:1.65, 500:0.9, 600:0.2, 700:0.16, 800:0.18"/>
            <spectrum name="k" value="300:1.92, 400:1.95, 500:1.95, 600:2.97, 700:3.8, 800:5.12"/>
        </bsdf>
    </shape>
</scene>
)");
    Verdict v = render_and_compare("scene.xml", 16, {0.986f, 0.708f, 0.404f}, w, h);
    EXPECT_TRUE(v.pass) << v.out;
    EXPECT_EQ(v.agreeing, 100.0) << v.out;
}

TEST_F(Conventions, SpawnedRaysStepOverASheetCloserThanTheOffset) {
    // A thin glass pane 4e-5 above a dark floor (a pane lying on a table): the ray the pane
    // transmits starts (1 + max |p_i|) · 8.9e-5 >= 8.9e-5 below the pane in Mitsuba, below the
    // floor too, and reaches the white environment under it. Everything the camera sees is then
    // the environment, reflected or transmitted by the pane: white, exactly.
    const int w = 16, h = 16;
    write_text("scene.xml", R"(<scene version="3.0.0">
    <default name="spp" value="4"/>
    <integrator type="path">
        <integer name="max_depth" value="8"/>
    </integrator>)" + camera(w, h) +
                                R"(
    <emitter type="constant">
        <rgb name="radiance" value="1"/>
    </emitter>
    <shape type="rectangle">
        <transform name="to_world">
            <scale value="1.5"/>
            <translate z="4e-5"/>
        </transform>
        <bsdf type="thindielectric"/>
    </shape>
    <shape type="rectangle">
        <transform name="to_world">
            <scale value="1.5"/>
        </transform>
        <bsdf type="diffuse">
            <rgb name="reflectance" value="0.1"/>
        </bsdf>
    </shape>
</scene>
)");
    Verdict v = render_and_compare("scene.xml", 4, {1.f, 1.f, 1.f}, w, h);
    EXPECT_TRUE(v.pass) << v.out;
    EXPECT_EQ(v.agreeing, 100.0) << v.out;
}
