// The spectral bands of a film (SpectralBands, the `specfilm` plugin): the density the paths'
// wavelengths are drawn from (the sum of the sensor response functions), a band's estimate
// ∫ s(λ) L(λ) dλ, the film's channels, its comparison with the hdrfilm's XYZ through the CIE
// curves as bands, and what it refuses.
#include <facet/film.h>
#include <facet/image.h>
#include <facet/integrator.h>
#include <facet/logger.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/spectrum.h>
#include <facet/texture.h>
#include <facet/xml.h>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

using namespace facet;

namespace {

std::shared_ptr<Texture> srf(const std::string &pairs) {
    return data_spectrum_texture(parse_spectrum_pairs(pairs), SpectrumKind::Measured);
}

/// ∫ of a piecewise linear spectrum given as pairs, by the trapezoids of its pairs.
double integral(const std::string &pairs) {
    const SpectrumData d = parse_spectrum_pairs(pairs);
    double sum = 0.0;
    for (size_t i = 1; i < d.wavelengths.size(); ++i)
        sum += 0.5 * (d.values[i - 1] + d.values[i]) * (d.wavelengths[i] - d.wavelengths[i - 1]);
    return sum;
}

const std::string Short = "400:0, 450:1, 500:0", Long = "560:0, 600:2, 640:0.5, 700:0";

SpectralBands two_bands(size_t points = 301) {
    return SpectralBands({{"short", srf(Short)}, {"long", srf(Long)}}, 400.f, 700.f, points);
}

/// Channel means of a render of `xml` in `mode`.
std::map<std::string, double> channel_means(const std::string &xml, const std::string &mode,
                                            int threads = 2) {
    LoadOptions lo;
    lo.mode = mode;
    auto scene = std::dynamic_pointer_cast<Scene>(load_string(xml, lo));
    RenderOptions ro;
    ro.progress = false;
    ro.threads = threads;
    const Image img = render(*scene, *scene->sensors().at(0), ro).image;
    std::map<std::string, double> mean;
    for (int c = 0; c < img.channels; ++c) {
        double sum = 0.0;
        for (int y = 0; y < img.height; ++y)
            for (int x = 0; x < img.width; ++x) sum += img.at(x, y, c);
        mean[img.channel_names[size_t(c)]] = sum / double(img.width * img.height);
    }
    return mean;
}

/// A 16x16 orthographic view of `content` under `emitter`, with the film `film`.
std::string view(const std::string &film, const std::string &emitter, const std::string &content,
                 int spp, const std::string &integrator = "<integrator type=\"path\"/>") {
    return fmt::format(R"(<scene version="3.0.0">
        {}
        <sensor type="orthographic">
            <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
            <sampler type="independent"><integer name="sample_count" value="{}"/></sampler>
            {}
        </sensor>
        {}
        {}
    </scene>)",
                       integrator, spp, film, emitter, content);
}

std::string specfilm(const std::string &bands) {
    return R"(<film type="specfilm"><integer name="width" value="16"/>
              <integer name="height" value="16"/><rfilter type="box"/>)" +
           bands + "</film>";
}

/// A load error's message (empty when the scene loads).
std::string load_error(const std::string &xml, const std::string &mode) {
    LoadOptions lo;
    lo.mode = mode;
    try {
        load_string(xml, lo);
    } catch (const Error &e) {
        return e.what();
    }
    return "";
}

/// A render error's message (empty when the scene renders).
std::string render_error(const std::string &xml, const std::string &mode) {
    LoadOptions lo;
    lo.mode = mode;
    auto scene = std::dynamic_pointer_cast<Scene>(load_string(xml, lo));
    RenderOptions ro;
    ro.progress = false;
    try {
        render(*scene, *scene->sensors().at(0), ro);
    } catch (const Error &e) {
        return e.what();
    }
    return "";
}

bool contains(const std::string &s, const std::string &part) {
    return s.find(part) != std::string::npos;
}

} // namespace

TEST(SpectralBands, DrawsWavelengthsFromTheSumOfTheResponses) {
    const SpectralBands bands = two_bands();
    // The density is S / ∫S: it integrates to one, is zero where no band responds.
    const double total = integral(Short) + integral(Long);
    EXPECT_NEAR(bands.pdf(450.f), 1.0 / total, 1e-6);
    EXPECT_NEAR(bands.pdf(600.f), 2.0 / total, 1e-6);
    EXPECT_EQ(bands.pdf(530.f), 0.f);
    EXPECT_EQ(bands.pdf(399.f), 0.f);
    EXPECT_EQ(bands.pdf(701.f), 0.f);
    // A histogram of the wavelengths against the density's integral over each bin (60 bins of
    // 5 nm): within 5 standard deviations of the binomial counts, and no sample where S is 0.
    constexpr int N = 100000, Bins = 60;
    std::vector<double> count(Bins, 0.0);
    int zero = 0;
    for (int k = 0; k < N; ++k) {
        // An irrational step: the four lanes of each u are the strata u + i/4.
        const float u = float(std::fmod(0.5 + k * 0.6180339887498949, 1.0));
        const auto [lambda, weight] = bands.sample_wavelengths(u);
        for (int i = 0; i < 4; ++i) {
            ASSERT_GE(lambda[i], 400.f);
            ASSERT_LE(lambda[i], 700.f);
            // Only the edges of S's support (u at a segment's end) can have a zero density:
            // a lane of weight 0.
            const float p = bands.pdf(lambda[i]);
            if (p == 0.f) {
                ++zero;
                EXPECT_EQ(weight[i], 0.f);
            } else {
                EXPECT_FLOAT_EQ(weight[i], 1.f / p);
            }
            count[size_t(std::min(Bins - 1, int((lambda[i] - 400.f) / 5.f)))] += 1.0;
        }
    }
    EXPECT_LE(zero, 2);
    for (int b = 0; b < Bins; ++b) {
        double p = 0.0; // ∫ pdf over the bin, by its midpoint rule at 0.05 nm
        for (int s = 0; s < 100; ++s) p += bands.pdf(400.f + 5.f * b + 0.05f * (s + 0.5f)) * 0.05;
        const double expected = 4.0 * N * p;
        EXPECT_NEAR(count[size_t(b)], expected, 5.0 * std::sqrt(expected) + 1.0)
            << "bin " << 400 + 5 * b << " nm";
    }
    // Lane i of u is lane 0 of u + i/4.
    const auto [l0, w0] = bands.sample_wavelengths(0.1f);
    const auto [l1, w1] = bands.sample_wavelengths(0.35f);
    EXPECT_NEAR(l0[1], l1[0], 1e-3f);
    EXPECT_NEAR(l0[2], l1[1], 1e-3f);
}

TEST(SpectralBands, ABandIsTheResponseWeightedRadiance) {
    // L(λ) = 1 + λ/1000: band j estimates ∫ s_j(λ) L(λ) dλ, computed here on a fine grid.
    const SpectralBands bands = two_bands();
    EXPECT_EQ(bands.names(), (std::vector<std::string>{"short", "long"}));
    auto L = [](float l) { return 1.f + l / 1000.f; };
    double exact[2] = {0.0, 0.0};
    const std::shared_ptr<Texture> s[2] = {srf(Short), srf(Long)};
    for (int j = 0; j < 2; ++j)
        for (int k = 0; k < 30000; ++k) {
            const float l = 400.f + 0.01f * (float(k) + 0.5f);
            const auto &t = dynamic_cast<const SpectralTexture &>(*s[j]);
            exact[j] += double(t.eval_wavelengths(Wavelengths(l)).r * L(l)) * 0.01;
        }
    constexpr int N = 20000;
    double sum[2] = {0.0, 0.0}, unweighted = 0.0;
    for (int k = 0; k < N; ++k) {
        const auto [lambda, weight] = bands.sample_wavelengths((float(k) + 0.5f) / float(N));
        float out[2];
        bands.develop(map(lambda, L), lambda, weight, out);
        sum[0] += out[0];
        sum[1] += out[1];
        bands.develop(map(lambda, L), lambda, Color3f(1.f), out);
        unweighted += out[0];
    }
    for (int j = 0; j < 2; ++j) EXPECT_NEAR(sum[j] / N, exact[j], 2e-3 * exact[j]) << j;
    // The weights (1/pdf) matter: without them the estimate is another number.
    EXPECT_GT(std::abs(unweighted / N - exact[0]), 0.5 * exact[0]);
}

TEST(SpectralBands, RefusesResponsesThatAreZeroAndGridsOutsideTheRange) {
    EXPECT_THROW(SpectralBands({{"zero", srf("400:0, 700:0")}}, 400.f, 700.f, 31), Error);
    EXPECT_THROW(SpectralBands({{"b", srf(Short)}}, 300.f, 700.f, 31), Error);
    EXPECT_THROW(SpectralBands({}, 400.f, 700.f, 31), Error);
    EXPECT_THROW(SpectralBands({{"b", srf(Short)}}, 400.f, 700.f, 1), Error);
}

TEST(SpecFilm, RecordsOneChannelPerResponseSortedByName) {
    // A sky of radiance 2 at every wavelength: band j is 2 ∫ s_j (a constant response over the
    // whole range: 2·470), in both spectral modes, with a tabulated, a regular and a constant
    // response.
    const std::string film = specfilm(R"(<spectrum name="tri" value="500:0, 550:1, 600:0"/>
        <spectrum name="flat" value="1"/>
        <spectrum name="blue" type="regular">
            <float name="wavelength_min" value="400"/><float name="wavelength_max" value="480"/>
            <string name="values" value="0, 2, 0"/>
        </spectrum>)");
    const std::string sky =
        R"(<emitter type="constant"><spectrum name="radiance" value="360:2, 830:2"/></emitter>)";
    for (const char *mode : {"scalar_spectral", "scalar_spectral_polarized"}) {
        SCOPED_TRACE(mode);
        const auto mean = channel_means(view(film, sky, "", 64), mode);
        ASSERT_EQ(mean.size(), 3u); // no R, G, B, no alpha
        EXPECT_NEAR(mean.at("tri"), 2.0 * 50.0, 0.01 * 100.0);
        EXPECT_NEAR(mean.at("flat"), 2.0 * 470.0, 0.01 * 940.0);
        EXPECT_NEAR(mean.at("blue"), 2.0 * 80.0, 0.01 * 160.0);
    }
    // The channel order is the names' (not the declaration's), AOVs after the bands.
    LoadOptions lo;
    lo.mode = "scalar_spectral";
    auto scene = std::dynamic_pointer_cast<Scene>(load_string(
        view(
            film, sky, "", 4,
            R"(<integrator type="aov"><string name="aovs" value="d:depth"/><integrator type="path"/></integrator>)"),
        lo));
    RenderOptions ro;
    ro.progress = false;
    const Image img = render(*scene, *scene->sensors().at(0), ro).image;
    EXPECT_EQ(img.channel_names, (std::vector<std::string>{"blue", "flat", "tri", "d"}));
}

TEST(SpecFilm, DrawsThePathsWavelengthsFromItsBands) {
    // One band under a flat sky: with the wavelengths drawn from the band itself every lane's
    // s(λ)·L/pdf is L·∫s, so every pixel of a 1-spp render is exactly 2·5 (drawn from the
    // visible range's density instead, 700-710 nm would be hit rarely and the pixels would
    // scatter around it).
    LoadOptions lo;
    lo.mode = "scalar_spectral";
    auto scene = std::dynamic_pointer_cast<Scene>(load_string(
        view(
            specfilm(R"(<spectrum name="red_edge" value="700:0, 705:1, 710:0"/>)"),
            R"(<emitter type="constant"><spectrum name="radiance" value="360:2, 830:2"/></emitter>)",
            "", 1),
        lo));
    RenderOptions ro;
    ro.progress = false;
    const Image img = render(*scene, *scene->sensors().at(0), ro).image;
    ASSERT_EQ(img.channels, 1);
    for (float v : img.data) ASSERT_NEAR(v, 10.f, 1e-3f);
}

TEST(SpecFilm, TheCieCurvesAsBandsGiveTheXyzOfTheHdrFilm) {
    // The bands x̄/∫ȳ, ȳ/∫ȳ, z̄/∫ȳ (the CIE 1931 table at 5 nm) record a pixel's XYZ, which the
    // hdrfilm's xyz pixel format gives from the visible range's wavelengths: two estimators of
    // one image, on a coloured plane under a blackbody sky.
    constexpr double CieYIntegral = 106.7502593994140625; // ∫ȳ dλ of the continuous curves
    std::string bands;
    for (int c = 0; c < 3; ++c) {
        std::string pairs;
        for (int l = 360; l <= 830; l += 5)
            pairs += fmt::format("{}{}:{}", pairs.empty() ? "" : ", ", l,
                                 double(cie1931_xyz(double(l))[c]) / CieYIntegral);
        bands += fmt::format(R"(<spectrum name="{}" value="{}"/>)", "XYZ"[c], pairs);
    }
    const std::string sky = R"(<emitter type="constant">
        <spectrum name="radiance" type="blackbody"><float name="temperature" value="4000"/></spectrum>
        </emitter>)";
    const std::string plane =
        R"(<shape type="rectangle"><transform name="to_world"><scale value="10"/>
        </transform><bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.6, 0.3"/></bsdf></shape>)";
    const auto spec = channel_means(view(specfilm(bands), sky, plane, 256), "scalar_spectral");
    const auto xyz = channel_means(view(R"(<film type="hdrfilm"><integer name="width" value="16"/>
        <integer name="height" value="16"/><rfilter type="box"/>
        <string name="pixel_format" value="xyz"/></film>)",
                                        sky, plane, 256),
                                   "scalar_spectral");
    for (const char *c : {"X", "Y", "Z"}) {
        SCOPED_TRACE(c);
        EXPECT_GT(xyz.at(c), 0.0);
        EXPECT_NEAR(spec.at(c), xyz.at(c), 0.01 * xyz.at(c));
    }
}

TEST(SpecFilm, WritesItsBandsInItsComponentFormat) {
    // float16 (the default) stores the bands as half, the AOVs after them as float32; float32
    // stores everything as float. An EXR of bands has no Rec.709 chromaticities.
    const std::string dir = ::testing::TempDir();
    for (const char *format : {"float16", "float32"}) {
        SCOPED_TRACE(format);
        LoadOptions lo;
        lo.mode = "scalar_spectral";
        auto scene = std::dynamic_pointer_cast<Scene>(load_string(
            view(
                specfilm(fmt::format(R"(<spectrum name="short" value="450:0, 500:1, 550:0"/>
                                         <spectrum name="long" value="550:0, 600:1, 650:0"/>
                                         <string name="component_format" value="{}"/>)",
                                     format)),
                R"(<emitter type="constant"/>)", "", 2,
                R"(<integrator type="aov"><string name="aovs" value="d:depth"/><integrator type="path"/></integrator>)"),
            lo));
        RenderOptions ro;
        ro.progress = false;
        const Sensor &sensor = *scene->sensors().at(0);
        const Image img = render(*scene, sensor, ro).image;
        const std::string path = dir + "/specfilm_" + format + ".exr";
        sensor.film().write(img, path, {});
        const ImageFile file = read_image_file(path);
        // (A reader may order the channels its own way.)
        std::vector<std::string> names = file.image.channel_names, half = file.half_channels;
        std::sort(names.begin(), names.end());
        std::sort(half.begin(), half.end());
        EXPECT_EQ(names, (std::vector<std::string>{"d", "long", "short"}));
        if (std::string(format) == "float16")
            EXPECT_EQ(half, (std::vector<std::string>{"long", "short"}));
        else
            EXPECT_TRUE(file.half_channels.empty());
        EXPECT_EQ(file.attributes.count("chromaticities"), 0u);
    }
}

TEST(SpecFilm, GivesTheSameImageWhateverTheThreadCount) {
    const std::string xml =
        view(specfilm(R"(<spectrum name="a" value="450:0, 500:1, 550:0"/>)"),
             R"(<emitter type="constant"><rgb name="radiance" value="0.3, 0.6, 0.9"/></emitter>)",
             R"(<shape type="sphere"><bsdf type="diffuse"/></shape>)", 8);
    EXPECT_EQ(channel_means(xml, "scalar_spectral", 1), channel_means(xml, "scalar_spectral", 2));
}

TEST(SpecFilm, RefusesWhatItCannotRecord) {
    const std::string sky =
        R"(<emitter type="constant"><rgb name="radiance" value="1"/></emitter>)";
    const std::string band = R"(<spectrum name="a" value="450:0, 500:1, 550:0"/>)";
    // Outside the spectral modes, as Mitsuba's.
    const std::string rgb = load_error(view(specfilm(band), sky, "", 4), "scalar_rgb");
    EXPECT_TRUE(contains(rgb, "specfilm") && contains(rgb, "scalar_spectral")) << rgb;
    // Without a response function, with a texture that is not a spectrum, with responses zero
    // everywhere or outside 360-830 nm: located errors.
    for (const auto &[film, expect] : std::vector<std::pair<std::string, std::string>>{
             {"", "at least one spectrum"},
             {R"(<texture name="t" type="checkerboard"/>)", "not a spectrum"},
             {R"(<spectrum name="z" value="400:0, 700:0"/>)", "zero everywhere"},
             {R"(<spectrum name="ir" value="900:1, 1000:1"/>)", "outside"},
             {R"(<spectrum name="facet.sum.x" value="400:0, 500:1, 600:0"/>)", "prefix"}}) {
        const std::string msg = load_error(view(specfilm(film), sky, "", 4), "scalar_spectral");
        EXPECT_TRUE(contains(msg, expect)) << msg;
        // The film's line (6) or the spectrum's (7).
        EXPECT_TRUE(contains(msg, "string:6:") || contains(msg, "string:7:")) << msg;
    }
    // Integrators that develop their own RGB, and light tracers (which splat R, G, B).
    for (
        const char *integrator :
        {R"(<integrator type="aov"><string name="aovs" value="a:albedo"/><integrator type="path"/></integrator>)",
         R"(<integrator type="moment"><integrator type="path"/></integrator>)",
         R"(<integrator type="stokes"><integrator type="path"/></integrator>)",
         R"(<integrator type="ptracer"/>)"}) {
        const std::string mode =
            contains(integrator, "stokes") ? "scalar_spectral_polarized" : "scalar_spectral";
        const std::string msg = render_error(view(specfilm(band), sky, "", 4, integrator), mode);
        EXPECT_TRUE(contains(msg, "spectral bands")) << integrator << ": " << msg;
    }
    // The aov integrator's geometric channels render with bands.
    EXPECT_EQ(
        render_error(
            view(
                specfilm(band), sky, "", 4,
                R"(<integrator type="aov"><string name="aovs" value="d:depth"/><integrator type="path"/></integrator>)"),
            "scalar_spectral"),
        "");
}

TEST(SensorSrf, WeighsTheRadianceTheFilmDevelops) {
    // A sensor response of 1 over 500-600 nm (0 elsewhere) under a sky of radiance 2 at every
    // wavelength: the hdrfilm's XYZ is 2 ∫ over 500-600 nm of x̄, ȳ, z̄, over ∫ȳ.
    constexpr double CieYIntegral = 106.7502593994140625;
    double expected[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < 10000; ++k) {
        const Color3f c = cie1931_xyz(500.0 + 0.01 * (k + 0.5));
        for (int i = 0; i < 3; ++i) expected[i] += 2.0 * double(c[i]) * 0.01 / CieYIntegral;
    }
    const std::string film = R"(<film type="hdrfilm"><integer name="width" value="16"/>
        <integer name="height" value="16"/><rfilter type="box"/>
        <string name="pixel_format" value="xyz"/></film>)";
    std::string xml = view(
        film,
        R"(<emitter type="constant"><spectrum name="radiance" value="360:2, 830:2"/></emitter>)",
        "", 64);
    const std::string srf = R"(<spectrum name="srf" value="499.99:0, 500:1, 600:1, 600.01:0"/>)";
    xml.insert(xml.find("<sampler"), srf);
    for (const char *mode : {"scalar_spectral", "scalar_spectral_polarized"}) {
        SCOPED_TRACE(mode);
        const auto mean = channel_means(xml, mode);
        EXPECT_NEAR(mean.at("X"), expected[0], 0.01 * expected[0]);
        EXPECT_NEAR(mean.at("Y"), expected[1], 0.01 * expected[1]);
        EXPECT_NEAR(mean.at("Z"), expected[2], 0.01 * expected[2]);
    }
    // Refused outside the spectral modes (as Mitsuba's), with a film's bands, by light tracers
    // and by integrators that develop their own RGB.
    EXPECT_TRUE(contains(load_error(xml, "scalar_rgb"), "needs a spectral mode"));
    std::string both = view(specfilm(R"(<spectrum name="a" value="450:0, 500:1, 550:0"/>)"),
                            R"(<emitter type="constant"/>)", "", 4);
    both.insert(both.find("<sampler"), srf);
    EXPECT_TRUE(contains(load_error(both, "scalar_spectral"), "give only one"));
    std::string traced = xml;
    traced.replace(traced.find("<integrator type=\"path\"/>"), 25,
                   "<integrator type=\"ptracer\"/>");
    EXPECT_TRUE(contains(render_error(traced, "scalar_spectral"), "srf"));
    std::string moment = xml;
    moment.replace(moment.find("<integrator type=\"path\"/>"), 25,
                   "<integrator type=\"moment\"><integrator type=\"path\"/></integrator>");
    EXPECT_TRUE(contains(render_error(moment, "scalar_spectral"), "srf"));
}
