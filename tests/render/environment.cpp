// Environment lighting: a diffuse plane seen by an orthographic camera straight from above, lit
// by an environment map. Every pixel then estimates the same number, ρ/π ∫ L(ω) cos θ dω over
// the upper hemisphere, which the test integrates by quadrature of the emitter's own lookup.
// Importance sampling and uniform sampling of the map must agree with it (and with each other)
// within their noise, and importance sampling must be the less noisy one. A map that varies by
// row only has a closed form under Mitsuba's corner-aligned rows (row j at θ = πj/(H-1)).

#include <facet/emitter.h>
#include <facet/image.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

using namespace facet;
namespace fs = std::filesystem;

namespace {

/// A 64×32 sky: a blue-to-white gradient, a warm bright "sun" patch, dark below the horizon.
std::string write_sky(const fs::path &dir) {
    Image img(64, 32, 3);
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            float t = float(y) / float(img.height - 1);
            Color3f c = t < 0.5f ? Color3f(0.3f + t, 0.5f + t, 1.0f) : Color3f(0.05f, 0.04f, 0.03f);
            if (x >= 40 && x < 43 && y >= 8 && y < 10) c = Color3f(400.f, 300.f, 200.f);
            for (int ch = 0; ch < 3; ++ch) img.at(x, y, ch) = c[ch];
        }
    std::string path = (dir / "sky.exr").string();
    write_image(path, img);
    return path;
}

/// A 64×32 sky without a sun, brighter below the horizon than above: the light samples of a
/// plane facing up (which sees only the upper half) and of one that takes the whole map differ
/// by a factor of about three, and the BSDF samples' MIS weights with them.
std::string write_bright_ground(const fs::path &dir) {
    Image img(64, 32, 3);
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const float t = float(y) / float(img.height - 1);
            const Color3f c = t < 0.5f ? Color3f(1.f + float(x % 8) * 0.1f, 1.f, 1.2f - t)
                                       : Color3f(4.f, 3.f, 2.f + t);
            for (int ch = 0; ch < 3; ++ch) img.at(x, y, ch) = c[ch];
        }
    std::string path = (dir / "bright-ground.exr").string();
    write_image(path, img);
    return path;
}

/// A 4×3 map constant along each row: `zenith` on the first row (θ = 0), `horizon` on the
/// second (θ = π/2), 0.1 on the last.
std::string write_rows(const fs::path &dir, float zenith, float horizon) {
    Image img(4, 3, 3);
    for (int x = 0; x < img.width; ++x)
        for (int ch = 0; ch < 3; ++ch) {
            img.at(x, 0, ch) = zenith;
            img.at(x, 1, ch) = horizon;
            img.at(x, 2, ch) = 0.1f;
        }
    std::string path = (dir / "rows.exr").string();
    write_image(path, img);
    return path;
}

/// The plane under `sky`, rendered by `integrator` (XML), the envmap given `extra` (XML).
std::string scene_xml(const std::string &sky, bool importance,
                      const std::string &integrator = R"(<integrator type="direct"/>)",
                      const std::string &extra = "") {
    return R"(<scene version="3.0.0">
    )" + integrator +
           R"(
    <sensor type="orthographic">
        <transform name="to_world">
            <scale value="0.5"/>
            <lookat origin="0, 5, 0" target="0, 0, 0" up="0, 0, 1"/>
        </transform>
        <sampler type="independent"><integer name="sample_count" value="32"/></sampler>
        <film type="hdrfilm">
            <integer name="width" value="32"/><integer name="height" value="32"/>
            <rfilter type="box"/>
        </film>
    </sensor>
    <emitter type="envmap">
        <string name="filename" value=")" +
           sky + R"("/>
        <boolean name="importance_sampling" value=")" +
           (importance ? "true" : "false") + R"("/>)" + extra + R"(
    </emitter>
    <shape type="rectangle">
        <transform name="to_world"><scale value="100"/><rotate x="1" angle="-90"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf>
    </shape>
</scene>)";
}

struct Stats {
    Color3f mean, stderr_;
    float luminance_stddev = 0.f;
};

Stats render_stats(const std::string &xml) {
    auto scene = std::dynamic_pointer_cast<Scene>(load_string(xml));
    RenderOptions opts;
    opts.progress = false;
    RenderResult r = render(*scene, *scene->sensors().at(0), opts);
    const Image &img = r.image;
    size_t n = size_t(img.width) * img.height;
    Stats s;
    Color3f sum, sum2;
    double lsum = 0, lsum2 = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            Color3f c(img.at(x, y, 0), img.at(x, y, 1), img.at(x, y, 2));
            sum += c;
            sum2 += c * c;
            lsum += c.luminance();
            lsum2 += double(c.luminance()) * c.luminance();
        }
    s.mean = sum / float(n);
    for (int ch = 0; ch < 3; ++ch) {
        float var = sum2[ch] / float(n) - s.mean[ch] * s.mean[ch];
        s.stderr_[ch] = std::sqrt(std::max(var, 0.f) / float(n - 1));
    }
    double lm = lsum / double(n);
    s.luminance_stddev = float(std::sqrt(std::max(lsum2 / double(n) - lm * lm, 0.0)));
    return s;
}

/// ρ/π ∫ L(ω) cos θ dω over the upper hemisphere, by the midpoint rule on a fine (θ, φ) grid.
Color3f reference_radiance(const std::string &xml) {
    auto scene = std::dynamic_pointer_cast<Scene>(load_string(xml));
    const Emitter &env = *scene->environment_emitters().at(0);
    const int nt = 512, np = 1024;
    Color3f sum;
    for (int i = 0; i < nt; ++i) {
        double theta = (i + 0.5) * (M_PI / 2) / nt;
        for (int j = 0; j < np; ++j) {
            double phi = (j + 0.5) * 2 * M_PI / np;
            Vector3f d(float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)),
                       float(std::sin(theta) * std::sin(phi)));
            SurfaceInteraction si;
            si.wi = -d;
            sum += env.eval(si) * float(std::cos(theta) * std::sin(theta));
        }
    }
    double dA = (M_PI / 2 / nt) * (2 * M_PI / np);
    return sum * float(dA * 0.5 / M_PI);
}

} // namespace

TEST(EnvironmentMap, ImportanceAndUniformSamplingAgreeWithQuadrature) {
    fs::path dir = fs::temp_directory_path() / "facet-envmap-render";
    fs::create_directories(dir);
    std::string sky = write_sky(dir);
    Color3f ref = reference_radiance(scene_xml(sky, true));
    Stats is = render_stats(scene_xml(sky, true));
    Stats us = render_stats(scene_xml(sky, false));
    for (int ch = 0; ch < 3; ++ch) {
        EXPECT_NEAR(is.mean[ch], ref[ch], 4.f * is.stderr_[ch] + 1e-3f * ref[ch])
            << "importance, channel " << ch;
        EXPECT_NEAR(us.mean[ch], ref[ch], 4.f * us.stderr_[ch] + 1e-3f * ref[ch])
            << "uniform, channel " << ch;
        float se = std::sqrt(sqr(is.stderr_[ch]) + sqr(us.stderr_[ch]));
        EXPECT_NEAR(is.mean[ch], us.mean[ch], 4.f * se) << "channel " << ch;
    }
    // The sun holds most of the energy in a tiny solid angle: sampling by luminance must be
    // far less noisy than sampling the sphere uniformly.
    EXPECT_LT(is.luminance_stddev * 3.f, us.luminance_stddev);
}

TEST(EnvironmentMap, RowMapMatchesTheClosedFormOfCornerAlignedRows) {
    // Rows at θ = 0 and π/2 with radiance a and b: over the upper hemisphere L(θ) = a + (b -
    // a) 2θ/π, so a plane of albedo ρ facing up shows ρ/π ∫ L cos θ dω = ρ (a + b) / 2. Rows at
    // pixel centres (θ = π/6 and π/2 for these rows) would show a different value.
    fs::path dir = fs::temp_directory_path() / "facet-envmap-render";
    fs::create_directories(dir);
    const float a = 2.f, b = 0.5f, rho = 0.5f;
    std::string map = write_rows(dir, a, b);
    float expected = rho * (a + b) / 2.f;
    for (bool importance : {true, false}) {
        Stats s = render_stats(scene_xml(map, importance));
        for (int ch = 0; ch < 3; ++ch)
            EXPECT_NEAR(s.mean[ch], expected, 4.f * s.stderr_[ch] + 1e-3f * expected)
                << (importance ? "importance" : "uniform") << ", channel " << ch;
    }
}

TEST(EnvironmentMap, MisCompensationSettingsAgreeWithQuadrature) {
    // The sky's mean luminance lies above everything but its sun: compensation samples only
    // the sun, unset mis_compensation mixes 10% of the plain table into the samples MIS
    // weighs. Every setting, with every way the integrators use light samples (the path
    // tracer's and the direct integrator's MIS, the direct integrator's light samples alone
    // when it takes no BSDF samples), must show the same plane.
    fs::path dir = fs::temp_directory_path() / "facet-envmap-render";
    fs::create_directories(dir);
    std::string sky = write_sky(dir);
    Color3f ref = reference_radiance(scene_xml(sky, true));
    const char *integrators[] = {
        R"(<integrator type="path"><integer name="max_depth" value="2"/></integrator>)",
        R"(<integrator type="direct"/>)",
        R"(<integrator type="direct"><integer name="bsdf_samples" value="0"/></integrator>)"};
    const char *settings[] = {"", R"(<boolean name="mis_compensation" value="true"/>)",
                              R"(<boolean name="mis_compensation" value="false"/>)"};
    for (const char *integrator : integrators)
        for (const char *setting : settings) {
            // Compensation alone never samples below the mean: only MIS makes it unbiased.
            if (std::string(integrator).find("bsdf_samples") != std::string::npos &&
                std::string(setting).find("true") != std::string::npos)
                continue;
            SCOPED_TRACE(std::string(integrator) + " " + setting);
            Stats s = render_stats(scene_xml(sky, true, integrator, setting));
            for (int ch = 0; ch < 3; ++ch)
                EXPECT_NEAR(s.mean[ch], ref[ch], 4.f * s.stderr_[ch] + 1e-3f * ref[ch])
                    << "channel " << ch;
        }
}

TEST(EnvironmentMap, LightSamplesToldTheSideAgreeWithQuadratureInATurnedMap) {
    // The diffuse plane reflects only to the side it is seen from: the path tracer's and the
    // direct integrator's MIS light samples leave out the map's blocks wholly below it. With
    // the map turned (its sun then lies at some height, and the plane's side falls in another
    // bin of the map's own frame for each turn), the plane must show what the quadrature of
    // the map over its upper hemisphere gives, for every compensation setting.
    fs::path dir = fs::temp_directory_path() / "facet-envmap-render";
    fs::create_directories(dir);
    const std::string skies[] = {write_sky(dir), write_bright_ground(dir)};
    const char *turns[] = {
        "",
        R"(<transform name="to_world"><rotate x="1" angle="70"/><rotate y="1" angle="30"/></transform>)",
        R"(<transform name="to_world"><rotate z="1" angle="-100"/></transform>)"};
    const char *integrators[] = {
        R"(<integrator type="path"><integer name="max_depth" value="2"/></integrator>)",
        R"(<integrator type="direct"/>)"};
    const char *settings[] = {"", R"(<boolean name="mis_compensation" value="true"/>)"};
    for (const std::string &sky : skies)
        for (const char *turn : turns)
            for (const char *integrator : integrators)
                for (const char *setting : settings) {
                    SCOPED_TRACE(sky + " " + turn + " " + integrator + " " + setting);
                    const std::string extra = std::string(turn) + setting;
                    Color3f ref = reference_radiance(scene_xml(sky, true, integrator, extra));
                    Stats s = render_stats(scene_xml(sky, true, integrator, extra));
                    for (int ch = 0; ch < 3; ++ch)
                        EXPECT_NEAR(s.mean[ch], ref[ch], 4.f * s.stderr_[ch] + 1e-3f * ref[ch])
                            << "channel " << ch;
                }
}
