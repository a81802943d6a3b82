// Closed forms away from normal incidence for every BSDF with a Fresnel term: each check fails
// when the plugin takes Fresnel at the wrong angle (at normal incidence, or at the macro normal
// where the microfacet normal belongs). The expected values come from this file's own
// double-precision Fresnel equations and microfacet terms, not from facet's headers:
// - smooth plugins: the weight of each delta lobe at θi = 30°, 60°, 80°;
// - rough plugins with α = 0.001: the mean sample weight of each lobe tends to the smooth lobe's
//   Fresnel term at the same angles;
// - rough plugins with α = 0.3: eval() at off-specular directions against F(wi·h)·D·G/(4 cos θi)
//   (and Walter et al.'s transmission lobe), where wi·h differs from cos θi by tens of degrees.

#include "bsdf_checks.h"

#include <complex>

using namespace facet;
using namespace bsdf_checks;

namespace {

constexpr double PiD = 3.14159265358979323846;
const double AnglesDeg[] = {30.0, 60.0, 80.0};

/// Unpolarised reflectance of a dielectric interface for light arriving at cos_i > 0 from the
/// side of index 1 onto index eta (Born & Wolf's amplitude coefficients).
double ref_fresnel_dielectric(double cos_i, double eta) {
    double sin_t_2 = (1.0 - cos_i * cos_i) / (eta * eta);
    if (sin_t_2 >= 1.0) return 1.0;
    double cos_t = std::sqrt(1.0 - sin_t_2);
    double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    double rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

/// The same for a conductor with complex index eta + i·k (complex Snell's law).
double ref_fresnel_conductor(double cos_i, double eta, double k) {
    std::complex<double> n(eta, k);
    std::complex<double> cos_t = std::sqrt(1.0 - (1.0 - cos_i * cos_i) / (n * n));
    std::complex<double> rs = (cos_i - n * cos_t) / (cos_i + n * cos_t);
    std::complex<double> rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
    return 0.5 * (std::norm(rs) + std::norm(rp));
}

struct V3 {
    double x, y, z;
};
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator*(V3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 unit(V3 a) { return a * (1.0 / std::sqrt(dot(a, a))); }
V3 spherical(double theta_deg, double phi_deg) {
    double t = theta_deg * PiD / 180.0, p = phi_deg * PiD / 180.0;
    return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}
Vector3f to_float(V3 v) { return Vector3f(float(v.x), float(v.y), float(v.z)); }

/// Isotropic GGX normal distribution and Smith masking (Walter et al. 2007, eq. 33 and 34).
double ref_ggx_D(V3 m, double alpha) {
    if (m.z <= 0.0) return 0.0;
    double a2 = alpha * alpha;
    double t = (m.x * m.x + m.y * m.y) / a2 + m.z * m.z;
    return 1.0 / (PiD * a2 * t * t);
}
double ref_ggx_G1(V3 v, V3 m, double alpha) {
    if (dot(v, m) * v.z <= 0.0) return 0.0;
    double tan_2 = (v.x * v.x + v.y * v.y) / (v.z * v.z);
    return 2.0 / (1.0 + std::sqrt(1.0 + alpha * alpha * tan_2));
}

/// The smooth references' directions: wi at θ in the xz-plane.
Vector3f incident(double theta_deg) { return to_float(spherical(theta_deg, 0.0)); }

/// Off-specular outgoing directions for the pointwise checks (the half vector then makes angles
/// with wi quite unlike θi).
const double OutgoingDeg[][2] = {{10.0, 90.0}, {45.0, 180.0}, {40.0, 30.0}, {70.0, 150.0}};

void expect_rel(double value, double expected, double rel, const std::string &what) {
    EXPECT_NEAR(value, expected, rel * std::abs(expected) + 1e-7) << what;
}

std::string at(double theta) { return " at theta_i = " + std::to_string(int(theta)) + " deg"; }

/// The weight of the lobe `component` sampled alone at incidence θ (smooth BSDFs: one sample).
Color3f delta_weight(const BSDF &bsdf, uint32_t component, Vector3f wi) {
    SurfaceInteraction si = make_si(wi);
    auto [bs, weight] = bsdf.sample(component_ctx(component), si, 0.5f, Point2f(0.5f, 0.5f));
    EXPECT_TRUE(has_flag(bs.sampled_type, BSDFFlags::Delta));
    return weight;
}

const double Eta = 1.5;                             // dielectric interfaces
const double CondEta = 1.2, CondK = 2.6;            // a conductor with a marked angle dependence
const double AlphaSmooth = 0.001, AlphaRough = 0.3; // near-smooth and rough lobes

} // namespace

TEST(OffNormalFresnel, ConductorWeightIsFresnelAtTheIncidentAngle) {
    auto bsdf = make_bsdf("conductor", {{"eta", CondEta}, {"k", CondK}});
    for (double theta : AnglesDeg) {
        double F = ref_fresnel_conductor(std::cos(theta * PiD / 180.0), CondEta, CondK);
        Color3f w = delta_weight(*bsdf, 0, incident(theta));
        for (int c = 0; c < 3; ++c) expect_rel(w[c], F, 1e-4, "conductor" + at(theta));
    }
}

TEST(OffNormalFresnel, DielectricLobesCarryFresnelAtTheIncidentAngle) {
    auto bsdf = make_bsdf("dielectric", {{"int_ior", Eta}, {"ext_ior", 1.0}});
    for (double theta : AnglesDeg) {
        double F = ref_fresnel_dielectric(std::cos(theta * PiD / 180.0), Eta);
        expect_rel(delta_weight(*bsdf, 0, incident(theta)).g, F, 1e-4,
                   "dielectric reflection" + at(theta));
        // Radiance refracted into the denser side is compressed by 1/η².
        expect_rel(delta_weight(*bsdf, 1, incident(theta)).g, (1.0 - F) / (Eta * Eta), 1e-4,
                   "dielectric transmission" + at(theta));
        // With both lobes, each is chosen with its Fresnel probability.
        SurfaceInteraction si = make_si(incident(theta));
        auto [bs, weight] = bsdf->sample(BSDFContext(), si, 0.f, Point2f(0.5f, 0.5f));
        EXPECT_TRUE(has_flag(bs.sampled_type, BSDFFlags::DeltaReflection));
        expect_rel(bs.pdf, F, 1e-4, "dielectric reflection probability" + at(theta));
    }
    // From the dense side, below the critical angle (41.8°): the inverse relative index.
    for (double theta : {20.0, 35.0, 40.0}) {
        double F = ref_fresnel_dielectric(std::cos(theta * PiD / 180.0), 1.0 / Eta);
        Vector3f wi = incident(theta);
        wi.z = -wi.z;
        expect_rel(delta_weight(*bsdf, 0, wi).g, F, 1e-4, "dielectric inside" + at(theta));
    }
}

TEST(OffNormalFresnel, ThinDielectricSlabReflectsItsFresnelSeries) {
    // A non-absorbing slab: R = F + (1 − F)²·F/(1 − F²) = 2F/(1 + F), with F at θi.
    auto bsdf = make_bsdf("thindielectric", {{"int_ior", Eta}, {"ext_ior", 1.0}});
    for (double theta : AnglesDeg) {
        double F = ref_fresnel_dielectric(std::cos(theta * PiD / 180.0), Eta);
        double R = 2.0 * F / (1.0 + F);
        expect_rel(delta_weight(*bsdf, 0, incident(theta)).g, R, 1e-4,
                   "thindielectric reflection" + at(theta));
        expect_rel(delta_weight(*bsdf, 1, incident(theta)).g, 1.0 - R, 1e-4,
                   "thindielectric transmission" + at(theta));
    }
}

TEST(OffNormalFresnel, PlasticSpecularAndDiffuseFollowFresnelAtTheirAngles) {
    auto bsdf = make_bsdf("plastic", {{"int_ior", Eta}, {"ext_ior", 1.0}});
    const double F0 = ref_fresnel_dielectric(1.0, Eta);
    const Vector3f normal(0.f, 0.f, 1.f);
    for (double theta : AnglesDeg) {
        double F = ref_fresnel_dielectric(std::cos(theta * PiD / 180.0), Eta);
        expect_rel(delta_weight(*bsdf, 0, incident(theta)).g, F, 1e-4,
                   "plastic specular" + at(theta));
        // The diffuse lobe carries (1 − F(θi))·(1 − F(θo)); its ratio to the same lobe seen
        // from the normal cancels the base's albedo and internal reflections.
        Vector3f wo = to_float(spherical(50.0, 120.0));
        SurfaceInteraction si = make_si(incident(theta)), si_n = make_si(normal);
        double ratio = bsdf->eval(BSDFContext(), si, wo).g / bsdf->eval(BSDFContext(), si_n, wo).g;
        expect_rel(ratio, (1.0 - F) / (1.0 - F0), 1e-4, "plastic diffuse, incident" + at(theta));
        // ... and symmetrically for the outgoing direction.
        si = make_si(to_float(spherical(50.0, 120.0)));
        ratio = bsdf->eval(BSDFContext(), si, incident(theta)).g /
                bsdf->eval(BSDFContext(), si, normal).g;
        double cos_ratio = std::cos(theta * PiD / 180.0);
        expect_rel(ratio, cos_ratio * (1.0 - F) / (1.0 - F0), 1e-4,
                   "plastic diffuse, outgoing" + at(theta));
    }
}

// Near-smooth rough plugins: every sampled normal is within a few α of the macro normal, so the
// mean weight of a lobe is its smooth Fresnel term at θi (G1 ≈ 1 at α = 0.001 up to 80°).

TEST(OffNormalFresnel, NearSmoothRoughConductorMatchesTheSmoothFresnel) {
    for (const char *distribution : {"beckmann", "ggx"}) {
        auto bsdf = make_bsdf("roughconductor", {{"eta", CondEta},
                                                 {"k", CondK},
                                                 {"alpha", AlphaSmooth},
                                                 {"distribution", std::string(distribution)}});
        for (double theta : AnglesDeg) {
            double F = ref_fresnel_conductor(std::cos(theta * PiD / 180.0), CondEta, CondK);
            Color3f albedo = furnace(*bsdf, BSDFContext(), incident(theta), 4000);
            expect_rel(albedo.g, F, 2e-3,
                       std::string("roughconductor ") + distribution + at(theta));
        }
    }
}

TEST(OffNormalFresnel, NearSmoothRoughDielectricMatchesTheSmoothFresnel) {
    for (const char *distribution : {"beckmann", "ggx"}) {
        auto bsdf = make_bsdf("roughdielectric", {{"int_ior", Eta},
                                                  {"ext_ior", 1.0},
                                                  {"alpha", AlphaSmooth},
                                                  {"distribution", std::string(distribution)}});
        for (double theta : AnglesDeg) {
            double F = ref_fresnel_dielectric(std::cos(theta * PiD / 180.0), Eta);
            std::string what = std::string("roughdielectric ") + distribution + at(theta);
            // furnace() undoes the radiance compression of refraction (η²).
            expect_rel(furnace(*bsdf, component_ctx(0), incident(theta), 4000).g, F, 2e-3,
                       what + ", reflection");
            expect_rel(furnace(*bsdf, component_ctx(1), incident(theta), 4000).g, 1.0 - F, 2e-3,
                       what + ", transmission");
        }
    }
}

TEST(OffNormalFresnel, NearSmoothRoughPlasticMatchesTheSmoothFresnel) {
    auto bsdf = make_bsdf("roughplastic", {{"int_ior", Eta},
                                           {"ext_ior", 1.0},
                                           {"alpha", AlphaSmooth},
                                           {"distribution", std::string("ggx")}});
    const double F0 = ref_fresnel_dielectric(1.0, Eta);
    const Vector3f normal(0.f, 0.f, 1.f);
    for (double theta : AnglesDeg) {
        double F = ref_fresnel_dielectric(std::cos(theta * PiD / 180.0), Eta);
        expect_rel(furnace(*bsdf, component_ctx(0), incident(theta), 4000).g, F, 2e-3,
                   "roughplastic specular" + at(theta));
        // The diffuse lobe carries the coating's transmittance T(θi) → 1 − F(θi) (a table
        // interpolated in cos θ, hence the looser tolerance).
        Vector3f wo = to_float(spherical(50.0, 120.0));
        SurfaceInteraction si = make_si(incident(theta)), si_n = make_si(normal);
        BSDFContext diffuse = component_ctx(1);
        double ratio = bsdf->eval(diffuse, si, wo).g / bsdf->eval(diffuse, si_n, wo).g;
        expect_rel(ratio, (1.0 - F) / (1.0 - F0), 5e-3, "roughplastic diffuse" + at(theta));
    }
}

// Rough lobes (α = 0.3, GGX): eval() pointwise against the lobe built here.

TEST(OffNormalFresnel, RoughConductorTakesFresnelAtTheMicrofacetNormal) {
    auto bsdf = make_bsdf("roughconductor", {{"eta", CondEta},
                                             {"k", CondK},
                                             {"alpha", AlphaRough},
                                             {"distribution", std::string("ggx")}});
    for (double theta : AnglesDeg) {
        V3 wi = spherical(theta, 0.0);
        for (const auto &o : OutgoingDeg) {
            V3 wo = spherical(o[0], o[1]), h = unit(wi + wo);
            double F = ref_fresnel_conductor(dot(wi, h), CondEta, CondK);
            double expected = F * ref_ggx_D(h, AlphaRough) * ref_ggx_G1(wi, h, AlphaRough) *
                              ref_ggx_G1(wo, h, AlphaRough) / (4.0 * wi.z);
            SurfaceInteraction si = make_si(to_float(wi));
            Color3f value = bsdf->eval(BSDFContext(), si, to_float(wo));
            expect_rel(value.g, expected, 1e-4,
                       "roughconductor, theta_o = " + std::to_string(int(o[0])) + at(theta));
        }
    }
}

TEST(OffNormalFresnel, RoughDielectricTakesFresnelAtTheMicrofacetNormal) {
    auto bsdf = make_bsdf("roughdielectric", {{"int_ior", Eta},
                                              {"ext_ior", 1.0},
                                              {"alpha", AlphaRough},
                                              {"distribution", std::string("ggx")}});
    for (double theta : AnglesDeg) {
        V3 wi = spherical(theta, 0.0);
        SurfaceInteraction si = make_si(to_float(wi));
        for (const auto &o : OutgoingDeg) {
            std::string what = "theta_o = " + std::to_string(int(o[0])) + at(theta);
            // Reflection: F(wi·h)·D·G / (4 cos θi).
            V3 wo = spherical(o[0], o[1]), h = unit(wi + wo);
            double expected = ref_fresnel_dielectric(dot(wi, h), Eta) * ref_ggx_D(h, AlphaRough) *
                              ref_ggx_G1(wi, h, AlphaRough) * ref_ggx_G1(wo, h, AlphaRough) /
                              (4.0 * wi.z);
            expect_rel(bsdf->eval(BSDFContext(), si, to_float(wo)).g, expected, 1e-4,
                       "roughdielectric reflection, " + what);

            // Transmission below the surface (Walter et al. 2007, eq. 16 and 21, times |cos θo|;
            // in radiance transport the η² of eq. 21 cancels against the 1/η² compression):
            // (1 − F(wi·h))·D·G·|wi·h|·|wo·h| / (cos θi·(wi·h + η·wo·h)²), h = −(wi + η·wo).
            V3 wt = spherical(180.0 - o[0], o[1]);
            V3 ht = unit(wi + wt * Eta);
            if (ht.z < 0.0) ht = ht * -1.0;
            double i_h = dot(wi, ht), o_h = dot(wt, ht);
            if (i_h <= 0.0 || o_h >= 0.0) continue; // not a refraction about any microfacet
            double G = ref_ggx_G1(wi, ht, AlphaRough) * ref_ggx_G1(wt, ht, AlphaRough);
            expected = (1.0 - ref_fresnel_dielectric(i_h, Eta)) * ref_ggx_D(ht, AlphaRough) * G *
                       std::abs(i_h * o_h) / (wi.z * (i_h + Eta * o_h) * (i_h + Eta * o_h));
            expect_rel(bsdf->eval(BSDFContext(), si, to_float(wt)).g, expected, 1e-4,
                       "roughdielectric transmission, " + what);
        }
    }
}

TEST(OffNormalFresnel, RoughPlasticTakesFresnelAtTheMicrofacetNormal) {
    auto bsdf = make_bsdf("roughplastic", {{"int_ior", Eta},
                                           {"ext_ior", 1.0},
                                           {"alpha", AlphaRough},
                                           {"distribution", std::string("ggx")}});
    BSDFContext specular = component_ctx(0);
    for (double theta : AnglesDeg) {
        V3 wi = spherical(theta, 0.0);
        SurfaceInteraction si = make_si(to_float(wi));
        for (const auto &o : OutgoingDeg) {
            V3 wo = spherical(o[0], o[1]), h = unit(wi + wo);
            double expected = ref_fresnel_dielectric(dot(wi, h), Eta) * ref_ggx_D(h, AlphaRough) *
                              ref_ggx_G1(wi, h, AlphaRough) * ref_ggx_G1(wo, h, AlphaRough) /
                              (4.0 * wi.z);
            expect_rel(bsdf->eval(specular, si, to_float(wo)).g, expected, 1e-4,
                       "roughplastic specular, theta_o = " + std::to_string(int(o[0])) + at(theta));
        }
    }
}
