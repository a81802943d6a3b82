// The thin principled BSDF: flags and components, parameter errors, the two-sided symmetry,
// closed forms (the Lambertian diffuse transmission, the Burley diffuse), eval/pdf/sample
// consistency on both sides, the pdf against the sampling frequencies, energy and reciprocity.

#include "bsdf_checks.h"

#include <facet/fresnel.h>
#include <facet/microfacet.h>
#include <facet/texture.h>

using namespace facet;
using namespace bsdf_checks;

namespace {

struct Config {
    const char *name;
    Params params;
};

std::vector<Config> configs() {
    return {
        {"Defaults", {}},
        {"Leaf",
         {{"base_color", Color3f(0.3f, 0.7f, 0.2f)}, {"diff_trans", 1.2}, {"roughness", 0.6}}},
        {"Pane", {{"spec_trans", 0.9}, {"roughness", 0.2}, {"eta", 1.5}, {"spec_tint", 0.3}}},
        {"Mixed",
         {{"base_color", Color3f(0.7f, 0.1f, 0.1f)},
          {"roughness", 0.35},
          {"anisotropic", 0.5},
          {"spec_trans", 0.5},
          {"diff_trans", 0.6},
          {"sheen", 0.7},
          {"sheen_tint", 0.4},
          {"flatness", 0.3},
          {"eta", 1.33},
          {"diffuse_transmittance_sampling_rate", 2.0}}},
        {"AllTransmitted", {{"diff_trans", 2.0}}},
    };
}

} // namespace

TEST(PrincipledThin, CreationAndFlags) {
    BSDFFlags sides = BSDFFlags::FrontSide | BSDFFlags::BackSide;
    auto plain = make_bsdf("principledthin");
    ASSERT_EQ(plain->component_count(), 3u);
    EXPECT_EQ(plain->flags(0), BSDFFlags::DiffuseReflection | sides);
    EXPECT_EQ(plain->flags(1), BSDFFlags::DiffuseTransmission | sides);
    EXPECT_EQ(plain->flags(2), BSDFFlags::GlossyReflection | sides);
    auto full = make_bsdf("principledthin", {{"spec_trans", 0.5}, {"anisotropic", 0.4}});
    ASSERT_EQ(full->component_count(), 4u);
    EXPECT_EQ(full->flags(2), BSDFFlags::GlossyTransmission | sides | BSDFFlags::Anisotropic);
    EXPECT_EQ(full->flags(3), BSDFFlags::GlossyReflection | sides | BSDFFlags::Anisotropic);
    EXPECT_NE(full->to_string().find("PrincipledThin"), std::string::npos);
    Properties textured("principledthin");
    textured.set_object("diff_trans", std::make_shared<RampTexture>());
    auto tex = PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, textured);
    EXPECT_TRUE(has_flag(tex->flags(1), BSDFFlags::SpatiallyVarying));
    expect_documented("principledthin");
    expect_documented("principledthin", configs()[3].params);
    expect_documented("principledthin", {{"specular_reflectance_sampling_rate", 0.5},
                                         {"specular_transmittance_sampling_rate", 0.5},
                                         {"diffuse_reflectance_sampling_rate", 0.5},
                                         {"sample_visible", false}});
}

TEST(PrincipledThin, RejectsBadParameters) {
    expect_error("principledthin", {{"diff_trans", 2.5}}, "diff_trans must be in [0, 2]");
    expect_error("principledthin", {{"diff_trans", -0.5}}, "diff_trans must be in [0, 2]");
    expect_error("principledthin", {{"eta", -1.5}}, "eta must be a positive");
    expect_error("principledthin", {{"specular_transmittance_sampling_rate", -1.0}},
                 "specular_transmittance_sampling_rate must be >= 0");
    // principled's parameters that the thin sheet does not have.
    expect_error("principledthin", {{"metallic", 0.5}}, "metallic");
    expect_error("principledthin", {{"clearcoat", 0.5}}, "clearcoat");
}

TEST(PrincipledThin, BothSidesAlike) {
    // The sheet is symmetric: mirroring wi and wo through it changes nothing.
    PCG32 rng(3);
    for (const Config &c : configs()) {
        auto bsdf = make_bsdf("principledthin", c.params);
        for (int i = 0; i < 200; ++i) {
            Vector3f wi = random_direction(rng, false), wo = random_direction(rng, false);
            Vector3f wi_m(wi.x, wi.y, -wi.z), wo_m(wo.x, wo.y, -wo.z);
            auto [v, p] = bsdf->eval_pdf(BSDFContext(), make_si(wi), wo);
            auto [vm, pm] = bsdf->eval_pdf(BSDFContext(), make_si(wi_m), wo_m);
            EXPECT_NEAR(p, pm, 1e-5f * p + 1e-7f) << c.name;
            for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(v[ch], vm[ch], 1e-5f * v[ch] + 1e-7f);
        }
    }
}

TEST(PrincipledThin, DiffuseClosedForms) {
    Color3f base(0.3f, 0.7f, 0.2f);
    float r = 0.6f, dt = 1.2f;
    auto bsdf = make_bsdf("principledthin",
                          {{"base_color", base}, {"diff_trans", double(dt)}, {"roughness", 0.6}});
    for (auto [ti, to, phi] : {std::tuple{30.f, 60.f, 180.f}, std::tuple{65.f, 40.f, 70.f}}) {
        Vector3f wi = direction_from_angles(ti, 0.f), wo = direction_from_angles(to, phi);
        // Transmission: Lambertian (d = diff_trans/2)·base/π·|cos θo| through the sheet.
        Vector3f wt(wo.x, wo.y, -wo.z);
        Color3f t = bsdf->eval(component_ctx(1), make_si(wi), wt);
        // Reflection: (1 − d)·Burley diffuse with retro-reflection.
        float fi = std::pow(1.f - wi.z, 5.f), fo = std::pow(1.f - wo.z, 5.f);
        float cos_d = dot(normalize(wi + wo), wo), rr = 2.f * r * cos_d * cos_d;
        float f = (1.f - 0.5f * fi) * (1.f - 0.5f * fo) + rr * (fo + fi + fo * fi * (rr - 1.f));
        Color3f refl = bsdf->eval(component_ctx(0), make_si(wi), wo);
        for (int ch = 0; ch < 3; ++ch) {
            EXPECT_NEAR(t[ch], 0.5f * dt * base[ch] * InvPi * wo.z, 1e-6f);
            EXPECT_NEAR(refl[ch], (1.f - 0.5f * dt) * base[ch] * InvPi * f * wo.z, 1e-6f);
        }
    }
}

TEST(PrincipledThin, GlossyClosedForm) {
    // spec_trans = 1: reflection F·D·G/(4 cos θi); transmission base·(1 − F)·D'·G'/(4 cos θi) about
    // the mirrored direction, D' with the roughness scaled by 0.65η − 0.35.
    float eta = 1.5f, r = 0.4f;
    auto bsdf = make_bsdf("principledthin",
                          {{"spec_trans", 1.0}, {"roughness", double(r)}, {"eta", double(eta)}});
    Vector3f wi = direction_from_angles(40.f, 0.f), wo = direction_from_angles(35.f, 170.f);
    Vector3f h = normalize(wi + wo);
    float F = fresnel_dielectric(dot(wi, h), eta).F;
    MicrofacetDistribution d(MicrofacetType::GGX, r * r);
    float refl = F * d.eval(h) * d.G(wi, wo, h) / (4.f * wi.z);
    EXPECT_NEAR(bsdf->eval(BSDFContext(), make_si(wi), wo).r, refl, 1e-5f * refl);
    Vector3f wt(wo.x, wo.y, -wo.z);
    float rs = (0.65f * eta - 0.35f) * r;
    MicrofacetDistribution ds(MicrofacetType::GGX, rs * rs);
    float trans = 0.5f * (1.f - F) * ds.eval(h) * ds.G(wi, wt, h) / (4.f * wi.z);
    EXPECT_NEAR(bsdf->eval(BSDFContext(), make_si(wi), wt).r, trans, 1e-5f * trans);
}

TEST(PrincipledThin, SampleWeightMatchesEvalPdf) {
    for (const Config &c : configs()) {
        auto bsdf = make_bsdf("principledthin", c.params);
        EXPECT_GT(check_sample_eval_pdf(*bsdf, BSDFContext(), true, 2000, 3), 1000) << c.name;
        for (uint32_t k = 0; k < bsdf->component_count(); ++k)
            check_sample_eval_pdf(*bsdf, component_ctx(k), true, 300, 4 + k);
    }
}

TEST(PrincipledThin, PdfMatchesSampling) {
    std::vector<Config> broad = {
        configs()[0],
        configs()[1],
        configs()[4],
        {"RoughMixed",
         {{"spec_trans", 0.6}, {"roughness", 0.6}, {"diff_trans", 0.8}, {"anisotropic", 0.5}}},
    };
    for (const Config &c : broad) {
        auto bsdf = make_bsdf("principledthin", c.params);
        for (float z : {0.8f, 0.3f, -0.5f}) {
            SurfaceInteraction si = make_si(normalize(Vector3f(std::sqrt(1.f - z * z), 0.1f, z)));
            EXPECT_NEAR(pdf_sphere_integral(*bsdf, BSDFContext(), si),
                        sampled_fraction(*bsdf, BSDFContext(), si), 0.01)
                << c.name << " z = " << z;
        }
    }
}

TEST(PrincipledThin, EnergyConservation) {
    // Reflection plus transmission stay below one (no η² factor: a thin sheet does not bend).
    for (const Config &c : configs()) {
        auto bsdf = make_bsdf("principledthin", c.params);
        for (float theta : {0.f, 45.f, 75.f}) {
            for (float side : {1.f, -1.f}) {
                Vector3f wi = direction_from_angles(theta, 20.f);
                wi.z *= side;
                Color3f albedo = furnace(*bsdf, BSDFContext(), wi, 20000);
                for (int ch = 0; ch < 3; ++ch)
                    EXPECT_LE(albedo[ch], 1.02f) << c.name << " theta " << theta;
            }
        }
    }
    // All transmitted: diff_trans = 2 is a Lambertian transmitter of albedo base_color.
    auto t = make_bsdf("principledthin", {{"diff_trans", 2.0}, {"base_color", 0.8}});
    Color3f albedo = furnace(*t, BSDFContext(), direction_from_angles(30.f, 0.f), 20000);
    EXPECT_NEAR(albedo.r, 0.8f, 1e-4f);
}

TEST(PrincipledThin, Reciprocity) {
    // Diffuse reflection and transmission, sheen and the glossy reflection are symmetric.
    PCG32 rng(12);
    for (const char *name : {"Defaults", "Leaf", "AllTransmitted"}) {
        Params params;
        for (const Config &c : configs())
            if (std::string(c.name) == name) params = c.params;
        auto bsdf = make_bsdf("principledthin", params);
        for (int i = 0; i < 300; ++i) {
            Vector3f wi = random_direction(rng, false), wo = random_direction(rng, false);
            Color3f f_io = bsdf->eval(BSDFContext(), make_si(wi), wo) / std::abs(wo.z);
            Color3f f_oi = bsdf->eval(BSDFContext(), make_si(wo), wi) / std::abs(wi.z);
            for (int ch = 0; ch < 3; ++ch)
                EXPECT_NEAR(f_io[ch], f_oi[ch], 2e-3f * std::max(f_io[ch], f_oi[ch]) + 1e-6f)
                    << name;
        }
    }
}
