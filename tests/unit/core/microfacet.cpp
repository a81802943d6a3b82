// Microfacet distributions: normalisation of D, the visible-normal density, Smith G1 against the
// lecture's formulas, sampling for Beckmann and GGX, and the parameter reader.

#include "draws.h"

#include <facet/chi2.h> // direction_from_angles
#include <facet/microfacet.h>
#include <facet/properties.h>
#include <facet/random.h>
#include <facet/warp.h>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

using namespace facet;

namespace {

/// ∫ f(ω) dω over the upper hemisphere by the midpoint rule in (cos θ, φ), with cells refined
/// near the pole where microfacet distributions concentrate (cos θ = 1 − t², t uniform).
template <typename F> double integrate_hemisphere(F f, int n_t = 1500, int n_phi = 300) {
    double sum = 0.0;
    for (int i = 0; i < n_t; ++i) {
        double t = (i + 0.5) / n_t;
        double cos_theta = 1.0 - t * t, dcos = 2.0 * t / n_t;
        double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
        for (int j = 0; j < n_phi; ++j) {
            double phi = 2.0 * M_PI * (j + 0.5) / n_phi;
            Vector3f w(float(sin_theta * std::cos(phi)), float(sin_theta * std::sin(phi)),
                       float(cos_theta));
            sum += f(w) * dcos * (2.0 * M_PI / n_phi);
        }
    }
    return sum;
}

struct Config {
    MicrofacetType type;
    float alpha_u, alpha_v;
};

const Config CONFIGS[] = {
    {MicrofacetType::Beckmann, 0.1f, 0.1f},  {MicrofacetType::Beckmann, 0.5f, 0.5f},
    {MicrofacetType::Beckmann, 0.3f, 0.08f}, {MicrofacetType::GGX, 0.1f, 0.1f},
    {MicrofacetType::GGX, 0.5f, 0.5f},       {MicrofacetType::GGX, 0.05f, 0.4f},
};

std::string name_of(const Config &c) {
    return std::string(microfacet_type_name(c.type)) + " " + std::to_string(c.alpha_u) + "/" +
           std::to_string(c.alpha_v);
}

/// Exact Smith G1 for Beckmann with a = 1/(α tan θ): 2 / (1 + erf(a) + exp(−a²)/(a√π)).
double beckmann_g1_exact(double a) {
    return 2.0 / (1.0 + std::erf(a) + std::exp(-a * a) / (a * std::sqrt(M_PI)));
}

Properties
microfacet_props(std::initializer_list<std::pair<std::string, Properties::Value>> entries) {
    Properties props("roughconductor");
    for (const auto &[name, value] : entries) props.set(name, value);
    return props;
}

void expect_read_error(const Properties &props, const std::string &fragment) {
    try {
        read_microfacet(props);
        ADD_FAILURE() << "expected an error containing \"" << fragment << "\"";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
}

} // namespace

TEST(Microfacet, DistributionIntegratesToOneInProjectedArea) {
    // ∫ D(m) cos θm dω = 1: the microfacets' projected area is the macro surface's.
    for (const Config &c : CONFIGS) {
        MicrofacetDistribution distr(c.type, c.alpha_u, c.alpha_v);
        double integral =
            integrate_hemisphere([&](const Vector3f &m) { return double(distr.eval(m)) * m.z; });
        EXPECT_NEAR(integral, 1.0, 2e-3) << name_of(c);
    }
}

TEST(Microfacet, DistributionIsZeroBelowTheHorizon) {
    MicrofacetDistribution distr(MicrofacetType::GGX, 0.5f);
    EXPECT_EQ(distr.eval(Vector3f(0.f, 0.f, -1.f)), 0.f);
    EXPECT_EQ(distr.eval(normalize(Vector3f(1.f, 0.f, -0.1f))), 0.f);
    // Closed form at the pole: D(n) = 1/(π αu αv) for both.
    EXPECT_NEAR(distr.eval(Vector3f(0.f, 0.f, 1.f)), 1.f / (Pi * 0.25f), 1e-5f);
    MicrofacetDistribution beckmann(MicrofacetType::Beckmann, 0.2f, 0.4f);
    EXPECT_NEAR(beckmann.eval(Vector3f(0.f, 0.f, 1.f)), 1.f / (Pi * 0.08f), 1e-4f);
}

TEST(Microfacet, LectureBeckmannFormula) {
    // D(h) = exp(−tan²θ/m²) / (π m² cos⁴θ) for the isotropic case.
    MicrofacetDistribution distr(MicrofacetType::Beckmann, 0.3f);
    for (int i = 0; i < 20; ++i) {
        float theta = 0.07f * i, phi = 0.4f * i;
        Vector3f h(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                   std::cos(theta));
        double t = std::tan(theta), c = std::cos(theta), m2 = 0.09;
        double expected = std::exp(-t * t / m2) / (M_PI * m2 * c * c * c * c);
        EXPECT_NEAR(distr.eval(h), expected, 1e-4 * expected + 1e-6) << "theta " << theta;
    }
}

TEST(Microfacet, SmithG1MatchesTheLecture) {
    float alpha = 0.4f;
    MicrofacetDistribution beckmann(MicrofacetType::Beckmann, alpha);
    MicrofacetDistribution ggx(MicrofacetType::GGX, alpha);
    Vector3f m(0.f, 0.f, 1.f);
    for (int i = 1; i < 90; ++i) {
        double theta = i * M_PI / 180.0;
        Vector3f v(float(std::sin(theta)), 0.f, float(std::cos(theta)));
        double a = 1.0 / (alpha * std::tan(theta));
        // The lecture's rational approximation (Walter), exactly.
        double rational =
            a < 1.6 ? (3.535 * a + 2.181 * a * a) / (1 + 2.276 * a + 2.577 * a * a) : 1.0;
        EXPECT_NEAR(beckmann.smith_g1(v, m), rational, 2e-5) << "theta " << i;
        // Which is within 0.35 % of the exact Smith function, used to normalise visible normals.
        EXPECT_NEAR(beckmann.smith_g1(v, m), beckmann_g1_exact(a), 0.0035 * beckmann_g1_exact(a))
            << "theta " << i;
        EXPECT_NEAR(beckmann.visible_normalization(v), beckmann_g1_exact(a), 1e-5) << "theta " << i;
        EXPECT_EQ(ggx.visible_normalization(v), ggx.smith_g1(v, m));
        // GGX: 2 / (1 + √(1 + α² tan²θ)).
        double ggx_exact = 2.0 / (1.0 + std::sqrt(1.0 + 1.0 / (a * a)));
        EXPECT_NEAR(ggx.smith_g1(v, m), ggx_exact, 2e-6) << "theta " << i;
    }
    // χ⁺: a facet seen from behind is masked; normal incidence is never masked.
    Vector3f v = normalize(Vector3f(1.f, 0.f, 0.3f));
    Vector3f back_facing = normalize(Vector3f(-1.f, 0.f, 0.2f));
    EXPECT_EQ(beckmann.smith_g1(v, back_facing), 0.f);
    EXPECT_EQ(ggx.smith_g1(v, back_facing), 0.f);
    EXPECT_EQ(ggx.smith_g1(Vector3f(0.f, 0.f, 1.f), m), 1.f);
    EXPECT_FLOAT_EQ(ggx.G(v, v, m), sqr(ggx.smith_g1(v, m)));
}

TEST(Microfacet, AnisotropicMaskingUsesTheProjectedRoughness) {
    PCG32 rng(5);
    for (MicrofacetType type : {MicrofacetType::Beckmann, MicrofacetType::GGX}) {
        MicrofacetDistribution aniso(type, 0.1f, 0.6f);
        for (int i = 0; i < 100; ++i) {
            Vector3f v = warp::square_to_uniform_hemisphere(next_point2f(rng));
            float alpha = aniso.project_roughness(v);
            float phi = std::atan2(v.y, v.x);
            EXPECT_NEAR(sqr(alpha), sqr(std::cos(phi) * 0.1f) + sqr(std::sin(phi) * 0.6f), 1e-5f);
            MicrofacetDistribution iso(type, alpha);
            EXPECT_NEAR(aniso.smith_g1(v, Vector3f(0.f, 0.f, 1.f)),
                        iso.smith_g1(v, Vector3f(0.f, 0.f, 1.f)), 1e-5f);
        }
    }
}

TEST(SlowMicrofacet, VisibleNormalDensityIntegratesToOne) {
    // ∫ G1(wi) max(0, wi·m) D(m) / cos θi dm = 1 with the exact Smith G1 of each distribution.
    for (const Config &c : CONFIGS) {
        MicrofacetDistribution distr(c.type, c.alpha_u, c.alpha_v, true);
        for (float theta_deg : {0.f, 30.f, 60.f, 85.f}) {
            Vector3f wi = direction_from_angles(theta_deg, 40.f);
            double integral =
                integrate_hemisphere([&](const Vector3f &m) { return double(distr.pdf(wi, m)); });
            EXPECT_NEAR(integral, 1.0, 2e-3) << name_of(c) << " theta " << theta_deg;
        }
    }
}

TEST(Microfacet, SampleReturnsItsPdf) {
    PCG32 rng(9);
    for (const Config &c : CONFIGS) {
        for (bool visible : {false, true}) {
            MicrofacetDistribution distr(c.type, c.alpha_u, c.alpha_v, visible);
            int ok = 0;
            for (int i = 0; i < 2000; ++i) {
                Vector3f wi = warp::square_to_uniform_hemisphere(next_point2f(rng));
                auto [m, pdf] = distr.sample(wi, next_point2f(rng));
                if (pdf == 0.f) continue;
                ASSERT_TRUE(is_finite(m));
                EXPECT_NEAR(norm(m), 1.f, 1e-5f);
                EXPECT_GT(m.z, 0.f);
                EXPECT_NEAR(pdf, distr.pdf(wi, m), 1e-4f * pdf) << name_of(c);
                if (visible) {
                    EXPECT_GT(dot(wi, m), 0.f) << name_of(c);
                }
                ++ok;
            }
            EXPECT_GT(ok, 1990) << name_of(c) << (visible ? " visible" : " all");
        }
    }
}

// Chi-square of normal sampling against pdf() (Mitsuba's test matrix): the microfacet lines of
// tests/chi2/configs.txt.

TEST(MicrofacetSampling, VisibleNormalsAreSeenFromWi) {
    // Every normal drawn by visible sampling faces wi, and at grazing incidence the normals
    // lean towards wi (those facing away are hidden).
    for (MicrofacetType type : {MicrofacetType::Beckmann, MicrofacetType::GGX}) {
        MicrofacetDistribution distr(type, 0.5f, 0.5f, true);
        Vector3f wi = direction_from_angles(85.f, 0.f);
        PCG32 rng(2);
        double mean_x = 0.0;
        for (int i = 0; i < 20000; ++i) {
            auto [m, pdf] = distr.sample(wi, next_point2f(rng));
            ASSERT_GT(pdf, 0.f);
            ASSERT_GT(dot(wi, m), 0.f);
            mean_x += m.x;
        }
        EXPECT_GT(mean_x / 20000, 0.1) << microfacet_type_name(type);
    }
}

TEST(MicrofacetParameters, ReadsMitsubaParameters) {
    Properties defaults("roughconductor");
    MicrofacetParameters p = read_microfacet(defaults);
    EXPECT_EQ(p.type(), MicrofacetType::Beckmann);
    EXPECT_TRUE(p.sample_visible());
    EXPECT_FALSE(p.is_anisotropic());
    EXPECT_FALSE(p.is_spatially_varying());
    SurfaceInteraction si;
    MicrofacetDistribution d = p.at(si);
    EXPECT_FLOAT_EQ(d.alpha_u(), 0.1f);
    EXPECT_FLOAT_EQ(d.alpha_v(), 0.1f);

    Properties aniso = microfacet_props({{"distribution", std::string("ggx")},
                                         {"alpha_u", 0.2},
                                         {"alpha_v", 0.05},
                                         {"sample_visible", false}});
    p = read_microfacet(aniso);
    EXPECT_EQ(p.type(), MicrofacetType::GGX);
    EXPECT_FALSE(p.sample_visible());
    EXPECT_TRUE(p.is_anisotropic());
    d = p.at(si);
    EXPECT_FLOAT_EQ(d.alpha_u(), 0.2f);
    EXPECT_FLOAT_EQ(d.alpha_v(), 0.05f);
    EXPECT_TRUE(aniso.unqueried().empty());

    // Equal alpha_u and alpha_v are isotropic.
    EXPECT_FALSE(
        read_microfacet(microfacet_props({{"alpha_u", 0.3}, {"alpha_v", 0.3}})).is_anisotropic());

    // Tiny roughness is clamped to 1e-4.
    Properties zero = microfacet_props({{"alpha", 0.0}});
    EXPECT_FLOAT_EQ(read_microfacet(zero).at(si).alpha(), MicrofacetDistribution::MinAlpha);
}

TEST(MicrofacetParameters, RejectsBadParameters) {
    expect_read_error(microfacet_props({{"distribution", std::string("phong")}}),
                      "distribution must be beckmann or ggx");
    expect_read_error(microfacet_props({{"distribution", std::string("GGX ")}}),
                      "distribution must be beckmann or ggx");
    expect_read_error(microfacet_props({{"alpha", 0.1}, {"alpha_u", 0.2}, {"alpha_v", 0.2}}),
                      "either alpha or both alpha_u and alpha_v");
    expect_read_error(microfacet_props({{"alpha", 0.1}, {"alpha_v", 0.2}}),
                      "either alpha or both alpha_u and alpha_v");
    expect_read_error(microfacet_props({{"alpha_u", 0.2}}), "found only alpha_u");
    expect_read_error(microfacet_props({{"alpha_v", 0.2}}), "found only alpha_v");
    expect_read_error(microfacet_props({{"alpha", -0.1}}), "alpha must be a roughness >= 0");
    expect_read_error(microfacet_props({{"alpha", std::string("rough")}}), "alpha");

    // Numbers only where textures are not allowed.
    Properties textured("roughplastic");
    textured.set_object("alpha", std::make_shared<ConstantTexture>(Color3f(0.2f)));
    EXPECT_THROW(read_microfacet(textured, 0.1f, false), Error);
    EXPECT_NO_THROW(read_microfacet(textured, 0.1f, true));
}

namespace {

/// The density of the normal that all-normals sampling draws for u, in double precision from u
/// by the inverse-CDF formulas (REFERENCE §4), so that no float rounding of the normal enters.
double pdf_from_u(const MicrofacetDistribution &distr, const Point2f &u) {
    const double au = distr.alpha_u(), av = distr.alpha_v();
    const bool ggx = distr.type() == MicrofacetType::GGX;
    double phi, alpha_2;
    if (au == av) {
        phi = 2.0 * M_PI * u.y;
        alpha_2 = au * au;
    } else {
        phi = std::atan(av / au * std::tan(2.0 * M_PI * u.y));
        if (std::abs(u.y - 0.5) < 0.25) phi += M_PI;
        alpha_2 = 1.0 / ((std::cos(phi) / au) * (std::cos(phi) / au) +
                         (std::sin(phi) / av) * (std::sin(phi) / av));
    }
    double tan_2 = ggx ? alpha_2 * u.x / (1.0 - u.x) : -alpha_2 * std::log1p(-double(u.x));
    double cos_3 = std::pow(1.0 + tan_2, -1.5);
    return ggx ? 1.0 / (M_PI * au * av * cos_3 * (1.0 + tan_2 / alpha_2) * (1.0 + tan_2 / alpha_2))
               : std::exp(-tan_2 / alpha_2) / (M_PI * au * av * cos_3);
}

/// pdf(wi, m) of the direction of m in double precision (D, the exact visible normalisation,
/// wi·m), for visible-normal sampling, whose float chain from u to m is itself ill-conditioned
/// near the horizon of the normals: there the density must be that of the normal returned.
double pdf_of_direction(const MicrofacetDistribution &distr, const Vector3f &wi_f,
                        const Vector3f &m_f) {
    double n = std::sqrt(double(m_f.x) * m_f.x + double(m_f.y) * m_f.y + double(m_f.z) * m_f.z);
    double mx = m_f.x / n, my = m_f.y / n, mz = m_f.z / n;
    double au = distr.alpha_u(), av = distr.alpha_v();
    double e = (mx / au) * (mx / au) + (my / av) * (my / av), c2 = mz * mz;
    double D = distr.type() == MicrofacetType::Beckmann
                   ? std::exp(-e / c2) / (M_PI * au * av * c2 * c2)
                   : 1.0 / (M_PI * au * av * (e + c2) * (e + c2));
    double wx = wi_f.x, wy = wi_f.y, wz = wi_f.z;
    double t = ((au * wx) * (au * wx) + (av * wy) * (av * wy)) / (wz * wz);
    double g1 = 1.0;
    if (t > 0.0)
        g1 = distr.type() == MicrofacetType::GGX ? 2.0 / (1.0 + std::sqrt(1.0 + t))
                                                 : beckmann_g1_exact(1.0 / std::sqrt(t));
    return D * g1 * std::max(0.0, wx * mx + wy * my + wz * mz) / wz;
}

} // namespace

TEST(MicrofacetSampling, SampledPdfMatchesDoublePrecision) {
    // sample() computes the density from tan²θ of the normal it draws (from the slope, for
    // visible normals), not from that normal rebuilt in float: rebuilt, cos θm is rounded and
    // D(m) inherits the rounding amplified (1.7e-4 relative for GGX all-normals sampling at
    // α = 0.05). Checked against the density of the same draw in double precision, for incident
    // directions down to cos θi = 0.05.
    struct Case {
        MicrofacetType type;
        float alpha_u, alpha_v;
        bool visible;
    };
    for (const Case &c :
         {Case{MicrofacetType::GGX, 0.5f, 0.5f, false}, Case{MicrofacetType::GGX, 0.5f, 0.5f, true},
          Case{MicrofacetType::GGX, 0.45f, 0.55f, false},
          Case{MicrofacetType::GGX, 0.45f, 0.55f, true},
          Case{MicrofacetType::GGX, 0.05f, 0.05f, false},
          Case{MicrofacetType::GGX, 0.05f, 0.05f, true},
          Case{MicrofacetType::Beckmann, 0.5f, 0.5f, false},
          Case{MicrofacetType::Beckmann, 0.05f, 0.05f, false},
          Case{MicrofacetType::Beckmann, 0.5f, 0.5f, true}}) {
        MicrofacetDistribution distr(c.type, c.alpha_u, c.alpha_v, c.visible);
        std::string name =
            name_of(Config{c.type, c.alpha_u, c.alpha_v}) + (c.visible ? " visible" : " all");
        PCG32 rng(21);
        double worst = 0.0;
        int checked = 0;
        for (int i = 0; i < 200000; ++i) {
            Vector3f wi = warp::square_to_uniform_hemisphere(next_point2f(rng));
            Point2f u = next_point2f(rng);
            if (wi.z < 0.05f) continue;
            auto [m, pdf] = distr.sample(wi, u);
            if (pdf == 0.f) continue;
            double ref = c.visible ? pdf_of_direction(distr, wi, m) : pdf_from_u(distr, u);
            if (ref < 1e-3) continue; // far in the tail, where relative errors are moot
            worst = std::max(worst, std::abs(double(pdf) - ref) / ref);
            ++checked;
        }
        EXPECT_GT(checked, 150000) << name;
        EXPECT_LT(worst, 2e-5) << name << ": worst relative error of the sampled pdf";
    }
}

TEST(MicrofacetSampling, BeckmannVisibleSlopeInvertsItsCdf) {
    // sample_visible_11() inverts the CDF of the x slope of Beckmann's visible normals,
    // C(x̃) = 1 + erf(x̃) + tanθ/√π·exp(−x̃²) (normalised by its value at cot θ), by Newton steps
    // from a tabulated start (middle of u) or from the grazing-angle inverse (tails). The CDF of
    // the slope it returns, in double, must be u to a float's precision: within 2e-6 (the
    // sampler's own rounding gives up to 1.2e-6 near normal incidence), 1e-5 in the outer 1e-4 of
    // the tails (where X = erf(x̃) is held 1e-6 inside −1). A start off by the table's own
    // interpolation error (up to 4e-4) without its Newton step fails.
    MicrofacetDistribution distr(MicrofacetType::Beckmann, 1.f, 1.f, true);
    double worst = 0.0;
    int count = 0;
    for (double cos_theta : {0.002, 0.02, 0.1, 0.3, 0.5, 0.7, 0.85, 0.95, 0.99, 0.999, 0.99999}) {
        const double sin_theta = std::sqrt(1.0 - cos_theta * cos_theta);
        const double tan_theta = sin_theta / cos_theta, cot_theta = cos_theta / sin_theta;
        const double k = tan_theta / std::sqrt(M_PI);
        auto cdf = [&](double x) { return 1.0 + std::erf(x) + k * std::exp(-x * x); };
        const double total = cdf(cot_theta);
        for (int j = 0; j <= 4000; ++j) {
            // Even steps, then the ends at finer steps (the tails take another start).
            float u = j <= 2000 ? float(j) / 2000.f : float(j - 2000) / 2000.f * 0.04f;
            if (j > 2000 && (j & 1)) u = 1.f - u;
            u = std::clamp(u, 1e-6f, 1.f - 1e-6f); // the function's own clamp
            const Point2f slope = distr.sample_visible_11(float(cos_theta), Point2f(u, 0.5f));
            ASSERT_TRUE(std::isfinite(slope.x)) << cos_theta << " " << u;
            const double error = std::abs(cdf(std::min(double(slope.x), cot_theta)) / total - u);
            worst = std::max(worst, error);
            const bool tail = u < 1e-4f || u > 1.f - 1e-4f;
            EXPECT_LT(error, tail ? 1e-5 : 2e-6)
                << "cos θ " << cos_theta << ", u " << u << ": slope " << slope.x;
            ++count;
        }
    }
    EXPECT_EQ(count, 11 * 4001);
    RecordProperty("worst_cdf_error", fmt::format("{:.3g}", worst));
}

TEST(MicrofacetSampling, BeckmannShortcutsAreExact) {
    // visible_normalization() returns 1 without erf and exp for α² tan²θ up to
    // BeckmannUnmaskedTan2, and sample_visible_11() takes its bounds without them from cot θ = 4
    // on: the full float expressions must give those values to the last bit there (every
    // float of cos θ; of α² tan²θ every 64th).
    const float InvSqrtPi = 0.56418958354775628f;
    int checked = 0;
    for (float t = std::numeric_limits<float>::min();
         t <= MicrofacetDistribution::BeckmannUnmaskedTan2;) {
        const float a = 1.f / std::sqrt(t);
        const float full = 2.f / (1.f + std::erf(a) + std::exp(-a * a) * InvSqrtPi / a);
        ASSERT_EQ(full, 1.f) << "α² tan²θ " << t;
        uint32_t bits;
        std::memcpy(&bits, &t, sizeof bits);
        bits += 64;
        std::memcpy(&t, &bits, sizeof bits);
        ++checked;
    }
    EXPECT_GT(checked, 15000000);
    checked = 0;
    for (float c = 4.f / std::sqrt(17.f); c < 1.f; c = std::nextafter(c, 2.f)) {
        const float sin_theta = std::sqrt(std::max(1.f - c * c, 0.f));
        const float tan_theta = sin_theta / c, cot_theta = c / sin_theta;
        if (!(cot_theta >= 4.f) || !(tan_theta > 1e-4f)) continue;
        const float x_max = std::min(std::erf(cot_theta), 1.f - 1e-6f);
        ASSERT_EQ(x_max, 1.f - 1e-6f) << "cos θ " << c;
        ASSERT_EQ(1.f + x_max + InvSqrtPi * tan_theta * std::exp(-sqr(cot_theta)),
                  1.f + (1.f - 1e-6f))
            << "cos θ " << c;
        ++checked;
    }
    EXPECT_GT(checked, 400000);
}
