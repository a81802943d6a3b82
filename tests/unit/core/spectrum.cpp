// Spectrum parsing and conversion to RGB (CIE 1931, D65, the conventions of Mitsuba's RGB
// variants).
#include <facet/logger.h>
#include <facet/spectrum.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>

using namespace facet;

namespace {

SpectrumData flat(double v, double lo = 360, double hi = 830) {
    SpectrumData s;
    s.uniform = false;
    s.wavelengths = {lo, hi};
    s.values = {v, v};
    return s;
}

void expect_color(const Color3f &c, const Color3f &ref, float eps) {
    EXPECT_NEAR(c.r, ref.r, eps) << c << " vs " << ref;
    EXPECT_NEAR(c.g, ref.g, eps) << c << " vs " << ref;
    EXPECT_NEAR(c.b, ref.b, eps) << c << " vs " << ref;
}

std::string error_of(const std::function<void()> &f) {
    try {
        f();
    } catch (const Error &e) {
        return e.what();
    }
    return "(no error)";
}

const Color3f QuirkWhite(1.204794f, 0.948291f, 0.908916f);

/// A temporary file removed at the end of the test.
struct TempFile {
    std::string path;
    explicit TempFile(const std::string &name, const std::string &content) {
        path = (std::filesystem::temp_directory_path() /
                (name + "_" + std::to_string(::getpid()) + ".spd"))
                   .string();
        std::ofstream(path) << content;
    }
    ~TempFile() { std::remove(path.c_str()); }
};

} // namespace

/// What a flat spectrum of 1 weighted by D65 comes to: Mitsuba scales D65 to luminance 1 against
/// the continuous curves (1 / 98.9974), which over its 1000-step quadrature gives 0.99889.
constexpr float D65White = 0.99889f;

TEST(Spectrum, ConstantReflectanceIsGrey) {
    // D65 is the sRGB white point: a flat reflectance is grey.
    for (float v : {0.5f, 1.f, 0.2f})
        expect_color(spectrum_to_rgb(flat(v), SpectrumKind::Reflectance), Color3f(v * D65White),
                     2e-4f * v);
}

TEST(Spectrum, UniformEmissionQuirk) {
    // A uniform emitter spectrum c becomes c * xyz_to_srgb(1, 1, 1).
    expect_color(spectrum_to_rgb(SpectrumData::constant(1.0), SpectrumKind::Emission), QuirkWhite,
                 1e-4f);
    expect_color(spectrum_to_rgb(SpectrumData::constant(2.5), SpectrumKind::Emission),
                 QuirkWhite * 2.5f, 2.5e-4f);
    expect_color(xyz_to_srgb(Color3f(1.f)), QuirkWhite, 1e-5f);
}

TEST(Spectrum, UniformNonEmissionStaysValue) {
    expect_color(spectrum_to_rgb(SpectrumData::constant(0.3), SpectrumKind::Reflectance),
                 Color3f(0.3f), 0.f);
    expect_color(spectrum_to_rgb(SpectrumData::constant(7.0), SpectrumKind::Unbounded),
                 Color3f(7.f), 0.f);
}

TEST(Spectrum, EmissionIsNotWeightedByD65) {
    // An equal-energy emitter given as pairs goes through the integration: its XYZ is about
    // (1, 1, 1) (the normalisation divides by the y-bar integral), so its RGB is the quirk white.
    expect_color(spectrum_to_rgb(flat(1.0), SpectrumKind::Emission), QuirkWhite, 1e-3f);
    // So are a conductor preset's tabulated eta and k.
    expect_color(spectrum_to_rgb(flat(4.0), SpectrumKind::Measured), QuirkWhite * 4.f, 4e-3f);
}

TEST(Spectrum, UnboundedSpectraOfNonEmittersAreWeightedByD65) {
    // An eta or k given as pairs is weighted by D65 like a reflectance (a flat spectrum is grey),
    // but not clamped to 1.
    expect_color(spectrum_to_rgb(flat(4.0), SpectrumKind::Unbounded), Color3f(4.f * D65White),
                 8e-4f);
    SpectrumData ramp = parse_spectrum_pairs("400:1, 700:3");
    Color3f weighted = spectrum_to_rgb(ramp, SpectrumKind::Unbounded);
    Color3f unweighted = spectrum_to_rgb(ramp, SpectrumKind::Measured);
    EXPECT_GT(weighted.r, 1.f);
    EXPECT_GT(std::abs(weighted.b - unweighted.b), 0.05f);
    // Weighted the same way as a reflectance, only without the clamp.
    SpectrumData low = parse_spectrum_pairs("400:0.1, 700:0.9");
    expect_color(spectrum_to_rgb(low, SpectrumKind::Unbounded),
                 spectrum_to_rgb(low, SpectrumKind::Reflectance), 0.f);
}

TEST(Spectrum, Clamping) {
    // Reflectances clamp to [0, 1]; emission and unbounded only to >= 0.
    expect_color(spectrum_to_rgb(flat(3.0), SpectrumKind::Reflectance), Color3f(1.f), 0.f);
    EXPECT_GT(spectrum_to_rgb(flat(3.0), SpectrumKind::Emission).r, 3.f);
    // A narrow green line has negative red in sRGB: clamped to zero.
    SpectrumData green = parse_spectrum_pairs("500:0, 510:10, 520:0");
    for (auto kind : {SpectrumKind::Reflectance, SpectrumKind::Emission, SpectrumKind::Unbounded,
                      SpectrumKind::Measured}) {
        Color3f c = spectrum_to_rgb(green, kind);
        EXPECT_EQ(c.r, 0.f);
        EXPECT_GT(c.g, 0.f);
    }
}

TEST(Spectrum, RedIsRed) {
    Color3f c = spectrum_to_rgb(parse_spectrum_pairs("360:0, 600:0, 610:1, 830:1"),
                                SpectrumKind::Reflectance);
    EXPECT_GT(c.r, 0.5f);
    EXPECT_LT(c.g, 0.1f);
    EXPECT_LT(c.b, 0.1f);
}

TEST(Spectrum, CieTableInterpolation) {
    // Table values: y-bar(555) = 1, x-bar(600) = 1.0622, z-bar(450) = 1.77211.
    EXPECT_NEAR(cie1931_xyz(555).g, 1.0f, 1e-6f);
    EXPECT_NEAR(cie1931_xyz(600).r, 1.0622f, 1e-5f);
    EXPECT_NEAR(cie1931_xyz(450).b, 1.77211f, 1e-5f);
    Color3f a = cie1931_xyz(550), b = cie1931_xyz(555), mid = cie1931_xyz(552.5);
    expect_color(mid, (a + b) * 0.5f, 1e-6f);
    expect_color(cie1931_xyz(300), Color3f(0.f), 0.f);
    expect_color(cie1931_xyz(900), Color3f(0.f), 0.f);
    // D65 keeps its shape: 560 nm is the reference wavelength of the relative table (100).
    EXPECT_NEAR(cie_d65(460) / cie_d65(560), 117.812 / 100.0, 1e-4);
}

TEST(Spectrum, EvalInterpolatesPairs) {
    SpectrumData s = parse_spectrum_pairs("400:0.5, 500:0.7");
    ASSERT_FALSE(s.uniform);
    ASSERT_EQ(s.wavelengths.size(), 2u);
    EXPECT_DOUBLE_EQ(s.eval(400), 0.5);
    EXPECT_DOUBLE_EQ(s.eval(450), 0.6);
    EXPECT_DOUBLE_EQ(s.eval(500), 0.7);
    EXPECT_DOUBLE_EQ(s.eval(399), 0.0);
    EXPECT_DOUBLE_EQ(s.eval(501), 0.0);
    SpectrumData u = parse_spectrum_pairs(" 0.25 ");
    EXPECT_TRUE(u.uniform);
    EXPECT_DOUBLE_EQ(u.value, 0.25);
    EXPECT_DOUBLE_EQ(u.eval(123), 0.25);
}

TEST(Spectrum, ParseErrors) {
    EXPECT_NE(error_of([] { parse_spectrum_pairs("500:0.5, 400:0.7"); }).find("ascending"),
              std::string::npos);
    EXPECT_NE(error_of([] { parse_spectrum_pairs("abc"); }).find("abc"), std::string::npos);
    EXPECT_NE(error_of([] { parse_spectrum_pairs("400:x"); }).find("\"x\""), std::string::npos);
    EXPECT_NE(error_of([] { parse_spectrum_pairs("400:0.5,"); }).find("pair"), std::string::npos);
    EXPECT_NE(error_of([] { parse_spectrum_pairs("400:0.5:3"); }).find("pair"), std::string::npos);
    EXPECT_NE(error_of([] { parse_spectrum_pairs(""); }).find("empty"), std::string::npos);
    EXPECT_NE(error_of([] { parse_spectrum_pairs("0.5, 0.6"); }), "(no error)");
}

TEST(Spectrum, ReadSpdFile) {
    TempFile f("facet_spectrum_test",
               "# measured\n400 0.5\n\n  450\t0.6  # inline comment\n500 0.7\n");
    SpectrumData s = read_spd_file(f.path);
    ASSERT_FALSE(s.uniform);
    EXPECT_EQ(s.wavelengths, (std::vector<double>{400, 450, 500}));
    EXPECT_EQ(s.values, (std::vector<double>{0.5, 0.6, 0.7}));
}

TEST(Spectrum, ReadSpdFileErrorsNameTheFile) {
    std::string missing = "/nonexistent/facet_missing.spd";
    std::string msg = error_of([&] { read_spd_file(missing); });
    EXPECT_NE(msg.find(missing), std::string::npos) << msg;

    TempFile bad("facet_spectrum_bad", "400 0.5\n450 oops\n");
    msg = error_of([&] { read_spd_file(bad.path); });
    EXPECT_NE(msg.find(bad.path), std::string::npos) << msg;
    EXPECT_NE(msg.find("line 2"), std::string::npos) << msg;

    TempFile order("facet_spectrum_order", "500 0.5\n400 0.6\n");
    msg = error_of([&] { read_spd_file(order.path); });
    EXPECT_NE(msg.find(order.path), std::string::npos) << msg;
    EXPECT_NE(msg.find("ascending"), std::string::npos) << msg;

    TempFile empty("facet_spectrum_empty", "# nothing\n");
    msg = error_of([&] { read_spd_file(empty.path); });
    EXPECT_NE(msg.find("no data"), std::string::npos) << msg;
}
