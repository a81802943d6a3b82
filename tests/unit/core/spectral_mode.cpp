// The spectral colour mode: the wavelengths a path carries (their density, strata and weights),
// the development of a path's radiance to the film's RGB, the spectra the colours of a scene
// become (rgb, numbers, spectra, emitters' colours, measured conductors), the plugins that
// refuse the mode, and small renders whose expected image is known: a white sphere and a
// coloured plane in a uniform environment (a constant emitter or an environment map). The
// images of the feature scenes are checked against the peer's spectral renders in the compat
// suite (labels compat-spectral).

#include <facet/conductor_data.h>
#include <facet/fresnel.h>
#include <facet/image.h>
#include <facet/logger.h>
#include <facet/mode.h>
#include <facet/mueller.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/spectral_upsampling.h>
#include <facet/spectrum.h>
#include <facet/texture.h>
#include <facet/xml.h>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <unistd.h>
#include <vector>

using namespace facet;
namespace fs = std::filesystem;

namespace {

/// ∫ f over [360, 830] nm by the spectral mode's estimator: the mean over `n` stratified
/// uniform numbers of the four lanes' f(λ)·w (the wavelengths of n paths).
template <typename F> Color3f estimate(F f, int n) {
    Color3f sum(0.f);
    for (int k = 0; k < n; ++k) {
        const auto [lambda, weight] = sample_wavelengths((float(k) + 0.5f) / float(n));
        sum += f(lambda) * weight;
    }
    return sum / float(n);
}

/// The film's RGB of a spectrum `f` (a function of the wavelengths), by the render loop's own
/// development averaged over `n` stratified paths.
template <typename F> Color3f develop(F f, int n = 3000) {
    Color3f sum(0.f);
    for (int k = 0; k < n; ++k) {
        const auto [lambda, weight] = sample_wavelengths((float(k) + 0.5f) / float(n));
        sum += spectral_to_srgb(f(lambda), lambda, weight);
    }
    return sum / float(n);
}

Color3f d65(const Wavelengths &l) { return cie_d65(l); }

/// a and b agree in every channel (the four wavelengths' values, or RGB and its copy of G).
void expect_near(const Color3f &a, const Color3f &b, float tol, const std::string &what) {
    for (int c = 0; c < Color3f::Channels; ++c)
        EXPECT_NEAR(a[c], b[c], tol) << what << " channel " << c;
}

std::shared_ptr<Texture> load_texture(const std::string &xml) {
    LoadOptions opts;
    opts.mode = "scalar_spectral";
    auto texture = std::dynamic_pointer_cast<Texture>(load_string(xml, opts));
    EXPECT_TRUE(texture) << xml;
    return texture;
}

/// A checkerboard whose color0 is the XML element `color0`: eval() at uv (0.1, 0.1) reads it.
std::shared_ptr<Texture> color0_of(const std::string &color0) {
    return load_texture("<texture version=\"3.0.0\" type=\"checkerboard\">" + color0 +
                        "<float name=\"color1\" value=\"0.25\"/></texture>");
}

Color3f eval_at(const Texture &t, const Wavelengths &lambda) {
    SurfaceInteraction si;
    si.uv = Point2f(0.1f, 0.1f);
    si.wavelengths = lambda;
    return t.eval(si);
}

/// The mean of the RGB channels of a render of `xml` in `mode`.
Color3f render_mean(const std::string &xml, const std::string &mode, const fs::path &dir = {}) {
    LoadOptions opts;
    opts.mode = mode;
    if (!dir.empty()) opts.search_path.push_back(dir.string());
    auto scene = std::dynamic_pointer_cast<Scene>(load_string(xml, opts));
    RenderOptions ro;
    ro.progress = false;
    const Image image = render(*scene, *scene->sensors().at(0), ro).image;
    Color3f sum(0.f);
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            sum += Color3f(image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2));
    return sum / float(image.width * image.height);
}

/// A 16x16 render (orthographic from z = 5 towards -z, box filter, `spp`) of `content` lit by
/// `emitter`, under `integrator`.
std::string
furnace(const std::string &emitter, const std::string &content,
        const std::string &integrator =
            R"(<integrator type="path"><integer name="max_depth" value="4"/></integrator>)",
        int spp = 256) {
    return fmt::format(R"(<scene version="3.0.0">
        {}
        <sensor type="orthographic">
            <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
            <sampler type="independent"><integer name="sample_count" value="{}"/></sampler>
            <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/>
                <rfilter type="box"/></film>
        </sensor>
        {}
        {}
    </scene>)",
                       integrator, spp, emitter, content);
}

} // namespace

TEST(SpectralMode, AValueHoldsFourChannelsAndAnRgbValueCopiesGreenIntoTheFourth) {
    // Three numbers (rgb, mono) put a copy of g in w; channel-wise arithmetic keeps it a copy, so
    // the four-channel checks see only real values.
    const Color3f a(0.5f, 2.f, -1.f), b(4.f, 0.25f, 3.f);
    EXPECT_EQ(a.w, a.g);
    for (const Color3f &c : {a + b, a - b, a * b, a / b, a * 3.f, a / 3.f})
        EXPECT_EQ(c.w, c.g) << c;
    EXPECT_EQ(a.max(), 2.f);
    EXPECT_FALSE(Color3f(0.f, 0.f, 0.f, 1.f).is_black());
    EXPECT_FALSE(Color3f(1.f, 1.f, 1.f, Infinity).is_finite());
    EXPECT_EQ(Color3f(0.f, 1.f, 0.f, 5.f).max(), 5.f);
    // map() calls f for each of four distinct channels, takes the copy for an rgb value.
    int calls = 0;
    auto twice = [&calls](float v) {
        ++calls;
        return 2.f * v;
    };
    EXPECT_EQ(map(Color3f(1.f, 2.f, 3.f, 4.f), twice), Color3f(2.f, 4.f, 6.f, 8.f));
    EXPECT_EQ(calls, 4);
    EXPECT_EQ(map(Color3f(1.f, 2.f, 3.f), twice), Color3f(2.f, 4.f, 6.f));
    EXPECT_EQ(calls, 7);
    EXPECT_EQ(map(Color3f(1.f, 2.f, 3.f, 4.f), Color3f(1.f, 2.f, 3.f), std::plus<float>()),
              Color3f(2.f, 4.f, 6.f, 6.f));
}

TEST(SpectralMode, PerWavelengthFormulasFillTheFourthChannel) {
    // A conductor with four different indices: each channel is the scalar formula's, the
    // reflection matrix's lanes too.
    const Color3f eta(0.2f, 0.9f, 1.5f, 0.4f), k(3.f, 2.5f, 1.9f, 2.8f);
    const Color3f F = fresnel_conductor(0.6f, eta, k);
    const Mueller M = mueller::specular_reflection(0.6f, eta, k);
    for (int c = 0; c < Color3f::Channels; ++c) {
        EXPECT_FLOAT_EQ(F[c], fresnel_conductor(0.6f, eta[c], k[c])) << "channel " << c;
        EXPECT_FLOAT_EQ(M.m[0][0][c], F[c]) << "channel " << c;
    }
    // D65 and an upsampled colour at each wavelength; the four-lane curve is the one-lane one,
    // to the bit, for curves small, steep (|x| > 1, x² overflowing) and constant (±infinity).
    const Wavelengths l(420.f, 530.f, 640.f, 700.f);
    std::vector<SigmoidPolynomial> curves = {
        SigmoidPolynomial{1e-4f, -0.1f, 24.f}, SigmoidPolynomial{1e18f, 1e18f, 0.f},
        SigmoidPolynomial{0.f, 0.f, 0.f}, SigmoidPolynomial{0.f, 0.f, Infinity},
        SigmoidPolynomial{0.f, 0.f, -Infinity}};
    for (int i = 0; i < 12 * 12 * 12; ++i)
        curves.push_back(rgb_to_sigmoid(
            Color3f(float(i % 12) / 11.f, float(i / 12 % 12) / 11.f, float(i / 144) / 11.f)));
    int differ = 0;
    for (const SigmoidPolynomial &p : curves)
        for (float shift = 0.f; shift < 100.f; shift += 7.f) {
            const Wavelengths at = l - Color3f(shift);
            const Color3f lanes = p(at);
            for (int c = 0; c < Color3f::Channels; ++c) differ += lanes[c] != p(at[c]);
        }
    EXPECT_EQ(differ, 0);
    const Color3f ends = SigmoidPolynomial{0.f, 0.f, Infinity}(l);
    EXPECT_EQ(ends, Color3f(1.f));
    const RGBSpectrum s = RGBSpectrum::from_rgb(Color3f(0.8f, 0.3f, 0.1f), SpectrumKind::Emission);
    const Color3f v = s.eval(l);
    for (int c = 0; c < Color3f::Channels; ++c) {
        EXPECT_FLOAT_EQ(cie_d65(l)[c], float(cie_d65(double(l[c])))) << "channel " << c;
        EXPECT_FLOAT_EQ(v[c], s.poly(l[c]) * s.scale * float(cie_d65(double(l[c]))))
            << "channel " << c;
    }
}

TEST(SpectralMode, TheWavelengthDensityIsNormalisedOnTheVisibleRange) {
    // The trapezoid rule over 1 nm steps.
    double sum = 0.0;
    for (int l = 360; l < 830; ++l)
        sum += 0.5 * (pdf_wavelength(float(l)) + pdf_wavelength(l + 1.f));
    EXPECT_NEAR(sum, 1.0, 1e-4);
    EXPECT_EQ(pdf_wavelength(359.f), 0.f);
    EXPECT_EQ(pdf_wavelength(831.f), 0.f);
    // It peaks at 538 nm.
    EXPECT_GT(pdf_wavelength(538.f), pdf_wavelength(500.f));
    EXPECT_GT(pdf_wavelength(538.f), pdf_wavelength(600.f));
}

TEST(SpectralMode, FourStratifiedWavelengthsWithWeightsOneOverTheDensity) {
    // The density's distribution function, by quadrature.
    auto cdf = [](float lambda) {
        double sum = 0.0;
        const int n = 4000;
        for (int i = 0; i < n; ++i) {
            const double l = 360.0 + (lambda - 360.0) * (i + 0.5) / n;
            sum += pdf_wavelength(float(l)) * (lambda - 360.0) / n;
        }
        return sum;
    };
    for (float u : {0.f, 0.1f, 0.25f, 0.3333f, 0.5f, 0.9f, 0.99999f}) {
        const auto [lambda, weight] = sample_wavelengths(u);
        for (int i = 0; i < Color3f::Channels; ++i) {
            EXPECT_GE(lambda[i], 360.f);
            EXPECT_LE(lambda[i], 830.f);
            EXPECT_FLOAT_EQ(weight[i], 1.f / pdf_wavelength(lambda[i]));
            // Lane i sits at u + i/4 (modulo 1) of the distribution function.
            double expected = std::fmod(double(u) + i / 4.0, 1.0);
            EXPECT_NEAR(cdf(lambda[i]), expected, 2e-4) << "u " << u << " lane " << i;
        }
    }
    // The estimator of ∫ 1 dλ over the range is the range's length: each lane's (on its grid
    // of n shifted points, 0.2 % off at the steep ends of 1/pdf) and the path's mean of them.
    const Color3f length = estimate([](const Wavelengths &) { return Color3f(1.f); }, 2000);
    expect_near(length, Color3f(470.f), 1.f, "range");
    EXPECT_NEAR(length.mean(), 470.f, 0.05f);
}

TEST(SpectralMode, DevelopmentGivesD65WhiteAndTheEqualEnergyWhite) {
    // D65 (as the spectral mode scales it) develops to RGB white, a flat unit spectrum to the
    // equal-energy white xyz_to_srgb(1, 1, 1): the conventions of the rgb mode's conversions.
    expect_near(develop(d65), Color3f(1.f), 3e-3f, "D65");
    expect_near(develop([](const Wavelengths &) { return Color3f(1.f); }),
                xyz_to_srgb(Color3f(1.f)), 3e-3f, "flat");
    // A spectrum nonzero in one lane only: the development is linear in each lane.
    const auto [lambda, weight] = sample_wavelengths(0.4f);
    for (int lane = 0; lane < Color3f::Channels; ++lane) {
        Color3f only(0.f);
        only[lane] = 1.f;
        const Color3f one = spectral_to_srgb(only, lambda, weight);
        const Color3f xyz =
            cie1931_xyz(lambda[lane]) * (weight[lane] / (4.f * 106.7502593994140625f));
        expect_near(one, xyz_to_srgb(xyz), 1e-5f, fmt::format("lane {} alone", lane));
    }
}

TEST(SpectralMode, ColoursComeBackThroughTheirSpectra) {
    // A reflectance under D65 and an emitter's colour develop back to their RGB (the
    // upsampling's round trip, within 1e-3 of a white; the estimator adds a little).
    for (const Color3f c : {Color3f(0.8f, 0.3f, 0.1f), Color3f(0.1f, 0.6f, 0.9f),
                            Color3f(0.5f, 0.5f, 0.45f), Color3f(0.05f, 0.05f, 0.05f)}) {
        const RGBSpectrum s = RGBSpectrum::from_rgb(c, SpectrumKind::Reflectance);
        EXPECT_FALSE(s.illuminant);
        expect_near(develop([&](const Wavelengths &l) { return s.eval(l) * d65(l); }), c, 4e-3f,
                    fmt::format("reflectance ({}, {}, {})", c.r, c.g, c.b));
    }
    for (const Color3f c :
         {Color3f(6.f, 5.5f, 5.f), Color3f(0.35f, 0.4f, 0.5f), Color3f(25.f, 2.f, 0.5f)}) {
        const RGBSpectrum s = RGBSpectrum::from_rgb(c, SpectrumKind::Emission);
        EXPECT_TRUE(s.illuminant);
        EXPECT_FLOAT_EQ(s.scale, 2.f * c.max());
        const Color3f back = develop([&](const Wavelengths &l) { return s.eval(l); });
        expect_near(back / c.max(), c / c.max(), 4e-3f,
                    fmt::format("emission ({}, {}, {})", c.r, c.g, c.b));
    }
    // Black is black in every form.
    const Wavelengths l(450.f, 550.f, 650.f, 500.f);
    EXPECT_EQ(RGBSpectrum::from_rgb(Color3f(0.f), SpectrumKind::Emission).eval(l), Color3f(0.f));
    EXPECT_EQ(RGBSpectrum::from_rgb(Color3f(0.f), SpectrumKind::Reflectance).eval(l), Color3f(0.f));
}

TEST(SpectralMode, SceneColoursBecomeSpectraEvaluatedAtTheWavelengths) {
    const Wavelengths l(420.f, 530.f, 640.f, 700.f);
    // An rgb: its upsampled curve at each wavelength.
    const Color3f c(0.8f, 0.3f, 0.1f);
    const auto rgb = color0_of("<rgb name=\"color0\" value=\"0.8, 0.3, 0.1\"/>");
    const SigmoidPolynomial s = rgb_to_sigmoid(c);
    EXPECT_EQ(eval_at(*rgb, l), Color3f(s(l.r), s(l.g), s(l.b), s(l.w)));
    EXPECT_NE(eval_at(*rgb, l), eval_at(*rgb, Wavelengths(600.f, 600.f, 600.f)));
    // A number and a grey: flat.
    EXPECT_EQ(eval_at(*color0_of("<float name=\"color0\" value=\"0.4\"/>"), l), Color3f(0.4f));
    EXPECT_EQ(eval_at(*color0_of("<rgb name=\"color0\" value=\"0.4\"/>"), l), Color3f(0.4f));
    // Spectra: linear between their pairs, 0 outside them, a uniform value flat.
    const auto pairs = color0_of("<spectrum name=\"color0\" value=\"400:0.1, 500:0.7, 600:0.3\"/>");
    const Color3f v = eval_at(*pairs, Wavelengths(450.f, 550.f, 700.f, 425.f));
    EXPECT_NEAR(v.r, 0.4f, 1e-6f);
    EXPECT_NEAR(v.g, 0.5f, 1e-6f);
    EXPECT_EQ(v.b, 0.f);
    EXPECT_NEAR(v.w, 0.25f, 1e-6f);
    EXPECT_EQ(eval_at(*color0_of("<spectrum name=\"color0\" value=\"0.6\"/>"), l), Color3f(0.6f));
    // Spectrum plugins per wavelength: d65 is D65, a blackbody Planck's law.
    const auto d65_plugin = color0_of("<spectrum name=\"color0\" type=\"d65\"/>");
    expect_near(eval_at(*d65_plugin, l), d65(l), 1e-6f, "d65");
    const auto planck =
        color0_of("<spectrum name=\"color0\" type=\"blackbody\"><float name=\"temperature\" "
                  "value=\"3000\"/></spectrum>");
    const double lm = 530e-9, h = 6.62607015e-34, cl = 2.99792458e8, k = 1.380649e-23;
    const double expected =
        1e-9 * 2 * h * cl * cl / (std::pow(lm, 5) * std::expm1(h * cl / (lm * k * 3000)));
    EXPECT_NEAR(eval_at(*planck, l).g / expected, 1.0, 1e-4);
}

TEST(SpectralMode, ConductorPresetsUseTheMeasuredDataPerWavelength) {
    const auto [eta, k] = conductor_eta_k_spectra("Au");
    // The BSDF's own textures are private: check the data read_conductor_ior() hands out.
    Properties props("conductor");
    props.set_mode(ColourMode::Spectral);
    props.set_string("material", "Au");
    const ConductorIOR ior = read_conductor_ior(props);
    const Wavelengths l(450.f, 550.f, 650.f, 500.f);
    const Color3f e = eval_at(*ior.eta, l), kk = eval_at(*ior.k, l);
    for (int i = 0; i < Color3f::Channels; ++i) {
        EXPECT_FLOAT_EQ(e[i], float(eta.eval(l[i])));
        EXPECT_FLOAT_EQ(kk[i], float(k.eval(l[i])));
    }
    // Gold: η well below 1 in the red, above 1 in the blue.
    EXPECT_LT(e.b, 0.5f);
    EXPECT_GT(e.r, 1.f);
}

/// The mean of each channel of a render of `xml` in `mode`, by channel name.
std::map<std::string, double> channel_means(const std::string &xml, const std::string &mode) {
    LoadOptions opts;
    opts.mode = mode;
    auto scene = std::dynamic_pointer_cast<Scene>(load_string(xml, opts));
    RenderOptions ro;
    ro.progress = false;
    const Image image = render(*scene, *scene->sensors().at(0), ro).image;
    std::map<std::string, double> means;
    for (int c = 0; c < image.channels; ++c) {
        double sum = 0.0;
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x) sum += image.at(x, y, c);
        means[image.channel_names.at(size_t(c))] = sum / double(image.width * image.height);
    }
    return means;
}

/// A diffuse plane of reflectance `rgb` 5 units away (furnace()'s view), under a white sky and
/// `integrator`.
std::string plane_view(const std::string &integrator, const std::string &rgb, int spp) {
    return furnace(
        R"(<emitter type="constant"><rgb name="radiance" value="1"/></emitter>)",
        fmt::format(R"(<shape type="rectangle"><transform name="to_world"><scale value="10"/>
                       </transform><bsdf type="diffuse"><rgb name="reflectance" value="{}"/></bsdf></shape>)",
                    rgb),
        integrator, spp);
}

TEST(SpectralMode, DepthAovAndMomentRenderInTheSpectralModes) {
    // depth: the distance is a flat spectrum developed like radiance (as Mitsuba's), i.e. the
    // distance times the flat spectrum's development (the equal-energy white).
    const Color3f flat = develop([](const Wavelengths &) { return Color3f(1.f); });
    for (const char *mode : {"scalar_spectral", "scalar_spectral_polarized"}) {
        auto depth = channel_means(plane_view("<integrator type=\"depth\"/>", "0.5", 64), mode);
        EXPECT_NEAR(depth["R"] / 5.0, flat.r, 0.01 * flat.r) << mode;
        EXPECT_NEAR(depth["G"] / 5.0, flat.g, 0.01 * flat.g) << mode;
        EXPECT_NEAR(depth["B"] / 5.0, flat.b, 0.01 * flat.b) << mode;
    }
    // aov: the depth channel raw; the albedo (a reflectance curve at the path's wavelengths)
    // developed, i.e. the curve's development under a flat spectrum, not under D65.
    const Color3f rho(0.7f, 0.35f, 0.1f);
    const RGBSpectrum curve = RGBSpectrum::from_rgb(rho, SpectrumKind::Reflectance);
    const Color3f albedo = develop([&](const Wavelengths &l) { return curve.eval(l); });
    auto aov = channel_means(plane_view(R"(<integrator type="aov">
            <string name="aovs" value="a:albedo, d:depth"/><integrator type="path"/>
        </integrator>)",
                                        "0.7, 0.35, 0.1", 64),
                             "scalar_spectral");
    EXPECT_NEAR(aov["d"], 5.0, 1e-5);
    EXPECT_NEAR(aov["a.R"], albedo.r, 0.01 * albedo.r);
    EXPECT_NEAR(aov["a.G"], albedo.g, 0.01 * albedo.g);
    EXPECT_NEAR(aov["a.B"], albedo.b, 0.01 * albedo.b);
    // ... which differs from the rgb mode's albedo by more than that tolerance in some channel.
    EXPECT_GT((albedo - rho).max(), 0.02f * rho.max()) << albedo;
    // moment: the XYZ channels are the samples' spectral XYZ, whose mean is the image's XYZ;
    // their second moments are at least their squared means.
    auto moment = channel_means(plane_view(R"(<integrator type="moment">
            <integrator name="p" type="path"/></integrator>)",
                                           "0.7, 0.35, 0.1", 64),
                                "scalar_spectral");
    const Color3f xyz =
        srgb_to_xyz(Color3f(float(moment["R"]), float(moment["G"]), float(moment["B"])));
    EXPECT_NEAR(moment["p.X"], xyz.r, 1e-4 * xyz.r);
    EXPECT_NEAR(moment["p.Y"], xyz.g, 1e-4 * xyz.g);
    EXPECT_NEAR(moment["p.Z"], xyz.b, 1e-4 * xyz.b);
    for (const char *c : {"X", "Y", "Z"}) {
        const double m1 = moment[std::string("p.") + c], m2 = moment[std::string("m2_p.") + c];
        EXPECT_GT(m2, m1 * m1) << c;
    }
    // The plane under a unit white sky is its colour (rgb 0.7, 0.35, 0.1 within the noise).
    EXPECT_NEAR(moment["R"], 0.7, 0.02);
    EXPECT_NEAR(moment["B"], 0.1, 0.01);
}

TEST(SpectralMode, AWhiteSphereInAUniformSkyIsTheSky) {
    // Every pixel sees the sky, or a white diffuse sphere that reflects it whole (a convex
    // shape: one bounce escapes). The image is the sky's colour, in rgb exactly; in the spectral
    // mode D65 times the colour's curve develops back to it, up to the round trip and the noise
    // of 65536 paths' wavelengths.
    const Color3f sky(0.3f, 0.5f, 0.8f);
    const std::string xml = furnace(
        "<emitter type=\"constant\"><rgb name=\"radiance\" value=\"0.3, 0.5, 0.8\"/></emitter>",
        "<shape type=\"sphere\"><float name=\"radius\" value=\"0.8\"/><bsdf type=\"diffuse\">"
        "<float name=\"reflectance\" value=\"1\"/></bsdf></shape>");
    expect_near(render_mean(xml, "scalar_rgb"), sky, 2e-3f, "rgb");
    expect_near(render_mean(xml, "scalar_spectral"), sky, 8e-3f, "spectral");
}

TEST(SpectralMode, AColoredPlaneUnderAWhiteEnvironmentMapIsItsColour) {
    // An environment map of one colour is a uniform sky; an orthographic view of a diffuse
    // plane facing it sees ρ times the sky. A white sky (1, 1, 1) is D65, so the plane develops
    // to ρ; the map is read per pixel as the spectral mode reads it (curve, scale, D65).
    const fs::path dir =
        fs::temp_directory_path() / fmt::format("facet-spectral-mode-{}", ::getpid());
    fs::create_directories(dir);
    Image sky(8, 4, 3);
    for (float &v : sky.data) v = 2.f;
    write_image((dir / "sky.exr").string(), sky);
    const Color3f rho(0.7f, 0.35f, 0.1f);
    const std::string xml =
        furnace("<emitter type=\"envmap\"><string name=\"filename\" value=\"sky.exr\"/>"
                "<float name=\"scale\" value=\"0.5\"/></emitter>",
                "<shape type=\"rectangle\"><transform name=\"to_world\"><scale value=\"10\"/>"
                "</transform><bsdf type=\"diffuse\"><rgb name=\"reflectance\" "
                "value=\"0.7, 0.35, 0.1\"/></bsdf></shape>");
    expect_near(render_mean(xml, "scalar_rgb", dir), rho, 2e-3f, "rgb");
    expect_near(render_mean(xml, "scalar_spectral", dir), rho, 8e-3f, "spectral");
    fs::remove_all(dir);
}

TEST(SpectralMode, ColoursAreClampedAlikeAndScalarsStayScalars) {
    const Wavelengths l(420.f, 530.f, 640.f, 700.f);
    // An unbounded rgb is clamped to [0, 1], grey or not (as Mitsuba's spectral modes clamp it);
    // a number is not.
    Properties props("test");
    props.set_mode(ColourMode::Spectral);
    props.set_color("grey", Color3f(1.5f));
    props.set_color("colour", Color3f(1.5f, 1.5f, 1.4f));
    props.set_float("number", 1.5);
    EXPECT_EQ(eval_at(*props.texture("grey", SpectrumKind::Unbounded), l), Color3f(1.f));
    const Color3f colour = eval_at(*props.texture("colour", SpectrumKind::Unbounded), l);
    EXPECT_LE(colour.max(), 1.f);
    EXPECT_GT(std::min(std::min(colour.r, colour.g), std::min(colour.b, colour.w)), 0.9f);
    EXPECT_EQ(eval_at(*props.texture("number", SpectrumKind::Unbounded), l), Color3f(1.5f));
    // A scalar parameter given as a colour (a blend weight, an opacity) is one number for every
    // path, the rgb mode's mean, not the mean of the path's wavelengths.
    props.set_color("weight", Color3f(0.9f, 0.2f, 0.1f));
    const auto weight = props.texture("weight");
    SurfaceInteraction a, b;
    a.uv = b.uv = Point2f(0.1f, 0.1f);
    a.wavelengths = Wavelengths(400.f, 410.f, 420.f);
    b.wavelengths = Wavelengths(650.f, 660.f, 670.f);
    EXPECT_FLOAT_EQ(weight->eval_1(a), 0.4f);
    EXPECT_FLOAT_EQ(weight->eval_1(b), 0.4f);
}

TEST(SpectralMode, ALightsIntensityMustNotVaryOverASurface) {
    const std::string xml = R"(<scene version="3.0.0">
        <emitter type="point">
            <texture type="checkerboard" name="intensity"/>
        </emitter>
    </scene>)";
    for (const char *mode : {"scalar_rgb", "scalar_spectral"}) {
        LoadOptions opts;
        opts.mode = mode;
        try {
            load_string(xml, opts);
            ADD_FAILURE() << "a checkerboard intensity was accepted in " << mode;
        } catch (const Error &e) {
            EXPECT_NE(std::string(e.what()).find("varies over the surface"), std::string::npos)
                << e.what();
            EXPECT_TRUE(e.location().valid()) << e.what();
        }
    }
}
