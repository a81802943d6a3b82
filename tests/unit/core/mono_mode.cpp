// The mono colour mode at the sources of colour: every rgb, spectrum, spectrum plugin, image
// texel and vertex colour a scene gives becomes its luminance in every channel when the scene is
// loaded with LoadOptions::mode = "scalar_mono", and stays as it is in scalar_rgb. (The images
// are checked against the peer's mono renders in the compat suite.)

#include "texture_lookup.h"

#include <facet/image.h>
#include <facet/mode.h>
#include <facet/properties.h>
#include <facet/scene.h>
#include <facet/spectrum.h>
#include <facet/texture.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <unistd.h>

using namespace facet;
namespace fs = std::filesystem;

namespace {

std::shared_ptr<Texture> load_texture(const std::string &xml, const std::string &mode,
                                      const std::string &dir = "") {
    LoadOptions opts;
    opts.mode = mode;
    if (!dir.empty()) opts.search_path.push_back(dir);
    auto texture = std::dynamic_pointer_cast<Texture>(load_string(xml, opts));
    EXPECT_TRUE(texture) << xml;
    return texture;
}

/// A checkerboard whose two colours are `color0` (an XML value element named color0) and grey;
/// uv (0.1, 0.1) is in a color0 square.
std::string checkerboard(const std::string &color0) {
    return "<texture version=\"3.0.0\" type=\"checkerboard\">" + color0 +
           "<float name=\"color1\" value=\"0.25\"/></texture>";
}

Color3f grey(float v) { return Color3f(v); }

} // namespace

TEST(MonoMode, RgbBecomesItsLuminance) {
    const std::string xml = checkerboard("<rgb name=\"color0\" value=\"0.8, 0.4, 0.1\"/>");
    const Color3f c(0.8f, 0.4f, 0.1f);
    EXPECT_EQ(load_texture(xml, "scalar_rgb")->eval(at_uv(0.1f, 0.1f)), c);
    const auto mono = load_texture(xml, "scalar_mono");
    EXPECT_EQ(mono->eval(at_uv(0.1f, 0.1f)), grey(c.luminance()));
    EXPECT_EQ(mono->eval(at_uv(0.6f, 0.1f)), grey(0.25f)); // a number stays that number
    // A vectorised name of the mode loads the same.
    EXPECT_EQ(load_texture(xml, "llvm_ad_mono")->eval(at_uv(0.1f, 0.1f)), grey(c.luminance()));
}

TEST(MonoMode, SpectraBecomeTheLuminanceOfTheirRgb) {
    const std::string pairs = "400:0.1, 500:0.7, 600:0.3, 700:0.9";
    const Color3f rgb = spectrum_to_rgb(parse_spectrum_pairs(pairs), SpectrumKind::Reflectance);
    ASSERT_NE(rgb.r, rgb.g);
    const std::string xml = checkerboard("<spectrum name=\"color0\" value=\"" + pairs + "\"/>");
    EXPECT_EQ(load_texture(xml, "scalar_rgb")->eval(at_uv(0.1f, 0.1f)), rgb);
    EXPECT_EQ(load_texture(xml, "scalar_mono")->eval(at_uv(0.1f, 0.1f)), grey(rgb.luminance()));

    // A spectrum plugin (here an srgb colour) likewise.
    const std::string plugin = checkerboard(
        "<spectrum type=\"srgb\" name=\"color0\"><rgb name=\"color\" value=\"0.2, 0.9, 0.5\"/>"
        "</spectrum>");
    const Color3f in_rgb = load_texture(plugin, "scalar_rgb")->eval(at_uv(0.1f, 0.1f));
    ASSERT_NE(in_rgb.r, in_rgb.g);
    EXPECT_EQ(load_texture(plugin, "scalar_mono")->eval(at_uv(0.1f, 0.1f)),
              grey(in_rgb.luminance()));
}

TEST(MonoMode, ImageTexelsBecomeTheirLuminanceUnlessRaw) {
    const fs::path dir = fs::temp_directory_path() / ("facet_mono_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    Image img(2, 2, 3);
    img.channel_names = {"R", "G", "B"};
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 2; ++x) {
            img.at(x, y, 0) = 0.1f + 0.3f * float(x);
            img.at(x, y, 1) = 0.7f - 0.2f * float(y);
            img.at(x, y, 2) = 0.05f + 0.4f * float(x * y);
        }
    write_image((dir / "colours.exr").string(), img);
    const auto bitmap = [&](const std::string &mode, bool raw) {
        return load_texture("<texture version=\"3.0.0\" type=\"bitmap\">"
                            "<string name=\"filename\" value=\"colours.exr\"/>"
                            "<boolean name=\"raw\" value=\"" +
                                std::string(raw ? "true" : "false") + "\"/></texture>",
                            mode, dir.string());
    };
    const auto rgb = bitmap("scalar_rgb", false), mono = bitmap("scalar_mono", false);
    const auto raw = bitmap("scalar_mono", true);
    for (float u : {0.1f, 0.3f, 0.55f, 0.9f})
        for (float v : {0.2f, 0.5f, 0.8f}) {
            const Color3f c = rgb->eval(at_uv(u, v));
            ASSERT_NE(c.r, c.g);
            const Color3f m = mono->eval(at_uv(u, v));
            EXPECT_EQ(m.r, m.g);
            EXPECT_EQ(m.r, m.b);
            EXPECT_NEAR(m.r, c.luminance(), 1e-6f) << u << " " << v;
            EXPECT_EQ(mono->eval_1(at_uv(u, v)), rgb->eval_1(at_uv(u, v)));
            // A raw image is data (a normal map): its channels stay.
            EXPECT_EQ(raw->eval(at_uv(u, v)), c);
        }
    EXPECT_NEAR(mono->mean().r, rgb->mean().luminance(), 1e-6f);
    EXPECT_EQ(mono->mean().r, mono->mean().b);
    std::error_code ec;
    fs::remove_all(dir, ec);
}

TEST(MonoMode, TheSceneAndItsPropertiesKnowTheMode) {
    const std::string xml = "<scene version=\"3.0.0\"><shape type=\"sphere\"/></scene>";
    LoadOptions opts;
    EXPECT_EQ(std::dynamic_pointer_cast<Scene>(load_string(xml, opts))->mode(), ColourMode::RGB);
    opts.mode = "scalar_mono";
    EXPECT_EQ(std::dynamic_pointer_cast<Scene>(load_string(xml, opts))->mode(), ColourMode::Mono);
    opts.mode = "scalar_spectral";
    EXPECT_EQ(std::dynamic_pointer_cast<Scene>(load_string(xml, opts))->mode(),
              ColourMode::Spectral);
    opts.mode = "scalar_spectral_polarized";
    EXPECT_EQ(std::dynamic_pointer_cast<Scene>(load_string(xml, opts))->mode(),
              ColourMode::SpectralPolarized);
    opts.mode = "scalar_rgb_polarized";
    EXPECT_THROW(load_string(xml, opts), Error);

    // A colour read straight from Properties follows the mode; so do defaults.
    Properties props("test");
    props.set_color("c", Color3f(1.f, 0.f, 0.f));
    EXPECT_EQ(props.get_color("c"), Color3f(1.f, 0.f, 0.f));
    props.set_mode(ColourMode::Mono);
    EXPECT_EQ(props.get_color("c"), grey(Color3f(1.f, 0.f, 0.f).luminance()));
    EXPECT_EQ(props.get_color("absent", Color3f(0.f, 1.f, 0.f)),
              grey(Color3f(0.f, 1.f, 0.f).luminance()));
    EXPECT_EQ(props.texture("absent", Color3f(0.f, 0.f, 1.f))->mean(),
              grey(Color3f(0.f, 0.f, 1.f).luminance()));
}
