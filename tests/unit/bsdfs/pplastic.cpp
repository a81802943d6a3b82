// The polarized plastic: flags, parameters, both lobes against their closed forms (the seed's
// Fresnel, GGX's D and Smith G), eval/pdf/sample consistency, reciprocity, the energy bound, and
// in the polarized mode: the matrices' intensities are the colours, and light leaving the
// diffuse base at a grazing angle is partly polarised, as Fresnel's transmission predicts.

#include "bsdf_checks.h"

#include <facet/fresnel.h>
#include <facet/mueller.h>
#include <facet/xml.h>

using namespace facet;
using namespace bsdf_checks;

namespace {

const double Eta = 1.49 / 1.000277;

/// The lecture's unpolarised Fresnel reflectance from air into η.
double lecture_F(double cos1, double eta) {
    const double sin2 = std::sqrt(std::max(0.0, 1.0 - cos1 * cos1)) / eta;
    const double cos2 = std::sqrt(1.0 - sin2 * sin2);
    const double fs = (cos1 - eta * cos2) / (cos1 + eta * cos2),
                 fp = (eta * cos1 - cos2) / (eta * cos1 + cos2);
    return 0.5 * (fs * fs + fp * fp);
}

/// GGX: D(h) = α²/(π cos⁴θh (α² + tan²θh)²); G1(v) = 2/(1 + √(1 + α² tan²θv)).
double ggx_D(const Vector3f &h, double a) {
    const double c2 = double(h.z) * h.z, t2 = (1.0 - c2) / c2;
    return a * a / (Pi * c2 * c2 * sqr(a * a + t2));
}
double ggx_G1(const Vector3f &v, double a) {
    const double c2 = double(v.z) * v.z, t2 = (1.0 - c2) / c2;
    return 2.0 / (1.0 + std::sqrt(1.0 + a * a * t2));
}

std::vector<Params> configs() {
    return {{},
            {{"distribution", std::string("ggx")}, {"alpha", 0.3}},
            {{"alpha", 0.05}, {"specular_reflectance", 0.6}, {"diffuse_reflectance", 0.2}},
            {{"alpha_u", 0.1}, {"alpha_v", 0.4}},
            {{"distribution", std::string("ggx")}, {"alpha", 0.2}, {"sample_visible", false}}};
}

} // namespace

TEST(PPlastic, CreationAndFlags) {
    auto bsdf = make_bsdf("pplastic");
    ASSERT_EQ(bsdf->component_count(), 2u);
    EXPECT_EQ(bsdf->flags(0), BSDFFlags::GlossyReflection | BSDFFlags::FrontSide |
                                  BSDFFlags::Polarizing | BSDFFlags::WiSideOnly);
    EXPECT_EQ(bsdf->flags(1), BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide |
                                  BSDFFlags::Polarizing | BSDFFlags::WiSideOnly);
    auto aniso = make_bsdf("pplastic", {{"alpha_u", 0.1}, {"alpha_v", 0.3}});
    EXPECT_TRUE(has_flag(aniso->flags(0), BSDFFlags::Anisotropic));
    expect_error("pplastic", {{"int_ior", 1.3}, {"ext_ior", 1.3}}, "must differ");
    expect_error("pplastic", {{"distribution", std::string("phong")}}, "distribution");
    expect_documented("pplastic");
}

TEST(PPlastic, BothLobesMatchTheirClosedForms) {
    const double a = 0.3;
    auto bsdf = make_bsdf("pplastic", {{"distribution", std::string("ggx")},
                                       {"alpha", a},
                                       {"diffuse_reflectance", 0.4},
                                       {"specular_reflectance", 0.8}});
    PCG32 rng(3);
    for (int i = 0; i < 200; ++i) {
        const Vector3f wi = random_direction(rng, true), wo = random_direction(rng, true);
        const Vector3f h = normalize(wi + wo);
        const double F = lecture_F(dot(wi, h), Eta);
        const double glossy = 0.8 * F * ggx_D(h, a) * ggx_G1(wi, a) * ggx_G1(wo, a) / (4 * wi.z);
        const double diffuse =
            0.4 * (1 - lecture_F(wi.z, Eta)) * (1 - lecture_F(wo.z, Eta)) * wo.z / Pi;
        const float g = bsdf->eval(component_ctx(0), make_si(wi), wo).g;
        const float d = bsdf->eval(component_ctx(1), make_si(wi), wo).g;
        EXPECT_NEAR(g, glossy, 2e-4 * glossy + 1e-7) << wi << " " << wo;
        EXPECT_NEAR(d, diffuse, 2e-5 * diffuse + 1e-8) << wi << " " << wo;
        EXPECT_NEAR(bsdf->eval(BSDFContext(), make_si(wi), wo).g, g + d, 1e-5 * (g + d) + 1e-7);
    }
}

TEST(PPlastic, SampleWeightMatchesEvalPdf) {
    for (const Params &p : configs()) {
        auto bsdf = make_bsdf("pplastic", p);
        EXPECT_GT(check_sample_eval_pdf(*bsdf, BSDFContext(), false, 2000, 3), 1500);
        EXPECT_GT(check_sample_eval_pdf(*bsdf, component_ctx(0), false, 500, 4), 250);
        EXPECT_GT(check_sample_eval_pdf(*bsdf, component_ctx(1), false, 500, 5), 450);
    }
}

TEST(PPlastic, ReciprocityAndEnergy) {
    PCG32 rng(12);
    for (const Params &p : configs()) {
        auto bsdf = make_bsdf("pplastic", p);
        for (int i = 0; i < 300; ++i) {
            Vector3f wi = random_direction(rng, true), wo = random_direction(rng, true);
            Color3f f_io = bsdf->eval(BSDFContext(), make_si(wi), wo) / wo.z;
            Color3f f_oi = bsdf->eval(BSDFContext(), make_si(wo), wi) / wi.z;
            EXPECT_NEAR(f_io.g, f_oi.g, 1e-4f * std::max(f_io.g, f_oi.g) + 1e-7f);
        }
        Params white;
        for (const auto &q : p)
            if (q.first != "diffuse_reflectance") white.push_back(q);
        white.push_back({"diffuse_reflectance", 1.0});
        auto w = make_bsdf("pplastic", white);
        for (int i = 0; i < 3; ++i) {
            const Color3f albedo = furnace(*w, BSDFContext(), random_direction(rng, true), 20000);
            EXPECT_LE(albedo.max(), 1.f + 1e-2f);
        }
        // At normal incidence a white base returns (1 − F(1))·(1 − F̄), F̄ = 2∫F(μ)μ dμ the
        // cosine-weighted mean reflectance; the glossy lobe adds at most F(1).
        double mean_F = 0.0;
        const int n = 4000;
        for (int k = 0; k < n; ++k) {
            const double mu = (k + 0.5) / n;
            mean_F += 2.0 * lecture_F(mu, Eta) * mu / n;
        }
        const double diffuse = (1.0 - lecture_F(1.0, Eta)) * (1.0 - mean_F);
        const float albedo = furnace(*w, BSDFContext(), Vector3f(0.f, 0.f, 1.f), 40000).g;
        EXPECT_GT(albedo, diffuse - 0.01);
        EXPECT_LT(albedo, diffuse + lecture_F(1.0, Eta) + 0.01);
    }
}

TEST(PPlastic, TheDiffuseBasePolarisesLightLeavingAtGrazingAngles) {
    LoadOptions opts;
    opts.mode = "scalar_spectral_polarized";
    auto bsdf = std::dynamic_pointer_cast<BSDF>(load_string(
        R"(<bsdf version="3.0.0" type="pplastic"><float name="diffuse_reflectance" value="0.5"/></bsdf>)",
        opts));
    ASSERT_TRUE(bsdf);
    // Unpolarised light from the normal, leaving at 80 degrees in the x-z plane (radiance mode:
    // light from wo to wi; here wi is the grazing direction). The base's light is transmitted
    // out of the coating with t_s < t_p: more p (in the plane of incidence) than s light.
    SurfaceInteraction si;
    si.wavelengths = Wavelengths(450.f, 550.f, 650.f, 500.f);
    const float t = 80.f * Pi / 180.f;
    si.wi = Vector3f(std::sin(t), 0.f, std::cos(t));
    const Vector3f wo(0.f, 0.f, 1.f);
    const Mueller M = bsdf->eval_pdf_polarized(component_ctx(1), si, wo).first;
    const Color3f f = bsdf->eval(component_ctx(1), si, wo);
    EXPECT_NEAR(M.m[0][0].g, f.g, 1e-5f * f.g);
    // The leaving light's Stokes vector for unpolarised light in, in the s-frame of its plane of
    // incidence: S1/S0 = (t_s² − t_p²)/(t_s² + t_p²) with the lecture's amplitudes from inside.
    const double cos_in = std::cos(std::asin(std::sin(t) / Eta)); // inside the coating
    const double eta = 1.0 / Eta, ci = cos_in, ct = std::cos(t);
    const double t_s = 1.0 + (ci - eta * ct) / (ci + eta * ct),
                 t_p = (1.0 + (eta * ci - ct) / (eta * ci + ct)) / eta;
    const double expected = (t_s * t_s - t_p * t_p) / (t_s * t_s + t_p * t_p);
    ASSERT_LT(expected, -0.05); // more p than s
    // Turn the leaving light into the frame whose x axis is the s direction n × wi.
    const Vector3f s_out = normalize(cross(Vector3f(0.f, 0.f, 1.f), si.wi));
    const Mueller R = mueller::rotate_stokes_basis(si.wi, mueller::stokes_basis(si.wi), s_out);
    const Stokes out = R * (M * Stokes::unpolarized(Color3f(1.f)));
    EXPECT_NEAR(out.s[1].g / out.s[0].g, expected, 1e-4);
    EXPECT_NEAR(out.s[2].g / out.s[0].g, 0.0, 1e-4);
}

// Chi-square tests of this plugin's sampling: tests/chi2/configs.txt (label chi2).

TEST(PPlastic, ReflectsOnlyToWiSide) {
    EXPECT_GT(check_wi_side_only(*make_bsdf("pplastic", {{"alpha", 0.5}})), 500);
}
