// The polarized mode: the Fresnel equations with their phases against the closed forms of
// surface-reflection.txt (the s- and p-amplitudes with their signs, Brewster's angle, the phase of
// total internal reflection, the conductor), the Mueller matrices of reflection and refraction,
// the rotation of Stokes frames, and renders whose answer is known: Malus's law through two
// polarizers on differently oriented sheets, a quarter-wave plate turning linear light circular,
// and the stokes integrator's components in the camera's frame.

#include <facet/bsdf.h>
#include <facet/fresnel.h>
#include <facet/mode.h>
#include <facet/mueller.h>
#include <facet/random.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <complex>
#include <string>
#include <tuple>

using namespace facet;

namespace {

using C = std::complex<double>;

/// The lecture's amplitudes for light from a medium η1 into η2 at cos θ1 (both real):
/// F_s = (η1 cos θ1 − η2 cos θ2)/(η1 cos θ1 + η2 cos θ2),
/// F_p = (η2 cos θ1 − η1 cos θ2)/(η2 cos θ1 + η1 cos θ2).
std::pair<double, double> lecture_amplitudes(double cos1, double eta1, double eta2) {
    const double sin1 = std::sqrt(1.0 - cos1 * cos1), sin2 = eta1 / eta2 * sin1;
    const double cos2 = std::sqrt(1.0 - sin2 * sin2);
    return {(eta1 * cos1 - eta2 * cos2) / (eta1 * cos1 + eta2 * cos2),
            (eta2 * cos1 - eta1 * cos2) / (eta2 * cos1 + eta1 * cos2)};
}

FresnelPolarized polarized(float cos_i, float eta, float k = 0.f) {
    FresnelPolarized f;
    fresnel_polarized(cos_i, std::complex<float>(eta, k), f);
    return f;
}

void expect_matrix(const Mueller &M, const double (&expected)[4][4], double tol,
                   const std::string &what) {
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            for (int lane = 0; lane < Color3f::Channels; ++lane)
                EXPECT_NEAR(M.m[i][j][lane], expected[i][j], tol)
                    << what << " entry (" << i << ", " << j << ") lane " << lane;
}

void expect_stokes(const Stokes &s, const double (&expected)[4], double tol,
                   const std::string &what) {
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(s.s[k].g, expected[k], tol) << what << " S" << k;
}

float deg(float d) { return d * Pi / 180.f; }

} // namespace

TEST(Polarization, AmplitudesAreTheLecturesWithTheirSigns) {
    // Light from air into glass (η = 1.5) and from glass into air, at 0, 30, 60 and 80 degrees
    // (inside: below the critical angle 41.8 degrees).
    for (float eta : {1.5f, 1.333f})
        for (float angle : {0.f, 30.f, 60.f, 80.f}) {
            const float c = std::cos(deg(angle));
            const auto [fs, fp] = lecture_amplitudes(c, 1.0, eta);
            const FresnelPolarized f = polarized(c, eta);
            EXPECT_NEAR(f.a_s.real(), fs, 2e-6) << eta << " at " << angle;
            EXPECT_NEAR(f.a_p.real(), fp, 2e-6) << eta << " at " << angle;
            EXPECT_EQ(f.a_s.imag(), 0.f);
            EXPECT_EQ(f.a_p.imag(), 0.f);
            // The reflectance the unpolarised code averages.
            EXPECT_NEAR(0.5 * (std::norm(f.a_s) + std::norm(f.a_p)), fresnel_dielectric(c, eta).F,
                        1e-6);
        }
    for (float angle : {0.f, 20.f, 35.f}) {
        const float c = std::cos(deg(angle));
        const auto [fs, fp] = lecture_amplitudes(c, 1.5, 1.0);
        const FresnelPolarized f = polarized(-c, 1.5f); // from the inside
        EXPECT_NEAR(f.a_s.real(), fs, 2e-6) << "inside at " << angle;
        EXPECT_NEAR(f.a_p.real(), fp, 2e-6) << "inside at " << angle;
    }
    // At normal incidence a_p = −a_s: for η > 1, a_s = (1 − η)/(1 + η) < 0.
    const FresnelPolarized n = polarized(1.f, 1.5f);
    EXPECT_NEAR(n.a_s.real(), -0.2, 1e-7);
    EXPECT_NEAR(n.a_p.real(), 0.2, 1e-7);
}

TEST(Polarization, BrewstersAngleReflectsNoPLight) {
    for (float eta : {1.5f, 1.333f, 2.4f}) {
        // tan θB = η from outside; tan θB = 1/η from inside.
        const float outside = std::cos(std::atan(eta)), inside = std::cos(std::atan(1.f / eta));
        EXPECT_NEAR(std::abs(polarized(outside, eta).a_p), 0.0, 1e-6) << eta;
        EXPECT_NEAR(std::abs(polarized(-inside, eta).a_p), 0.0, 1e-6) << eta;
        EXPECT_GT(std::abs(polarized(outside, eta).a_s), 0.1) << eta;
        // The reflection is then a linear polariser along s: S1 = S0 for unpolarised light.
        const Mueller M = mueller::specular_reflection(outside, eta);
        EXPECT_NEAR(M.m[0][0].r, M.m[1][0].r, 1e-6);
        EXPECT_NEAR(M.m[2][2].r, 0.0, 1e-6);
    }
}

TEST(Polarization, TotalInternalReflectionKeepsAllLightAndShiftsThePhases) {
    // From glass (n1 = 1.5) into air at angles past the critical angle: |a_s| = |a_p| = 1, and
    // the phase of p ahead of s is δ with tan(δ/2) = cos θ·√(sin²θ − n²)/sin²θ, n = 1/1.5.
    const double n = 1.0 / 1.5;
    for (float angle : {45.f, 50.f, 60.f, 75.f}) {
        const double t = deg(angle), c = std::cos(t), s2 = std::sin(t) * std::sin(t);
        const FresnelPolarized f = polarized(-float(c), 1.5f);
        EXPECT_NEAR(std::abs(f.a_s), 1.0, 1e-6) << angle;
        EXPECT_NEAR(std::abs(f.a_p), 1.0, 1e-6) << angle;
        EXPECT_EQ(f.cos_t, 0.f);
        const double delta = std::arg(C(f.a_p) * std::conj(C(f.a_s)));
        const double expected = 2.0 * std::atan(c * std::sqrt(s2 - n * n) / s2);
        EXPECT_NEAR(delta, expected, 2e-6) << angle;
        // Each phase alone: φ_s = 2 atan(√(sin²θ − n²)/cos θ), φ_p = 2 atan(√(…)/(n² cos θ)).
        EXPECT_NEAR(std::arg(C(f.a_s)), 2.0 * std::atan(std::sqrt(s2 - n * n) / c), 2e-6);
        EXPECT_NEAR(std::arg(C(f.a_p)), 2.0 * std::atan(std::sqrt(s2 - n * n) / (n * n * c)), 2e-6);
        // The Mueller matrix turns linear light at 45 degrees elliptical by δ.
        const Mueller M = mueller::specular_reflection(-float(c), 1.5f);
        EXPECT_NEAR(M.m[2][2].r, std::cos(delta), 2e-6);
        EXPECT_NEAR(M.m[3][2].r, std::sin(delta), 2e-6);
    }
}

TEST(Polarization, ConductorsReflectTheUnpolarisedFresnelAndShiftPhases) {
    for (auto [eta, k] : {std::pair{0.2f, 3.0f}, {1.5f, 2.5f}, {0.05f, 4.2f}})
        for (float angle : {0.f, 30.f, 60.f, 80.f}) {
            const float c = std::cos(deg(angle));
            const FresnelPolarized f = polarized(c, eta, k), g = polarized(c, eta, -k);
            EXPECT_NEAR(0.5 * (std::norm(f.a_s) + std::norm(f.a_p)), fresnel_conductor(c, eta, k),
                        2e-6)
                << eta << " + " << k << "i at " << angle;
            // Either sign of k is the same metal.
            EXPECT_EQ(f.a_s, g.a_s);
            // r_s ≥ r_p away from the normal (the p-wave's pseudo-Brewster dip).
            if (angle > 0.f) {
                EXPECT_GT(std::norm(f.a_s), std::norm(f.a_p));
            }
            // A pure (non-depolarising) element: m22² + m32² = m00² − m01².
            const Mueller M = mueller::specular_reflection(c, Color3f(eta), Color3f(k));
            const float a = M.m[0][0].r, b = M.m[0][1].r;
            EXPECT_NEAR(sqr(M.m[2][2].r) + sqr(M.m[3][2].r), a * a - b * b, 1e-5);
            EXPECT_EQ(M.m[2][3].r, -M.m[3][2].r);
            if (angle >= 30.f) {
                EXPECT_GT(std::abs(M.m[3][2].r), 1e-3) << "no phase shift";
            }
        }
}

TEST(Polarization, ReflectionAndTransmissionMatricesAtTheNormalAndAtAngles) {
    // Normal incidence on glass: R = 0.04, and the mirror flips S2 and S3 (a_p = −a_s).
    const double R = 0.04;
    expect_matrix(mueller::specular_reflection(1.f, 1.5f),
                  {{R, 0, 0, 0}, {0, R, 0, 0}, {0, 0, -R, 0}, {0, 0, 0, -R}}, 1e-7, "normal");
    expect_matrix(mueller::specular_transmission(1.f, 1.5f),
                  {{1 - R, 0, 0, 0}, {0, 1 - R, 0, 0}, {0, 0, 1 - R, 0}, {0, 0, 0, 1 - R}}, 1e-6,
                  "normal transmission");
    for (float angle : {30.f, 60.f, 80.f}) {
        const float c = std::cos(deg(angle));
        const auto [fs, fp] = lecture_amplitudes(c, 1.0, 1.5);
        const double rs = fs * fs, rp = fp * fp;
        const Mueller M = mueller::specular_reflection(c, 1.5f);
        EXPECT_NEAR(M.m[0][0].r, 0.5 * (rs + rp), 1e-6);
        EXPECT_NEAR(M.m[0][1].r, 0.5 * (rs - rp), 1e-6);
        EXPECT_NEAR(M.m[2][2].r, fs * fp, 1e-6); // cos δ·√(r_s r_p) with its sign
        // What is not reflected is transmitted, from either side.
        const Mueller T = mueller::specular_transmission(c, 1.5f);
        EXPECT_NEAR(T.m[0][0].r, 1.0 - M.m[0][0].r, 1e-6) << angle;
        EXPECT_NEAR(T.m[0][1].r, -M.m[0][1].r, 1e-6) << angle;
        const float c_t = -fresnel_dielectric(c, 1.5f).cos_t;
        EXPECT_NEAR(mueller::specular_transmission(-c_t, 1.5f).m[0][0].r, T.m[0][0].r, 1e-6);
    }
    // Total internal reflection transmits nothing.
    expect_matrix(mueller::specular_transmission(-std::cos(deg(60.f)), 1.5f),
                  {{0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}}, 0.0, "TIR");
}

TEST(Polarization, StokesFramesTurnAboutTheDirectionOfTravel) {
    // Light along +z polarised along x, seen in the frame turned by 30 degrees (x towards y):
    // its angle there is −30 degrees, S1 = cos(−60°), S2 = sin(−60°).
    const Stokes h = {{Color3f(1.f), Color3f(1.f), Color3f(0.f), Color3f(0.f)}};
    const double turned[4] = {1, 0.5, -std::sqrt(3.0) / 2, 0};
    expect_stokes(mueller::rotator(deg(30.f)) * h, turned, 1e-6, "rotator");
    const Vector3f z(0.f, 0.f, 1.f), x(1.f, 0.f, 0.f);
    const Vector3f x30(std::cos(deg(30.f)), std::sin(deg(30.f)), 0.f);
    expect_stokes(mueller::rotate_stokes_basis(z, x, x30) * h, turned, 1e-6, "basis");
    // The same turn seen from light travelling along −z is the opposite one.
    const double back[4] = {1, 0.5, std::sqrt(3.0) / 2, 0};
    expect_stokes(mueller::rotate_stokes_basis(-z, x, x30) * h, back, 1e-6, "basis along -z");
    // A polariser turned by θ passes light along x by cos²θ (Malus).
    const Mueller P = mueller::rotated_element(deg(60.f), mueller::linear_polarizer());
    EXPECT_NEAR((P * h).s[0].r, 0.25, 1e-6);
    // A quarter-wave plate turns light at −45 degrees right circular.
    const Stokes d = {{Color3f(1.f), Color3f(0.f), Color3f(-1.f), Color3f(0.f)}};
    const double right[4] = {1, 0, 0, 1};
    expect_stokes(mueller::linear_retarder(Pi / 2) * d, right, 1e-6, "quarter wave");
    // A Mueller matrix re-expressed in other frames and back is unchanged.
    const Mueller M = mueller::specular_reflection(0.6f, Color3f(0.2f), Color3f(3.f));
    const Frame f(normalize(Vector3f(0.3f, -0.5f, 0.8f)));
    const Vector3f in = normalize(Vector3f(0.2f, 0.1f, -0.9f)), out(0.6f, 0.f, 0.8f);
    const Mueller back_again =
        mueller::to_local(f, mueller::to_world(f, M, in, out), f.to_world(in), f.to_world(out));
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) EXPECT_NEAR(back_again.m[i][j].g, M.m[i][j].g, 1e-5);
}

namespace {

/// A 4x4 orthographic render (the square [−1, 1]²), down −z onto an emitting 4x4 square at
/// z = 0, through the sheets `sheets` (shapes between z = 0 and the camera at z = 5); the mean
/// of the image and of its extra channels.
std::vector<double> render_sheets(const std::string &sheets, const std::string &mode,
                                  const std::string &integrator = "<integrator type=\"path\"/>",
                                  int spp = 64, int seed = 0) {
    const std::string xml = fmt::format(R"(<scene version="3.0.0">
        {}
        <sensor type="orthographic">
            <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
            <sampler type="independent"><integer name="sample_count" value="{}"/>
                <integer name="seed" value="{}"/></sampler>
            <film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/>
                <rfilter type="box"/></film>
        </sensor>
        <shape type="rectangle">
            <transform name="to_world"><scale value="2"/></transform>
            <emitter type="area"><spectrum name="radiance" value="1"/></emitter>
        </shape>
        {}
    </scene>)",
                                        integrator, spp, seed, sheets);
    LoadOptions opts;
    opts.mode = mode;
    auto scene = std::dynamic_pointer_cast<Scene>(load_string(xml, opts));
    RenderOptions ro;
    ro.progress = false;
    const Image image = render(*scene, *scene->sensors().at(0), ro).image;
    std::vector<double> mean(size_t(image.channels), 0.0);
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            for (int c = 0; c < image.channels; ++c) mean[size_t(c)] += image.at(x, y, c);
    for (double &m : mean) m /= double(image.width * image.height);
    return mean;
}

/// A sheet at height z with the BSDF `bsdf`, turned by `turn` degrees about the z axis.
std::string sheet(float z, float turn, const std::string &bsdf) {
    return fmt::format(R"(<shape type="rectangle">
            <transform name="to_world"><scale value="10"/><rotate z="1" angle="{}"/>
                <translate z="{}"/></transform>
            {}
        </shape>)",
                       turn, z, bsdf);
}

std::string polarizer(float theta) {
    return fmt::format(R"(<bsdf type="polarizer"><float name="theta" value="{}"/></bsdf>)", theta);
}

} // namespace

TEST(Polarization, MalusLawThroughTwoPolarizersOnTurnedSheets) {
    const std::string mode = "scalar_spectral_polarized";
    // The open scene: the same sheets, passing everything (same random numbers: a Null lobe
    // each).
    const std::vector<double> open = render_sheets(
        sheet(1.f, 0.f, "<bsdf type=\"null\"/>") + sheet(2.f, 0.f, "<bsdf type=\"null\"/>"), mode);
    ASSERT_GT(open[1], 0.5);
    // A polarizer's axis is its sheet's first tangent turned by −theta (theta turns it from u
    // towards −v), and the sheet turns it with itself: the light through both is ½·cos² of the
    // difference of (turn − theta).
    struct Case {
        float theta1, turn2, theta2;
    };
    for (const Case &c : {Case{0, 0, 0}, Case{0, 0, 30}, Case{0, 30, 0}, Case{20, 40, 50},
                          Case{0, 0, 90}, Case{10, 60, -25}}) {
        const double diff = deg((c.turn2 - c.theta2) - (0.f - c.theta1));
        const std::vector<double> m = render_sheets(
            sheet(1.f, 0.f, polarizer(c.theta1)) + sheet(2.f, c.turn2, polarizer(c.theta2)), mode);
        for (int ch = 0; ch < 3; ++ch)
            EXPECT_NEAR(m[size_t(ch)] / open[size_t(ch)], 0.5 * sqr(std::cos(diff)), 2e-5)
                << c.theta1 << " / " << c.turn2 << " + " << c.theta2 << " channel " << ch;
    }
    // Without polarisation the two sheets pass a quarter, whatever their angles.
    const std::vector<double> rgb_open = render_sheets(sheet(1.f, 0.f, "<bsdf type=\"null\"/>") +
                                                           sheet(2.f, 0.f, "<bsdf type=\"null\"/>"),
                                                       "scalar_spectral");
    const std::vector<double> crossed = render_sheets(
        sheet(1.f, 0.f, polarizer(0)) + sheet(2.f, 0.f, polarizer(90)), "scalar_spectral");
    EXPECT_NEAR(crossed[1] / rgb_open[1], 0.25, 1e-5);
}

TEST(Polarization, AQuarterWavePlateTurnsLinearLightCircular) {
    const std::string mode = "scalar_spectral_polarized";
    const std::string nulls = sheet(1.f, 0.f, "<bsdf type=\"null\"/>") +
                              sheet(2.f, 0.f, "<bsdf type=\"null\"/>") +
                              sheet(3.f, 0.f, "<bsdf type=\"null\"/>");
    const double open = render_sheets(nulls, mode)[1];
    // Light polarised at −45 degrees to the plate's fast axis (a polariser at theta = 45:
    // transmission axis (−cos θ, sin θ)), then a quarter-wave plate: right circular light, which
    // a right circular polariser passes whole and a left one stops.
    const std::string linear_then_plate =
        sheet(1.f, 0.f, polarizer(45)) +
        sheet(2.f, 0.f, R"(<bsdf type="retarder"><float name="delta" value="90"/></bsdf>)");
    const double right =
        render_sheets(linear_then_plate + sheet(3.f, 0.f, R"(<bsdf type="circular"/>)"), mode)[1];
    const double left = render_sheets(
        linear_then_plate +
            sheet(3.f, 0.f,
                  R"(<bsdf type="circular"><boolean name="left_handed" value="true"/></bsdf>)"),
        mode)[1];
    EXPECT_NEAR(right / open, 0.5, 2e-5);
    EXPECT_NEAR(left / open, 0.0, 2e-5);
    // Without the plate, linear light is half right and half left.
    const double no_plate =
        render_sheets(sheet(1.f, 0.f, polarizer(45)) + sheet(2.f, 0.f, "<bsdf type=\"null\"/>") +
                          sheet(3.f, 0.f, R"(<bsdf type="circular"/>)"),
                      mode)[1];
    EXPECT_NEAR(no_plate / open, 0.25, 2e-5);
}

TEST(Polarization, TheStokesIntegratorGivesTheComponentsInTheCamerasFrame) {
    const std::string mode = "scalar_spectral_polarized";
    const std::string integrator =
        R"(<integrator type="stokes"><integrator type="path"/></integrator>)";
    // Channels: R, G, B, then S0.R, S0.G, S0.B, S1.R, ... (the film may add A before them).
    auto components = [&](const std::string &sheets) {
        const std::vector<double> m = render_sheets(sheets, mode, integrator);
        const size_t first = m.size() - 12;
        std::array<double, 4> s{};
        for (int k = 0; k < 4; ++k) s[size_t(k)] = m[first + size_t(3 * k) + 1]; // G
        return s;
    };
    // The camera looks down −z with +y up: its horizontal axis is +x. A polariser at theta = 0
    // passes light along the sheet's x axis: S1 = S0. At 90: S1 = −S0. Its axis at theta is
    // (−cos θ, sin θ): theta = 45 passes the (−1, 1) diagonal, S2 = −S0.
    const auto h = components(sheet(1.f, 0.f, polarizer(0)));
    EXPECT_GT(h[0], 0.1);
    EXPECT_NEAR(h[1] / h[0], 1.0, 1e-4);
    EXPECT_NEAR(h[2] / h[0], 0.0, 1e-4);
    EXPECT_NEAR(h[3] / h[0], 0.0, 1e-4);
    const auto v = components(sheet(1.f, 0.f, polarizer(90)));
    EXPECT_NEAR(v[1] / v[0], -1.0, 1e-4);
    const auto d = components(sheet(1.f, 0.f, polarizer(45)));
    EXPECT_NEAR(d[1] / d[0], 0.0, 1e-4);
    EXPECT_NEAR(d[2] / d[0], -1.0, 1e-4);
    // Turned sheets turn the light: a sheet turned by 90 degrees with theta = 0 is vertical.
    const auto t = components(sheet(1.f, 90.f, polarizer(0)));
    EXPECT_NEAR(t[1] / t[0], -1.0, 1e-4);
    // Then a quarter-wave plate: right circular, S3 = S0.
    const auto c = components(
        sheet(1.f, 0.f, polarizer(45)) +
        sheet(2.f, 0.f, R"(<bsdf type="retarder"><float name="delta" value="90"/></bsdf>)"));
    EXPECT_NEAR(c[3] / c[0], 1.0, 1e-4);
    EXPECT_NEAR(c[1] / c[0], 0.0, 1e-4);
    // S0 is the image.
    const std::vector<double> m = render_sheets(sheet(1.f, 0.f, polarizer(0)), mode, integrator);
    EXPECT_NEAR(m[m.size() - 11], m[1], 1e-6);
}

TEST(Polarization, ATiltedGlassSlabTransmitsEachPolarisationOnItsOwn) {
    // Unpolarised light through a glass slab (η = 1.5) tilted by 60 degrees, with its internal
    // reflections: each polarisation x passes T_x²·Σ R_x^2k = (1 − R_x)/(1 + R_x), so the slab
    // passes ½ Σ_x (1 − R_x)/(1 + R_x) = 0.8481, where Fresnel's unpolarised average R̄ would
    // give (1 − R̄)/(1 + R̄) = 0.8362. The two faces' planes of incidence are the same plane in
    // the world, in different local frames: only consistent frame rotations keep s and p apart.
    const float c = std::cos(deg(60.f));
    const auto [fs, fp] = lecture_amplitudes(c, 1.0, 1.5);
    const double rs = fs * fs, rp = fp * fp, rm = 0.5 * (rs + rp);
    const double polarised = 0.5 * ((1 - rs) / (1 + rs) + (1 - rp) / (1 + rp));
    const double averaged = (1 - rm) / (1 + rm);
    ASSERT_GT(polarised - averaged, 0.01);
    // The upper face (towards the camera) faces up; the lower one faces down into the air.
    // What either face reflects leaves the view: the emitter is small enough for the light
    // reflected at 60 degrees to miss it.
    auto face = [](float z, bool down) {
        return fmt::format(R"(<shape type="rectangle">
            <transform name="to_world"><scale value="20"/>{}<rotate x="1" angle="60"/>
                <translate z="{}"/></transform>
            <bsdf type="dielectric"><float name="int_ior" value="1.5"/>
                <float name="ext_ior" value="1"/></bsdf>
        </shape>)",
                           down ? R"(<rotate x="1" angle="180"/>)" : "", z);
    };
    const std::string integrator = R"(<integrator type="path"><integer name="max_depth" value="64"/>
        <integer name="rr_depth" value="64"/></integrator>)";
    auto render_many = [&](const std::string &sheets, const std::string &mode) {
        // The emitter lies at z = 0; the slab between it and the camera.
        double sum = 0.0;
        for (int seed = 0; seed < 8; ++seed)
            sum += render_sheets(sheets, mode, integrator, 1024, seed)[1];
        return sum / 8.0;
    };
    const double open = render_many("", "scalar_spectral_polarized");
    const double slab =
        render_many(face(2.5f, false) + face(2.f, true), "scalar_spectral_polarized");
    // The spectral mode, without polarisation, gives the averaged figure; it draws the same
    // lobes with the same random numbers, so the difference of the two ratios is the
    // polarisation's alone, with little noise.
    const double spectral_open = render_many("", "scalar_spectral");
    const double spectral_slab =
        render_many(face(2.5f, false) + face(2.f, true), "scalar_spectral");
    EXPECT_NEAR(slab / open, polarised, 0.004) << "the unpolarised average gives " << averaged;
    EXPECT_NEAR(spectral_slab / spectral_open, averaged, 0.004);
    EXPECT_NEAR(slab / open - spectral_slab / spectral_open, polarised - averaged, 0.0006);
}

TEST(Polarization, TwoMirrorsChangeTheIntensityOfTheirLight) {
    // Unpolarised light reflected by two glass mirrors whose planes of incidence are
    // perpendicular: the first reflects r_s of s light and r_p of p light, which the second
    // sees swapped, so the pair passes r_s·r_p, not the unpolarised product ((r_s + r_p)/2)².
    // Checked at the Mueller level: the product of the two matrices in world frames.
    const float c = std::cos(deg(60.f));
    const auto [fs, fp] = lecture_amplitudes(c, 1.0, 1.5);
    const double rs = fs * fs, rp = fp * fp;
    const Mueller M = mueller::specular_reflection(c, 1.5f);
    // In s-frames, turning the plane of incidence by 90 degrees is rotator(90°) between them.
    const Mueller pair = M * mueller::rotator(deg(90.f)) * M;
    EXPECT_NEAR(pair.m[0][0].r, rs * rp, 1e-7);
    const Mueller parallel = M * M;
    EXPECT_NEAR(parallel.m[0][0].r, 0.5 * (rs * rs + rp * rp), 1e-7);
}

namespace {

std::shared_ptr<BSDF> load_bsdf(const std::string &xml) {
    LoadOptions opts;
    opts.mode = "scalar_spectral_polarized";
    auto bsdf = std::dynamic_pointer_cast<BSDF>(load_string(xml, opts));
    EXPECT_TRUE(bsdf) << xml;
    return bsdf;
}

double relative_error(float a, float b) {
    return std::abs(double(a) - double(b)) / std::max(1e-4, std::abs(double(b)));
}

} // namespace

TEST(Polarization, BSDFMatricesAgreeWithTheirColoursAndTheirDensities) {
    // For each BSDF that polarises, and the adapters around one: sample_polarized() takes the
    // same direction as sample() with the same density, its matrix's entry (0, 0) is sample()'s
    // weight, eval_pdf_polarized()'s is eval_pdf()'s value, and for glossy lobes the sampled
    // matrix is the evaluated one over the density.
    const std::string rough =
        R"(<bsdf type="roughconductor"><string name="material" value="Au"/><float name="alpha" value="0.3"/></bsdf>)";
    const std::vector<std::string> bsdfs = {
        R"(<bsdf version="3.0.0" type="conductor"><string name="material" value="Cu"/></bsdf>)",
        "<bsdf version=\"3.0.0\"" + rough.substr(5),
        R"(<bsdf version="3.0.0" type="roughconductor"><string name="distribution" value="beckmann"/>
            <float name="alpha_u" value="0.1"/><float name="alpha_v" value="0.4"/></bsdf>)",
        R"(<bsdf version="3.0.0" type="dielectric"><float name="int_ior" value="1.7"/></bsdf>)",
        "<bsdf version=\"3.0.0\" type=\"twosided\">" + rough + "</bsdf>",
        "<bsdf version=\"3.0.0\" type=\"blendbsdf\"><float name=\"weight\" value=\"0.3\"/>" +
            rough + "<bsdf type=\"diffuse\"/></bsdf>",
        "<bsdf version=\"3.0.0\" type=\"mask\"><float name=\"opacity\" value=\"0.6\"/>" + rough +
            "</bsdf>",
        R"(<bsdf version="3.0.0" type="polarizer"><float name="theta" value="30"/></bsdf>)",
        R"(<bsdf version="3.0.0" type="pplastic"><string name="distribution" value="ggx"/>
            <float name="alpha" value="0.2"/><rgb name="diffuse_reflectance" value="0.2, 0.5, 0.8"/></bsdf>)",
    };
    PCG32 rng(7);
    for (const std::string &xml : bsdfs) {
        const std::shared_ptr<BSDF> bsdf = load_bsdf(xml);
        ASSERT_TRUE(bsdf);
        EXPECT_TRUE(has_flag(bsdf->flags(), BSDFFlags::Polarizing)) << xml;
        int glossy = 0;
        for (int i = 0; i < 400; ++i) {
            SurfaceInteraction si;
            si.wavelengths = Wavelengths(450.f, 550.f, 650.f, 500.f);
            const float z = 0.05f + 0.95f * rng.next_float(), phi = 2.f * Pi * rng.next_float();
            const float r = std::sqrt(1.f - z * z);
            si.wi = Vector3f(r * std::cos(phi), r * std::sin(phi), i % 5 == 4 ? -z : z);
            const float s1 = rng.next_float();
            const Point2f s2(rng.next_float(), rng.next_float());
            const BSDFContext ctx;
            const auto [bs, weight] = bsdf->sample(ctx, si, s1, s2);
            const auto [pbs, pweight] = bsdf->sample_polarized(ctx, si, s1, s2);
            EXPECT_EQ(bs.wo, pbs.wo) << xml;
            EXPECT_EQ(bs.sampled_type, pbs.sampled_type) << xml;
            EXPECT_NEAR(bs.pdf, pbs.pdf, 1e-5f * bs.pdf) << xml;
            for (int c = 0; c < Color3f::Channels; ++c)
                EXPECT_LT(relative_error(pweight.m[0][0][c], weight[c]), 2e-4)
                    << xml << " sample " << i << " lane " << c;
            if (weight.is_black() || has_flag(bs.sampled_type, BSDFFlags::Delta)) continue;
            ++glossy;
            const auto [value, pdf] = bsdf->eval_pdf(ctx, si, bs.wo);
            const auto [pvalue, ppdf] = bsdf->eval_pdf_polarized(ctx, si, bs.wo);
            EXPECT_NEAR(pdf, ppdf, 1e-5f * pdf) << xml;
            for (int c = 0; c < Color3f::Channels; ++c)
                EXPECT_LT(relative_error(pvalue.m[0][0][c], value[c]), 2e-4) << xml;
            for (int a = 0; a < 4; ++a)
                for (int b = 0; b < 4; ++b)
                    EXPECT_NEAR(pweight.m[a][b].g, pvalue.m[a][b].g / ppdf,
                                2e-4f * pweight.m[0][0].g)
                        << xml << " entry " << a << ", " << b;
        }
        if (xml.find("rough") != std::string::npos) {
            EXPECT_GT(glossy, 100) << xml;
        }
    }
}

TEST(Polarization, EachMicrofacetReflectsAsASmoothInterfaceInItsOwnFrame) {
    // A microfacet BSDF's reflection matrix at (wi, wo), normalised by its (0, 0) entry, is the
    // smooth interface's for the mirror whose normal is h = (wi + wo)/|wi + wo|, taken from the
    // frame of h to the surface's frame: roughconductor against conductor, pplastic's glossy
    // lobe against the dielectric's reflection.
    BSDFContext reflection;
    reflection.component = 0;
    const std::vector<std::tuple<std::string, std::string, BSDFContext>> pairs = {
        {R"(<bsdf version="3.0.0" type="roughconductor"><string name="material" value="Au"/>
            <float name="alpha" value="0.4"/></bsdf>)",
         R"(<bsdf version="3.0.0" type="conductor"><string name="material" value="Au"/></bsdf>)",
         BSDFContext()},
        {R"(<bsdf version="3.0.0" type="pplastic"><float name="alpha" value="0.4"/></bsdf>)",
         R"(<bsdf version="3.0.0" type="dielectric"><float name="int_ior" value="1.49"/>
            <float name="ext_ior" value="1.000277"/></bsdf>)",
         reflection},
    };
    for (const auto &[rough_xml, smooth_xml, ctx] : pairs) {
        const std::shared_ptr<BSDF> rough = load_bsdf(rough_xml), smooth = load_bsdf(smooth_xml);
        ASSERT_TRUE(rough && smooth);
        PCG32 rng(11);
        int checked = 0;
        for (int i = 0; i < 200; ++i) {
            auto upper = [&]() {
                const float z = 0.1f + 0.9f * rng.next_float(), phi = 2.f * Pi * rng.next_float();
                const float r = std::sqrt(1.f - z * z);
                return Vector3f(r * std::cos(phi), r * std::sin(phi), z);
            };
            SurfaceInteraction si;
            si.wavelengths = Wavelengths(450.f, 550.f, 650.f, 500.f);
            si.wi = upper();
            const Vector3f wo = upper();
            const auto [M, pdf] = rough->eval_pdf_polarized(ctx, si, wo);
            if (M.is_black()) continue;
            const Frame fh(normalize(si.wi + wo));
            SurfaceInteraction hi = si;
            hi.wi = fh.to_local(si.wi);
            const auto [bs, S] = smooth->sample_polarized(ctx, hi, 0.f, Point2f(0.5f));
            ASSERT_LT(norm(fh.to_world(bs.wo) - wo), 1e-4f) << smooth_xml;
            const Mueller expected = mueller::to_world(fh, S, -bs.wo, hi.wi);
            for (int a = 0; a < 4; ++a)
                for (int b = 0; b < 4; ++b)
                    for (int lane = 0; lane < Color3f::Channels; ++lane)
                        EXPECT_NEAR(M.m[a][b][lane] / M.m[0][0][lane],
                                    expected.m[a][b][lane] / expected.m[0][0][lane], 2e-4)
                            << rough_xml << " entry " << a << ", " << b << " sample " << i;
            ++checked;
        }
        EXPECT_GT(checked, 150) << rough_xml;
    }
}

namespace {

/// The mean G of a 16x16 view of a diffuse floor lit through three sheets (the BSDFs `upper`,
/// `middle`, `lower`, in the order the light crosses them) by an area light above them, rendered
/// by `integrator` in the polarized mode.
double floor_through_sheets(const std::string &integrator, const std::string &upper,
                            const std::string &middle, const std::string &lower) {
    const std::string xml = fmt::format(R"(<scene version="3.0.0">
        <integrator type="{}"><integer name="max_depth" value="6"/></integrator>
        <sensor type="perspective">
            <float name="fov" value="30"/>
            <transform name="to_world"><lookat origin="0, -6, 1.5" target="0, 0, 0" up="0, 0, 1"/></transform>
            <sampler type="independent"><integer name="sample_count" value="512"/></sampler>
            <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/>
                <rfilter type="box"/></film>
        </sensor>
        <shape type="rectangle">
            <transform name="to_world"><scale value="3"/><rotate x="1" angle="180"/><translate z="4"/></transform>
            <emitter type="area"><spectrum name="radiance" value="1"/></emitter>
        </shape>
        <shape type="rectangle">
            <transform name="to_world"><scale value="8"/><translate z="3"/></transform>
            {}
        </shape>
        <shape type="rectangle">
            <transform name="to_world"><scale value="8"/><translate z="2.75"/></transform>
            {}
        </shape>
        <shape type="rectangle">
            <transform name="to_world"><scale value="8"/><translate z="2.5"/></transform>
            {}
        </shape>
        <shape type="rectangle">
            <transform name="to_world"><scale value="10"/></transform>
            <bsdf type="diffuse"/>
        </shape>
    </scene>)",
                                        integrator, upper, middle, lower);
    LoadOptions opts;
    opts.mode = "scalar_spectral_polarized";
    auto scene = std::dynamic_pointer_cast<Scene>(load_string(xml, opts));
    RenderOptions ro;
    ro.progress = false;
    const Image image = render(*scene, *scene->sensors().at(0), ro).image;
    double sum = 0.0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) sum += image.at(x, y, 1);
    return sum / double(image.width * image.height);
}

} // namespace

TEST(Polarization, LightTracingCarriesPolarisationLikeThePathTracer) {
    // The particle tracer follows the light from the emitter (importance mode: each BSDF's
    // matrix maps light from −wi to wo); the path tracer from the camera. Through two
    // polarizers at 60 degrees a floor gets about a quarter of the light of parallel ones
    // (cos² 60°, a little more for oblique light): both must see it, and agree.
    const std::string null = R"(<bsdf type="null"/>)";
    const double path_parallel = floor_through_sheets("path", polarizer(0), null, polarizer(0));
    const double path_crossed = floor_through_sheets("path", polarizer(0), null, polarizer(60));
    const double light_parallel = floor_through_sheets("ptracer", polarizer(0), null, polarizer(0));
    const double light_crossed = floor_through_sheets("ptracer", polarizer(0), null, polarizer(60));
    ASSERT_GT(path_parallel, 0.01);
    EXPECT_NEAR(path_crossed / path_parallel, 0.25, 0.03);
    EXPECT_NEAR(light_parallel / path_parallel, 1.0, 0.02);
    EXPECT_NEAR(light_crossed / path_crossed, 1.0, 0.03);
    // Linear light, a quarter-wave plate at 45 degrees to it, a circular polariser: the plate's
    // axis must turn the same way for light traced from either end (about all the light, or
    // none, passes the circular polariser, depending on the handedness).
    const std::string plate =
        R"(<bsdf type="retarder"><float name="theta" value="45"/><float name="delta" value="90"/></bsdf>)";
    for (const char *circular :
         {R"(<bsdf type="circular"/>)",
          R"(<bsdf type="circular"><boolean name="left_handed" value="true"/></bsdf>)"}) {
        const double path = floor_through_sheets("path", polarizer(0), plate, circular);
        const double light = floor_through_sheets("ptracer", polarizer(0), plate, circular);
        EXPECT_NEAR(light, path, 0.03 * path_parallel) << circular;
    }
}

TEST(Polarization, AGlassSphereInAUniformSkyIsTheSky) {
    // A furnace: a smooth glass sphere under a uniform, unpolarised sky. Reflection and
    // refraction conserve the intensity of light of any polarisation (the (0, 0) and (0, 1)
    // entries of their matrices sum to 1 and 0), so the sphere disappears: in the spectral mode
    // every path's weight is exactly 1, in the polarized mode it is 1 in expectation.
    auto render_centre = [](const std::string &mode, bool sphere) {
        const std::string xml =
            fmt::format(R"(<scene version="3.0.0">
            <integrator type="path"><integer name="max_depth" value="64"/>
                <integer name="rr_depth" value="64"/></integrator>
            <sensor type="orthographic">
                <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
                <sampler type="independent"><integer name="sample_count" value="256"/></sampler>
                <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/>
                    <rfilter type="box"/></film>
            </sensor>
            <emitter type="constant"><spectrum name="radiance" value="1"/></emitter>
            {}
        </scene>)",
                        sphere ? R"(<shape type="sphere"><float name="radius" value="0.9"/>
                <bsdf type="dielectric"><float name="int_ior" value="1.6"/></bsdf></shape>)"
                               : "");
        LoadOptions opts;
        opts.mode = mode;
        auto scene = std::dynamic_pointer_cast<Scene>(load_string(xml, opts));
        RenderOptions ro;
        ro.progress = false;
        const Image image = render(*scene, *scene->sensors().at(0), ro).image;
        // The centre of the image sees the sky through the sphere.
        double mean = 0.0;
        for (int y = 4; y < 12; ++y)
            for (int x = 4; x < 12; ++x) mean += image.at(x, y, 1) / 64.0;
        return mean;
    };
    for (const char *mode : {"scalar_spectral_polarized", "scalar_spectral"}) {
        const double ratio = render_centre(mode, true) / render_centre(mode, false);
        EXPECT_NEAR(ratio, 1.0, std::string(mode) == "scalar_spectral" ? 1e-4 : 0.01) << mode;
    }
}
