// The smooth dielectric: flags, parameters, Fresnel split between the lobes, Snell's law, total
// internal reflection, radiance scaling, single-lobe contexts and energy conservation.

#include "bsdf_checks.h"

#include <facet/fresnel.h>
#include <facet/ior.h>

using namespace facet;
using namespace bsdf_checks;

TEST(Dielectric, CreationAndFlags) {
    auto bsdf = make_bsdf("dielectric");
    ASSERT_EQ(bsdf->component_count(), 2u);
    BSDFFlags sides = BSDFFlags::FrontSide | BSDFFlags::BackSide | BSDFFlags::Polarizing;
    EXPECT_EQ(bsdf->flags(0), BSDFFlags::DeltaReflection | sides);
    EXPECT_EQ(bsdf->flags(1), BSDFFlags::DeltaTransmission | sides | BSDFFlags::NonSymmetric);
    EXPECT_EQ(bsdf->flags(), bsdf->flags(0) | bsdf->flags(1));
    EXPECT_NE(bsdf->to_string().find("Dielectric"), std::string::npos);
    expect_documented("dielectric",
                      {{"specular_reflectance", 0.5}, {"specular_transmittance", 0.5}});
}

TEST(Dielectric, DefaultsAreBK7InAir) {
    auto bsdf = make_bsdf("dielectric");
    SurfaceInteraction si = make_si(Vector3f(0.f, 0.f, 1.f));
    auto [bs, weight] = bsdf->sample(component_ctx(0), si, 0.5f, Point2f(0.5f));
    float expected = fresnel_dielectric(1.f, 1.5046f / 1.000277f).F;
    EXPECT_NEAR(weight.r, expected, 1e-6f);
    EXPECT_NEAR(expected, 0.04054f, 1e-5f); // ((1.5046 − 1.000277)/(1.5046 + 1.000277))²
}

TEST(Dielectric, AcceptsNamesAndNumbers) {
    auto bsdf = make_bsdf("dielectric", {{"int_ior", std::string("water")}, {"ext_ior", 1.0}});
    SurfaceInteraction si = make_si(Vector3f(0.f, 0.f, 1.f));
    auto [bs, weight] = bsdf->sample(component_ctx(0), si, 0.5f, Point2f(0.5f));
    EXPECT_NEAR(weight.r, sqr(0.333f / 2.333f), 1e-6f);
    auto diamond = make_bsdf("dielectric", {{"int_ior", std::string("Diamond")}});
    auto [bs2, weight2] = diamond->sample(component_ctx(1), si, 0.5f, Point2f(0.5f));
    EXPECT_NEAR(bs2.eta, 2.419f / 1.000277f, 1e-5f);
}

TEST(Dielectric, RejectsBadParameters) {
    expect_error("dielectric", {{"int_ior", std::string("unobtainium")}}, "unknown IOR name");
    expect_error("dielectric", {{"int_ior", std::string("diamnd")}}, "did you mean \"diamond\"");
    expect_error("dielectric", {{"ext_ior", -1.0}}, "ext_ior must be a positive index");
    expect_error("dielectric", {{"int_ior", 0.0}}, "int_ior must be a positive index");
    expect_error("dielectric", {{"int_ior", Color3f(1.5f)}}, "int_ior");
    expect_error("dielectric", {{"intior", 1.5}}, "intior");
}

TEST(Dielectric, NormalIncidenceReflectsFourPercent) {
    // The lecture's 4 % for η = 1.5, split between the lobes by sample1.
    auto bsdf = make_bsdf("dielectric", {{"int_ior", 1.5}, {"ext_ior", 1.0}});
    SurfaceInteraction si = make_si(Vector3f(0.f, 0.f, 1.f));
    BSDFContext ctx;
    auto [r, wr] = bsdf->sample(ctx, si, 0.03f, Point2f(0.5f));
    EXPECT_EQ(r.sampled_type, BSDFFlags::DeltaReflection);
    EXPECT_EQ(r.sampled_component, 0u);
    EXPECT_NEAR(r.pdf, 0.04f, 1e-6f);
    EXPECT_EQ(wr, Color3f(1.f));
    EXPECT_EQ(r.wo, Vector3f(0.f, 0.f, 1.f));
    EXPECT_EQ(r.eta, 1.f);

    auto [t, wt] = bsdf->sample(ctx, si, 0.05f, Point2f(0.5f));
    EXPECT_EQ(t.sampled_type, BSDFFlags::DeltaTransmission);
    EXPECT_EQ(t.sampled_component, 1u);
    EXPECT_NEAR(t.pdf, 0.96f, 1e-6f);
    EXPECT_NEAR(t.wo.z, -1.f, 1e-6f);
    EXPECT_EQ(t.eta, 1.5f);
    // Radiance entering glass is compressed into a smaller solid angle: × 1/η².
    EXPECT_NEAR(wt.r, 1.f / 2.25f, 1e-6f);
    auto [t2, wt2] = bsdf->sample(BSDFContext(TransportMode::Importance), si, 0.05f, Point2f(0.5f));
    EXPECT_EQ(wt2, Color3f(1.f));

    // Leaving the glass: × η².
    SurfaceInteraction inside = make_si(Vector3f(0.f, 0.f, -1.f));
    auto [t3, wt3] = bsdf->sample(ctx, inside, 0.5f, Point2f(0.5f));
    EXPECT_NEAR(t3.eta, 1.f / 1.5f, 1e-6f);
    EXPECT_NEAR(wt3.r, 2.25f, 1e-5f);
    EXPECT_NEAR(t3.wo.z, 1.f, 1e-6f);
}

TEST(Dielectric, EveryRefractedSampleFollowsSnellsLaw) {
    float eta = 1.5046f / 1.000277f;
    auto bsdf = make_bsdf("dielectric");
    PCG32 rng(21);
    int refracted = 0;
    for (int i = 0; i < 5000; ++i) {
        SurfaceInteraction si = make_si(random_direction(rng, false));
        auto [bs, weight] = bsdf->sample(BSDFContext(), si, rng.next_float(), Point2f(0.5f));
        ASSERT_FALSE(weight.is_black());
        ASSERT_NEAR(norm(bs.wo), 1.f, 1e-5f);
        float cos_i = si.wi.z;
        auto [F, cos_t, eta_it, eta_ti] = fresnel_dielectric(cos_i, eta);
        if (bs.sampled_type == BSDFFlags::DeltaReflection) {
            EXPECT_EQ(bs.wo, Vector3f(-si.wi.x, -si.wi.y, si.wi.z));
            EXPECT_NEAR(bs.pdf, F, 1e-6f);
            continue;
        }
        ++refracted;
        EXPECT_LT(bs.wo.z * cos_i, 0.f);
        float eta_i = cos_i > 0.f ? 1.f : eta, eta_t = cos_i > 0.f ? eta : 1.f;
        EXPECT_NEAR(eta_i * Frame::sin_theta(si.wi), eta_t * Frame::sin_theta(bs.wo), 2e-5f);
        EXPECT_NEAR(bs.eta, eta_t / eta_i, 1e-6f);
        EXPECT_NEAR(bs.pdf, 1.f - F, 1e-6f);
        EXPECT_NEAR(weight.r, sqr(eta_i / eta_t), 1e-5f);
        // Coplanar with wi and the normal, on the opposite side of the normal.
        EXPECT_NEAR(bs.wo.x * si.wi.y - bs.wo.y * si.wi.x, 0.f, 1e-5f);
        EXPECT_LE(bs.wo.x * si.wi.x + bs.wo.y * si.wi.y, 1e-6f);
    }
    EXPECT_GT(refracted, 2000); // about half come from inside, where TIR is common
}

TEST(Dielectric, TotalInternalReflectionFromTheDenseSide) {
    auto bsdf = make_bsdf("dielectric", {{"int_ior", 1.5}, {"ext_ior", 1.0}});
    float critical = std::asin(1.f / 1.5f);
    for (float theta : {critical + 0.01f, critical + 0.3f, 1.5f}) {
        // Inside the glass, the normal points away: wi has cos θ < 0.
        SurfaceInteraction si = make_si(Vector3f(std::sin(theta), 0.f, -std::cos(theta)));
        for (float s1 : {0.f, 0.5f, 0.999f}) {
            auto [bs, weight] = bsdf->sample(BSDFContext(), si, s1, Point2f(0.5f));
            EXPECT_EQ(bs.sampled_type, BSDFFlags::DeltaReflection);
            EXPECT_EQ(bs.pdf, 1.f);
            EXPECT_EQ(weight, Color3f(1.f));
            EXPECT_LT(bs.wo.z, 0.f);
        }
        // Transmission alone has nothing to give.
        auto [bs, weight] = bsdf->sample(component_ctx(1), si, 0.5f, Point2f(0.5f));
        EXPECT_TRUE(weight.is_black());
    }
    // Just below the critical angle some light leaves.
    float theta = critical - 0.01f;
    SurfaceInteraction si = make_si(Vector3f(std::sin(theta), 0.f, -std::cos(theta)));
    auto [bs, weight] = bsdf->sample(component_ctx(1), si, 0.5f, Point2f(0.5f));
    EXPECT_FALSE(weight.is_black());
    EXPECT_GT(bs.wo.z, 0.f);
}

TEST(Dielectric, SingleLobeContexts) {
    auto bsdf = make_bsdf("dielectric", {{"int_ior", 1.5}, {"ext_ior", 1.0}});
    Vector3f wi = normalize(Vector3f(0.4f, -0.2f, 0.7f));
    SurfaceInteraction si = make_si(wi);
    float F = fresnel_dielectric(wi.z, 1.5f).F;
    for (float s1 : {0.f, 0.5f, 0.99f}) {
        auto [r, wr] = bsdf->sample(component_ctx(0), si, s1, Point2f(0.5f));
        EXPECT_EQ(r.sampled_type, BSDFFlags::DeltaReflection);
        EXPECT_EQ(r.pdf, 1.f);
        EXPECT_NEAR(wr.r, F, 1e-6f);

        BSDFContext ctx(TransportMode::Importance);
        ctx.type_mask = uint32_t(BSDFFlags::DeltaTransmission);
        auto [t, wt] = bsdf->sample(ctx, si, s1, Point2f(0.5f));
        EXPECT_EQ(t.sampled_type, BSDFFlags::DeltaTransmission);
        EXPECT_EQ(t.pdf, 1.f);
        EXPECT_NEAR(wt.r, 1.f - F, 1e-6f);
    }
    BSDFContext none;
    none.type_mask = uint32_t(BSDFFlags::Glossy);
    EXPECT_TRUE(bsdf->sample(none, si, 0.5f, Point2f(0.5f)).second.is_black());
}

TEST(Dielectric, EvalAndPdfAreZero) {
    auto bsdf = make_bsdf("dielectric");
    SurfaceInteraction si = make_si(normalize(Vector3f(0.3f, 0.f, 1.f)));
    Vector3f wo = reflect(si.wi);
    EXPECT_TRUE(bsdf->eval(BSDFContext(), si, wo).is_black());
    EXPECT_EQ(bsdf->pdf(BSDFContext(), si, wo), 0.f);
    auto [v, p] = bsdf->eval_pdf(BSDFContext(), si, wo);
    EXPECT_TRUE(v.is_black());
    EXPECT_EQ(p, 0.f);
}

TEST(Dielectric, WhiteFurnaceConservesEnergy) {
    // Reflection + transmission carry all the energy, from both sides (radiance-mode samples are
    // compensated by η², importance-mode ones are not scaled at all).
    auto bsdf = make_bsdf("dielectric");
    PCG32 rng(4);
    for (int i = 0; i < 20; ++i) {
        Vector3f wi = random_direction(rng, false);
        for (TransportMode mode : {TransportMode::Radiance, TransportMode::Importance}) {
            Color3f albedo = furnace(*bsdf, BSDFContext(mode), wi, 2000);
            EXPECT_NEAR(albedo.r, 1.f, 1e-5f) << wi;
        }
    }
    // Tints scale each lobe: F·r + (1 − F)·t in expectation (exact: each weight is r or t).
    auto tinted =
        make_bsdf("dielectric", {{"specular_reflectance", 0.5}, {"specular_transmittance", 0.25}});
    Vector3f wi = normalize(Vector3f(0.5f, 0.f, 0.5f));
    float F = fresnel_dielectric(wi.z, 1.5046f / 1.000277f).F;
    Color3f albedo = furnace(*tinted, BSDFContext(TransportMode::Importance), wi, 200000);
    // Binomial noise of the lobe choice: σ = 0.25·√(F(1−F)/N) ≈ 1.2e-4.
    EXPECT_NEAR(albedo.g, 0.5f * F + 0.25f * (1.f - F), 6e-4f);
}

TEST(Dielectric, LobeChoiceFollowsFresnel) {
    auto bsdf = make_bsdf("dielectric");
    Vector3f wi = normalize(Vector3f(0.9f, 0.f, 0.2f));
    SurfaceInteraction si = make_si(wi);
    float F = fresnel_dielectric(wi.z, 1.5046f / 1.000277f).F;
    PCG32 rng(8);
    int reflected = 0, n = 100000;
    for (int i = 0; i < n; ++i)
        if (bsdf->sample(BSDFContext(), si, rng.next_float(), Point2f(0.5f)).first.sampled_type ==
            BSDFFlags::DeltaReflection)
            ++reflected;
    // 5σ of the binomial count.
    EXPECT_NEAR(double(reflected) / n, F, 5.0 * std::sqrt(F * (1.0 - F) / n));
}
