// The smooth plastic: flags, parameters, the Fresnel split between the mirror and the diffuse
// base, closed forms, eval/pdf/sample consistency, reciprocity of the diffuse lobe, energy and
// chi-square of the diffuse sampling.

#include "bsdf_checks.h"

#include <facet/fresnel.h>

using namespace facet;
using namespace bsdf_checks;

namespace {

/// Polypropylene in air, the defaults.
const float DefaultEta = 1.49f / 1.000277f;

/// The diffuse lobe's f·cos θo written out (Mitsuba's plastic model).
float diffuse_closed_form(float rho, float eta, const Vector3f &wi, const Vector3f &wo,
                          bool nonlinear = false) {
    float fdr = fresnel_diffuse_reflectance(1.f / eta);
    float albedo = nonlinear ? rho / (1.f - rho * fdr) : rho / (1.f - fdr);
    float Fi = fresnel_dielectric(wi.z, eta).F, Fo = fresnel_dielectric(wo.z, eta).F;
    return albedo / (eta * eta) * (1.f - Fi) * (1.f - Fo) * wo.z / Pi;
}

struct Config {
    const char *name;
    Params params;
};

std::vector<Config> configs() {
    return {
        {"Defaults", {}},
        {"Coloured", {{"diffuse_reflectance", Color3f(0.3f, 0.6f, 0.2f)}}},
        {"Nonlinear", {{"diffuse_reflectance", Color3f(0.9f, 0.5f, 0.1f)}, {"nonlinear", true}}},
        {"Tinted", {{"specular_reflectance", 0.4}, {"int_ior", 1.9}}},
        {"DenseCoating", {{"int_ior", std::string("diamond")}, {"diffuse_reflectance", 0.8}}},
    };
}

} // namespace

TEST(Plastic, CreationAndFlags) {
    auto bsdf = make_bsdf("plastic");
    ASSERT_EQ(bsdf->component_count(), 2u);
    EXPECT_EQ(bsdf->flags(0), BSDFFlags::DeltaReflection | BSDFFlags::SeparableDelta |
                                  BSDFFlags::FrontSide | BSDFFlags::WiSideOnly);
    EXPECT_EQ(bsdf->flags(1),
              BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide | BSDFFlags::WiSideOnly);
    EXPECT_EQ(bsdf->flags(), bsdf->flags(0) | bsdf->flags(1));
    EXPECT_NE(bsdf->to_string().find("Plastic"), std::string::npos);
    EXPECT_EQ(bsdf->eval_diffuse_reflectance(make_si(Vector3f(0.f, 0.f, 1.f))), Color3f(0.5f));
    expect_documented("plastic");
    expect_documented(
        "plastic",
        {{"specular_reflectance", 0.5}, {"nonlinear", true}, {"int_ior", 1.6}, {"ext_ior", 1.1}});
}

TEST(Plastic, RejectsBadParameters) {
    expect_error("plastic", {{"int_ior", std::string("unobtainium")}}, "unknown IOR name");
    expect_error("plastic", {{"ext_ior", -1.0}}, "ext_ior must be a positive index");
    expect_error("plastic", {{"int_ior", 0.0}}, "int_ior must be a positive index");
    expect_error("plastic", {{"nonlinear", std::string("yes")}}, "nonlinear");
    expect_error("plastic", {{"diffuse_reflectance", std::string("red")}}, "diffuse_reflectance");
    expect_error("plastic", {{"alpha", 0.1}}, "alpha");
    expect_error("plastic", {{"reflectance", 0.3}}, "reflectance");
}

TEST(Plastic, SpecularWeightAtNormalIncidenceIsF0) {
    // wi = n: the mirror lobe reflects F(0) = ((η − 1)/(η + 1))², whatever lobe selection does.
    auto bsdf = make_bsdf("plastic");
    SurfaceInteraction si = make_si(Vector3f(0.f, 0.f, 1.f));
    float F0 = sqr((DefaultEta - 1.f) / (DefaultEta + 1.f));
    EXPECT_NEAR(F0, fresnel_dielectric(1.f, DefaultEta).F, 1e-6f);

    // Specular lobe alone: always taken, weight F(0).
    auto [bs0, w0] = bsdf->sample(component_ctx(0), si, 0.7f, Point2f(0.3f, 0.4f));
    EXPECT_EQ(bs0.sampled_type, BSDFFlags::DeltaReflection);
    EXPECT_EQ(bs0.sampled_component, 0u);
    EXPECT_EQ(bs0.pdf, 1.f);
    EXPECT_EQ(bs0.wo, Vector3f(0.f, 0.f, 1.f));
    EXPECT_NEAR(w0.r, F0, 1e-6f);

    // Both lobes: p_spec = F·w/(F·w + (1 − F)(1 − w)) with w = 1/(1 + 0.5); weight·p_spec = F(0).
    float w = 1.f / 1.5f;
    float p_spec = F0 * w / (F0 * w + (1.f - F0) * (1.f - w));
    auto [bs, weight] = bsdf->sample(BSDFContext(), si, 0.5f * p_spec, Point2f(0.3f, 0.4f));
    EXPECT_EQ(bs.sampled_type, BSDFFlags::DeltaReflection);
    EXPECT_NEAR(bs.pdf, p_spec, 1e-6f);
    EXPECT_NEAR(weight.r * bs.pdf, F0, 1e-6f);
    auto [bs_d, w_d] = bsdf->sample(BSDFContext(), si, p_spec + 1e-3f, Point2f(0.3f, 0.4f));
    EXPECT_EQ(bs_d.sampled_type, BSDFFlags::DiffuseReflection);
    EXPECT_EQ(bs_d.sampled_component, 1u);

    // specular_reflectance tints the mirror.
    auto tinted = make_bsdf("plastic", {{"specular_reflectance", Color3f(0.5f, 0.25f, 1.f)}});
    auto [bs_t, w_t] = tinted->sample(component_ctx(0), si, 0.5f, Point2f(0.5f));
    EXPECT_NEAR(w_t.r, 0.5f * F0, 1e-6f);
    EXPECT_NEAR(w_t.g, 0.25f * F0, 1e-6f);
    EXPECT_NEAR(w_t.b, F0, 1e-6f);
}

TEST(Plastic, DiffuseLobeClosedForm) {
    PCG32 rng(4);
    for (bool nonlinear : {false, true}) {
        auto bsdf = make_bsdf(
            "plastic", {{"diffuse_reflectance", 0.7}, {"int_ior", 1.7}, {"nonlinear", nonlinear}});
        float eta = 1.7f / 1.000277f;
        for (int i = 0; i < 100; ++i) {
            Vector3f wi = random_direction(rng, true), wo = random_direction(rng, true);
            float value = bsdf->eval(BSDFContext(), make_si(wi), wo).g;
            float expected = diffuse_closed_form(0.7f, eta, wi, wo, nonlinear);
            EXPECT_NEAR(value, expected, 1e-5f * expected) << nonlinear;
        }
    }
    // The diffuse sample weight at normal incidence: ρ/(1 − fdr)/η²·(1 − F_i)(1 − F_o)/p_diff.
    auto bsdf = make_bsdf("plastic");
    SurfaceInteraction si = make_si(Vector3f(0.f, 0.f, 1.f));
    auto [bs, weight] = bsdf->sample(component_ctx(1), si, 0.2f, Point2f(0.f, 0.f));
    ASSERT_EQ(bs.sampled_type, BSDFFlags::DiffuseReflection);
    float expected = diffuse_closed_form(0.5f, DefaultEta, si.wi, bs.wo) * Pi / bs.wo.z;
    EXPECT_NEAR(weight.r, expected, 1e-5f);
}

TEST(Plastic, SampleWeightMatchesEvalPdf) {
    for (const Config &c : configs()) {
        auto bsdf = make_bsdf("plastic", c.params);
        // Mirror samples (a few percent to a third) have nothing smooth to check.
        EXPECT_GT(check_sample_eval_pdf(*bsdf, BSDFContext(), false, 2000, 3), 1200) << c.name;
        EXPECT_GT(check_sample_eval_pdf(*bsdf, component_ctx(1), false, 500, 4), 450) << c.name;
        // The mirror alone has nothing smooth to check, but must not produce smooth samples.
        EXPECT_EQ(check_sample_eval_pdf(*bsdf, component_ctx(0), false, 200, 5), 0) << c.name;
    }
}

TEST(Plastic, PdfMatchesLobeSelection) {
    // pdf() of the diffuse lobe includes 1 − p_spec, and is the full cosine density when the
    // diffuse lobe is alone.
    auto bsdf = make_bsdf("plastic", {{"diffuse_reflectance", 0.2}});
    Vector3f wi = normalize(Vector3f(0.4f, 0.1f, 0.6f)),
             wo = normalize(Vector3f(-0.3f, 0.2f, 0.7f));
    SurfaceInteraction si = make_si(wi);
    float F = fresnel_dielectric(wi.z, DefaultEta).F, w = 1.f / 1.2f;
    float p_spec = F * w / (F * w + (1.f - F) * (1.f - w));
    EXPECT_NEAR(bsdf->pdf(BSDFContext(), si, wo), (1.f - p_spec) * wo.z * InvPi, 1e-6f);
    EXPECT_NEAR(bsdf->pdf(component_ctx(1), si, wo), wo.z * InvPi, 1e-6f);
    EXPECT_EQ(bsdf->pdf(component_ctx(0), si, wo), 0.f);
    EXPECT_TRUE(bsdf->eval(component_ctx(0), si, wo).is_black());
}

TEST(Plastic, DiffuseLobeIsReciprocal) {
    // f = ρ/(1 − fdr)/η²·(1 − F(cos θi))(1 − F(cos θo))/π is symmetric in wi and wo.
    PCG32 rng(12);
    for (const Config &c : configs()) {
        auto bsdf = make_bsdf("plastic", c.params);
        for (int i = 0; i < 300; ++i) {
            Vector3f wi = random_direction(rng, true), wo = random_direction(rng, true);
            Color3f f_io = bsdf->eval(BSDFContext(), make_si(wi), wo) / wo.z;
            Color3f f_oi = bsdf->eval(BSDFContext(), make_si(wo), wi) / wi.z;
            for (int ch = 0; ch < 3; ++ch)
                EXPECT_NEAR(f_io[ch], f_oi[ch], 1e-5f * std::max(f_io[ch], f_oi[ch])) << c.name;
        }
    }
}

TEST(Plastic, BackSideIsBlack) {
    auto bsdf = make_bsdf("plastic");
    Vector3f below = normalize(Vector3f(0.2f, 0.1f, -0.6f)),
             above = normalize(Vector3f(-0.2f, 0.1f, 0.6f));
    for (float s1 : {0.01f, 0.99f})
        EXPECT_TRUE(
            bsdf->sample(BSDFContext(), make_si(below), s1, Point2f(0.3f, 0.4f)).second.is_black());
    EXPECT_TRUE(bsdf->eval(BSDFContext(), make_si(below), above).is_black());
    EXPECT_TRUE(bsdf->eval(BSDFContext(), make_si(above), below).is_black());
    EXPECT_EQ(bsdf->pdf(BSDFContext(), make_si(above), below), 0.f);
    EXPECT_EQ(bsdf->pdf(BSDFContext(), make_si(below), above), 0.f);
    BSDFContext glossy_only;
    glossy_only.type_mask = uint32_t(BSDFFlags::Glossy);
    EXPECT_TRUE(
        bsdf->sample(glossy_only, make_si(above), 0.5f, Point2f(0.3f, 0.4f)).second.is_black());
}

TEST(Plastic, WhiteFurnace) {
    // With ρ = 1 the coating only redistributes light: the albedo is F_i + (1 − F_i)·(1 − fdr_ext)
    // /(η²(1 − fdr_int)), one up to the accuracy of the fdr fits. Everything else stays below.
    PCG32 rng(13);
    auto white = make_bsdf("plastic", {{"diffuse_reflectance", 1.0}});
    float eta = DefaultEta;
    float ratio = (1.f - fresnel_diffuse_reflectance(eta)) /
                  (eta * eta * (1.f - fresnel_diffuse_reflectance(1.f / eta)));
    EXPECT_NEAR(ratio, 1.f, 0.01f);
    for (float theta : {0.f, 30.f, 60.f, 85.f}) {
        Vector3f wi = direction_from_angles(theta, 20.f);
        float F = fresnel_dielectric(wi.z, eta).F;
        Color3f albedo = furnace(*white, BSDFContext(), wi, 40000);
        EXPECT_NEAR(albedo.r, F + (1.f - F) * ratio, 0.01f) << theta;
    }
    for (const Config &c : configs()) {
        auto bsdf = make_bsdf("plastic", c.params);
        for (int i = 0; i < 4; ++i) {
            Vector3f wi = random_direction(rng, true);
            EXPECT_LE(furnace(*bsdf, BSDFContext(), wi, 20000).max(), 1.f + 5e-3f) << c.name;
        }
    }
}

TEST(Plastic, CoatSampledAloneCarriesWhatSamplesBringThroughIt) {
    // SeparableDelta: the coat sampled alone weighs the mirror direction by what the plastic's
    // own samples (which pick the coat with probability p and divide by it) bring on average,
    // F times specular_reflectance; the path tracer counts it in every sample on that promise.
    // Also through the adapters that pass the flag on.
    for (const auto &config : configs()) {
        SCOPED_TRACE(config.name);
        auto bsdf = make_bsdf("plastic", config.params);
        EXPECT_GT(check_separable_delta(*bsdf, false), 20);
        auto twosided = make_nested("twosided", {bsdf});
        EXPECT_TRUE(has_flag(twosided->flags(2), BSDFFlags::SeparableDelta));
        EXPECT_GT(check_separable_delta(*twosided, true), 20); // one side's coat is lit
        auto mask = make_nested("mask", {bsdf}, {{"opacity", 0.3}});
        EXPECT_GT(check_separable_delta(*mask, false), 20);
    }
}

// Chi-square tests of this plugin's sampling: tests/chi2/configs.txt (label chi2).

TEST(Plastic, ReflectsOnlyToWiSide) {
    EXPECT_GT(check_wi_side_only(*make_bsdf("plastic")), 500);
    EXPECT_GT(check_wi_side_only(*make_bsdf("plastic", {{"nonlinear", true}, {"int_ior", 1.9}})),
              500);
}
