// The thin dielectric sheet: flags, the slab reflectance 2R/(1 + R), unbent transmission, both
// sides alike, null transmission and energy conservation.

#include "bsdf_checks.h"

#include <facet/fresnel.h>

using namespace facet;
using namespace bsdf_checks;

TEST(ThinDielectric, CreationAndFlags) {
    auto bsdf = make_bsdf("thindielectric");
    ASSERT_EQ(bsdf->component_count(), 2u);
    BSDFFlags sides = BSDFFlags::FrontSide | BSDFFlags::BackSide;
    EXPECT_EQ(bsdf->flags(0), BSDFFlags::DeltaReflection | sides);
    EXPECT_EQ(bsdf->flags(1), BSDFFlags::Null | sides);
    EXPECT_NE(bsdf->to_string().find("ThinDielectric"), std::string::npos);
    expect_documented("thindielectric",
                      {{"specular_reflectance", 0.5}, {"specular_transmittance", 0.5}});
}

TEST(ThinDielectric, RejectsBadParameters) {
    expect_error("thindielectric", {{"int_ior", std::string("glas")}}, "unknown IOR name");
    expect_error("thindielectric", {{"int_ior", -1.5}}, "int_ior must be a positive index");
    expect_error("thindielectric", {{"alpha", 0.1}}, "alpha");
}

TEST(ThinDielectric, SlabReflectanceAtNormalIncidence) {
    // One interface reflects 4 % for η = 1.5; the slab reflects 2R/(1 + R) = 0.08/1.04.
    auto bsdf = make_bsdf("thindielectric", {{"int_ior", 1.5}, {"ext_ior", 1.0}});
    for (float z : {1.f, -1.f}) {
        SurfaceInteraction si = make_si(Vector3f(0.f, 0.f, z));
        auto [r, wr] = bsdf->sample(BSDFContext(), si, 0.05f, Point2f(0.5f));
        EXPECT_EQ(r.sampled_type, BSDFFlags::DeltaReflection);
        EXPECT_NEAR(r.pdf, 0.08f / 1.04f, 1e-6f);
        EXPECT_EQ(wr, Color3f(1.f));
        EXPECT_EQ(r.wo, Vector3f(0.f, 0.f, z));

        auto [t, wt] = bsdf->sample(BSDFContext(), si, 0.5f, Point2f(0.5f));
        EXPECT_EQ(t.sampled_type, BSDFFlags::Null);
        EXPECT_EQ(t.sampled_component, 1u);
        EXPECT_NEAR(t.pdf, 1.f - 0.08f / 1.04f, 1e-6f);
        EXPECT_EQ(t.eta, 1.f);
        EXPECT_EQ(wt, Color3f(1.f)); // no bending, no radiance scaling
        EXPECT_EQ(t.wo, Vector3f(0.f, 0.f, -z));
        EXPECT_NEAR(bsdf->eval_null_transmission(si).r, 1.f - 0.08f / 1.04f, 1e-6f);
    }
}

TEST(ThinDielectric, TransmissionPassesStraightThroughOnBothSides) {
    auto bsdf = make_bsdf("thindielectric");
    float eta = 1.5046f / 1.000277f;
    PCG32 rng(5);
    for (int i = 0; i < 1000; ++i) {
        SurfaceInteraction si = make_si(random_direction(rng, false));
        float F = fresnel_dielectric(std::abs(si.wi.z), eta).F;
        float R = 2.f * F / (1.f + F);
        auto [bs, weight] = bsdf->sample(BSDFContext(), si, rng.next_float(), Point2f(0.5f));
        ASSERT_EQ(weight, Color3f(1.f));
        if (bs.sampled_type == BSDFFlags::Null) {
            EXPECT_EQ(bs.wo, -si.wi);
            EXPECT_NEAR(bs.pdf, 1.f - R, 1e-6f);
        } else {
            EXPECT_EQ(bs.wo, reflect(si.wi));
            EXPECT_NEAR(bs.pdf, R, 1e-6f);
        }
    }
}

TEST(ThinDielectric, SingleLobeContextsCarryTheirFraction) {
    auto bsdf = make_bsdf("thindielectric", {{"int_ior", 1.5},
                                             {"ext_ior", 1.0},
                                             {"specular_reflectance", 0.5},
                                             {"specular_transmittance", 0.8}});
    Vector3f wi = normalize(Vector3f(0.6f, 0.3f, -0.5f));
    SurfaceInteraction si = make_si(wi);
    float F = fresnel_dielectric(std::abs(wi.z), 1.5f).F, R = 2.f * F / (1.f + F);
    BSDFContext refl;
    refl.component = 0;
    auto [r, wr] = bsdf->sample(refl, si, 0.99f, Point2f(0.5f));
    EXPECT_EQ(r.pdf, 1.f);
    EXPECT_NEAR(wr.r, 0.5f * R, 1e-6f);
    BSDFContext null;
    null.type_mask = uint32_t(BSDFFlags::Null);
    auto [t, wt] = bsdf->sample(null, si, 0.f, Point2f(0.5f));
    EXPECT_EQ(t.sampled_type, BSDFFlags::Null);
    EXPECT_NEAR(wt.r, 0.8f * (1.f - R), 1e-6f);
    EXPECT_NEAR(bsdf->eval_null_transmission(si).r, 0.8f * (1.f - R), 1e-6f);
    EXPECT_TRUE(bsdf->eval(BSDFContext(), si, -wi).is_black());
    EXPECT_EQ(bsdf->pdf(BSDFContext(), si, -wi), 0.f);
}

TEST(ThinDielectric, WhiteFurnaceConservesEnergy) {
    auto bsdf = make_bsdf("thindielectric", {{"int_ior", std::string("diamond")}});
    PCG32 rng(6);
    for (int i = 0; i < 20; ++i) {
        Vector3f wi = random_direction(rng, false);
        EXPECT_NEAR(furnace(*bsdf, BSDFContext(), wi, 1000).r, 1.f, 1e-6f) << wi;
    }
}
