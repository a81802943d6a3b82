// The principled BSDF: flags and components, parameter errors, closed forms (the metallic limit
// against the conductor Fresnel of base_color, the Burley diffuse, the clearcoat's GTR1),
// eval/pdf/sample consistency, the pdf against the sampling frequencies, energy and reciprocity.

#include "bsdf_checks.h"

#include <facet/fresnel.h>
#include <facet/microfacet.h>
#include <facet/principled.h>
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
        {"Metallic",
         {{"base_color", Color3f(0.9f, 0.6f, 0.2f)}, {"metallic", 1.0}, {"roughness", 0.3}}},
        {"AnisotropicMetal",
         {{"metallic", 0.8}, {"roughness", 0.5}, {"anisotropic", 0.8}, {"spec_tint", 0.3}}},
        {"Glass", {{"spec_trans", 0.85}, {"roughness", 0.15}, {"eta", 1.45}}},
        {"Clearcoat",
         {{"base_color", Color3f(0.7f, 0.1f, 0.1f)},
          {"roughness", 0.6},
          {"clearcoat", 1.0},
          {"clearcoat_gloss", 0.8}}},
        {"SheenFlat",
         {{"roughness", 0.8},
          {"sheen", 1.0},
          {"sheen_tint", 0.5},
          {"flatness", 0.7},
          {"specular", 0.3},
          {"spec_tint", 0.4}}},
        {"Everything",
         {{"base_color", Color3f(1.f, 0.8f, 0.6f)},
          {"metallic", 0.3},
          {"specular", 0.6},
          {"roughness", 0.2},
          {"spec_tint", 0.4},
          {"anisotropic", 0.5},
          {"sheen", 0.3},
          {"sheen_tint", 0.2},
          {"clearcoat", 0.6},
          {"clearcoat_gloss", 0.3},
          {"spec_trans", 0.4},
          {"clearcoat_sampling_rate", 2.0},
          {"diffuse_reflectance_sampling_rate", 0.5}}},
    };
}

} // namespace

TEST(Principled, CreationAndFlags) {
    auto plain = make_bsdf("principled");
    ASSERT_EQ(plain->component_count(), 2u);
    EXPECT_EQ(plain->flags(0), BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide);
    EXPECT_EQ(plain->flags(1),
              BSDFFlags::GlossyReflection | BSDFFlags::FrontSide | BSDFFlags::BackSide);
    EXPECT_NE(plain->to_string().find("Principled"), std::string::npos);

    auto full =
        make_bsdf("principled", {{"clearcoat", 0.5}, {"spec_trans", 0.5}, {"anisotropic", 0.3}});
    ASSERT_EQ(full->component_count(), 4u);
    EXPECT_EQ(full->flags(1), BSDFFlags::GlossyReflection | BSDFFlags::FrontSide);
    EXPECT_EQ(full->flags(2), BSDFFlags::GlossyTransmission | BSDFFlags::FrontSide |
                                  BSDFFlags::BackSide | BSDFFlags::NonSymmetric |
                                  BSDFFlags::Anisotropic);
    EXPECT_TRUE(has_flag(full->flags(3), BSDFFlags::Anisotropic));
    // A lobe given as the number 0 is off, like an absent one.
    EXPECT_EQ(make_bsdf("principled", {{"clearcoat", 0.0}, {"spec_trans", 0.0}})->component_count(),
              2u);

    Properties textured("principled");
    textured.set_object("roughness", std::make_shared<RampTexture>());
    auto tex = PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, textured);
    EXPECT_TRUE(has_flag(tex->flags(), BSDFFlags::SpatiallyVarying));
    EXPECT_FALSE(has_flag(plain->flags(), BSDFFlags::SpatiallyVarying));

    expect_documented("principled");
    expect_documented("principled", {{"eta", 1.5}, {"sample_visible", false}});
    expect_documented("principled", configs().back().params);
}

TEST(Principled, RejectsBadParameters) {
    expect_error("principled", {{"eta", 1.5}, {"specular", 0.5}}, "either eta or specular");
    expect_error("principled", {{"eta", -1.0}}, "eta must be a positive");
    expect_error("principled", {{"specular", -0.1}}, "specular must be in [0, 12.5)");
    expect_error("principled", {{"specular", 13.0}}, "specular must be in [0, 12.5)");
    expect_error("principled", {{"clearcoat_sampling_rate", -1.0}},
                 "clearcoat_sampling_rate must be >= 0");
    expect_error("principled", {{"main_specular_sampling_rate", -1.0}},
                 "main_specular_sampling_rate must be >= 0");
    expect_error("principled", {{"alpha", 0.2}}, "alpha");
}

TEST(Principled, SpecularMapsToEta) {
    // η = 2/(1 − √(0.08·specular)) − 1, so that ((η − 1)/(η + 1))² = 0.08·specular: at normal
    // incidence the smooth dielectric reflection (metallic 0, no diffuse from spec_trans 1 is not
    // needed: compare the main lobe's Fresnel at low roughness through its closed form).
    for (double specular : {0.2, 0.5, 1.0}) {
        float eta = 2.f / (1.f - std::sqrt(0.08f * float(specular))) - 1.f;
        EXPECT_NEAR(principled::schlick_r0(eta), 0.08f * float(specular), 1e-5f);
        auto a = make_bsdf("principled", {{"specular", specular}, {"roughness", 0.4}});
        auto b = make_bsdf("principled", {{"eta", double(eta)}, {"roughness", 0.4}});
        Vector3f wi = direction_from_angles(40.f, 0.f), wo = direction_from_angles(30.f, 170.f);
        Color3f va = a->eval(BSDFContext(), make_si(wi), wo),
                vb = b->eval(BSDFContext(), make_si(wi), wo);
        EXPECT_NEAR(va.r, vb.r, 1e-5f * vb.r);
    }
}

TEST(Principled, MetallicSmoothLimitIsSchlickOfBaseColor) {
    // metallic = 1, roughness → 0: the lobe is a near-mirror whose albedo is Schlick's Fresnel
    // with R0 = base_color, F = R0 + (1 − R0)(1 − cos θ)⁵ (Burley 2012), compared with the
    // furnace of the sampled weights at 30°, 60° and 80°. Against the exact conductor Fresnel of an
    // IOR whose normal reflectance is base_color (k = 0, η = (1 + √R0)/(1 − √R0)) Schlick is within
    // 0.01 at 30° (at 60° it is 0.02–0.05 above, at 80° up to 0.3: Mitsuba's metal is Schlick's).
    Color3f base(0.9f, 0.6f, 0.2f);
    auto bsdf =
        make_bsdf("principled", {{"base_color", base}, {"metallic", 1.0}, {"roughness", 0.02}});
    for (float theta : {30.f, 60.f, 80.f}) {
        Vector3f wi = direction_from_angles(theta, 0.f);
        Color3f albedo = furnace(*bsdf, BSDFContext(), wi, 20000);
        float c = std::cos(theta * Pi / 180.f), w = std::pow(1.f - c, 5.f);
        for (int ch = 0; ch < 3; ++ch) {
            float schlick = base[ch] + (1.f - base[ch]) * w;
            // Masking at α = 4e-4 is 1 up to 80°: the albedo is F.
            EXPECT_NEAR(albedo[ch], schlick, 2e-3f) << theta << " channel " << ch;
            // Schlick's approximation departs from the exact Fresnel away from normal
            // incidence; at 30° they still agree.
            if (theta < 45.f) {
                float s = std::sqrt(base[ch]);
                float exact = fresnel_conductor(c, (1.f + s) / (1.f - s), 0.f);
                EXPECT_NEAR(albedo[ch], exact, 0.01f) << theta << " channel " << ch;
            }
        }
    }
}

TEST(Principled, DiffuseLobeClosedForm) {
    // Component 0 alone (roughness r, no sheen, no flatness) is Burley's diffuse:
    // base/π·((1 − Fi/2)(1 − Fo/2) + R_R(Fo + Fi + Fo·Fi(R_R − 1)))·cos θo, R_R = 2r·cos²θd.
    Color3f base(0.2f, 0.5f, 0.8f);
    float r = 0.7f;
    auto bsdf = make_bsdf("principled", {{"base_color", base}, {"roughness", double(r)}});
    for (auto [ti, to, phi] : {std::tuple{30.f, 60.f, 180.f}, std::tuple{60.f, 45.f, 90.f},
                               std::tuple{75.f, 20.f, 10.f}}) {
        Vector3f wi = direction_from_angles(ti, 0.f), wo = direction_from_angles(to, phi);
        float fi = std::pow(1.f - wi.z, 5.f), fo = std::pow(1.f - wo.z, 5.f);
        float cos_d = dot(normalize(wi + wo), wo);
        float rr = 2.f * r * cos_d * cos_d;
        float f = (1.f - 0.5f * fi) * (1.f - 0.5f * fo) + rr * (fo + fi + fo * fi * (rr - 1.f));
        Color3f value = bsdf->eval(component_ctx(0), make_si(wi), wo);
        for (int ch = 0; ch < 3; ++ch)
            EXPECT_NEAR(value[ch], base[ch] * InvPi * f * wo.z, 1e-6f) << ti << " " << to;
    }
    // Sheen adds sheen·(1 − cos θd)⁵·cos θo (untinted).
    auto sheen =
        make_bsdf("principled", {{"base_color", base}, {"roughness", double(r)}, {"sheen", 0.8}});
    Vector3f wi = direction_from_angles(70.f, 0.f), wo = direction_from_angles(65.f, 60.f);
    float cos_d = dot(normalize(wi + wo), wo);
    Color3f diff = sheen->eval(component_ctx(0), make_si(wi), wo) -
                   bsdf->eval(component_ctx(0), make_si(wi), wo);
    EXPECT_NEAR(diff.g, 0.8f * std::pow(1.f - cos_d, 5.f) * wo.z, 1e-6f);
}

TEST(Principled, ClearcoatClosedForm) {
    // 0.25·clearcoat·F_schlick(0.04)·D_GTR1·G·cos θo, with D normalised: ∫ D cos θm dω = 1.
    principled::GTR1 d(0.05f);
    double integral = 0.0;
    const int n = 4000;
    for (int i = 0; i < n; ++i) {
        float mu = (float(i) + 0.5f) / float(n);
        integral += double(d.eval(Vector3f(std::sqrt(1.f - mu * mu), 0.f, mu))) * mu;
    }
    EXPECT_NEAR(integral * 2.0 * double(Pi) / n, 1.0, 2e-3);

    auto bsdf = make_bsdf("principled", {{"clearcoat", 0.8}, {"clearcoat_gloss", 0.5}});
    Vector3f wi = direction_from_angles(50.f, 0.f), wo = direction_from_angles(40.f, 180.f);
    Vector3f h = normalize(wi + wo);
    float alpha = 0.1f + (0.001f - 0.1f) * 0.5f;
    float F = 0.04f + 0.96f * std::pow(1.f - dot(wi, h), 5.f);
    float expected = 0.25f * 0.8f * F * principled::GTR1(alpha).eval(h) *
                     principled::clearcoat_g(wi, wo, h) * wo.z;
    EXPECT_NEAR(bsdf->eval(component_ctx(1), make_si(wi), wo).r, expected, 1e-5f * expected);
}

TEST(Principled, SampleWeightMatchesEvalPdf) {
    for (const Config &c : configs()) {
        auto bsdf = make_bsdf("principled", c.params);
        bool both = has_flag(bsdf->flags(), BSDFFlags::GlossyTransmission);
        EXPECT_GT(check_sample_eval_pdf(*bsdf, BSDFContext(), both, 2000, 3), 1000) << c.name;
        for (uint32_t k = 0; k < bsdf->component_count(); ++k) {
            int checked = check_sample_eval_pdf(*bsdf, component_ctx(k), both, 400, 4 + k);
            // A fully metallic material has no diffuse lobe to sample.
            if (std::string(c.name) != "Metallic" || k != 0) {
                EXPECT_GT(checked, 100) << c.name << " component " << k;
            }
        }
        EXPECT_GT(
            check_sample_eval_pdf(*bsdf, BSDFContext(TransportMode::Importance), both, 500, 9), 250)
            << c.name;
    }
}

TEST(Principled, PdfMatchesSampling) {
    // The density integrates over the sphere to the fraction of successful samples.
    // Lobes broad enough for a uniform-sphere estimate of the integral (the sharp ones are
    // covered by the chi-square lines).
    std::vector<Config> broad = {
        {"Defaults", {}},
        {"AnisotropicMetal", {{"metallic", 0.8}, {"roughness", 0.5}, {"anisotropic", 0.8}}},
        {"RoughClearcoat", {{"clearcoat", 1.0}, {"clearcoat_gloss", 0.0}, {"roughness", 0.7}}},
        {"RoughGlass", {{"spec_trans", 0.9}, {"roughness", 0.5}, {"eta", 1.5}}},
        {"SheenFlat", {{"roughness", 0.8}, {"sheen", 1.0}, {"flatness", 0.7}}},
    };
    for (const Config &c : broad) {
        auto bsdf = make_bsdf("principled", c.params);
        for (float z : {0.8f, 0.3f, -0.5f}) {
            if (z < 0.f && !has_flag(bsdf->flags(), BSDFFlags::GlossyTransmission)) continue;
            Vector3f wi = normalize(Vector3f(std::sqrt(1.f - z * z), 0.1f, z));
            SurfaceInteraction si = make_si(wi);
            EXPECT_NEAR(pdf_sphere_integral(*bsdf, BSDFContext(), si),
                        sampled_fraction(*bsdf, BSDFContext(), si), 0.01)
                << c.name << " z = " << z;
        }
    }
}

TEST(Principled, EnergyConservation) {
    // Configurations whose lobes Mitsuba's model keeps below one: metals, plain dielectric
    // bases, glass. The model adds the sheen and the clearcoat on top of the base without taking
    // their energy from it, so "Everything" (a white base under both) reflects up to 8 % more
    // than it receives at grazing angles, as Mitsuba's does: it is left out.
    for (const Config &c : configs()) {
        if (std::string(c.name) == "Everything") continue;
        auto bsdf = make_bsdf("principled", c.params);
        for (float theta : {0.f, 40.f, 70.f, 85.f}) {
            Color3f albedo = furnace(*bsdf, BSDFContext(TransportMode::Importance),
                                     direction_from_angles(theta, 30.f), 20000);
            for (int ch = 0; ch < 3; ++ch)
                EXPECT_LE(albedo[ch], 1.02f) << c.name << " theta " << theta;
        }
    }
    // Retro-reflection can push the Burley diffuse above one at high roughness: that is the
    // model, so only the metal and glass are held to 1 from inside as well.
    auto glass = make_bsdf(
        "principled", {{"spec_trans", 1.0}, {"roughness", 0.3}, {"eta", 1.5}, {"base_color", 1.0}});
    Color3f inside = furnace(*glass, BSDFContext(TransportMode::Importance),
                             normalize(Vector3f(0.3f, 0.f, -0.8f)), 20000);
    EXPECT_LE(inside.r, 1.01f);
    EXPECT_GT(inside.r, 0.9f);
}

TEST(Principled, Reciprocity) {
    // The reflection lobes are symmetric in (wi, wo) (Disney diffuse, sheen, the dielectric and
    // metallic main lobe and the clearcoat); the transmission is not (it is NonSymmetric).
    PCG32 rng(12);
    for (const Config &c : configs()) {
        auto bsdf = make_bsdf("principled", c.params);
        for (int i = 0; i < 300; ++i) {
            Vector3f wi = random_direction(rng, true), wo = random_direction(rng, true);
            Color3f f_io = bsdf->eval(BSDFContext(), make_si(wi), wo) / wo.z;
            Color3f f_oi = bsdf->eval(BSDFContext(), make_si(wo), wi) / wi.z;
            for (int ch = 0; ch < 3; ++ch)
                EXPECT_NEAR(f_io[ch], f_oi[ch], 2e-3f * std::max(f_io[ch], f_oi[ch]) + 1e-6f)
                    << c.name << " wi " << wi << " wo " << wo;
        }
    }
}

TEST(Principled, BackSideIsDielectricOnly) {
    // Without spec_trans the back side is black; with it only F and 1 − F of the dielectric
    // remain (no diffuse, no clearcoat).
    Vector3f below = normalize(Vector3f(0.2f, 0.1f, -0.6f)),
             below2 = normalize(Vector3f(-0.3f, 0.2f, -0.7f));
    auto opaque = make_bsdf("principled", {{"clearcoat", 1.0}});
    EXPECT_TRUE(opaque->eval(BSDFContext(), make_si(below), below2).is_black());
    EXPECT_TRUE(
        opaque->sample(BSDFContext(), make_si(below), 0.5f, Point2f(0.3f, 0.6f)).second.is_black());
    auto glass = make_bsdf("principled", {{"spec_trans", 1.0}, {"clearcoat", 1.0}});
    EXPECT_TRUE(glass->eval(component_ctx(0), make_si(below), below2).is_black());
    EXPECT_TRUE(glass->eval(component_ctx(1), make_si(below), below2).is_black());
}

TEST(Principled, ScalarParametersUseTheScalarQuery) {
    // A texture whose colour and scalar queries differ: the scalar one must drive metallic.
    class SplitTexture final : public Texture {
    public:
        Color3f eval(const SurfaceInteraction &) const override { return Color3f(0.f); }
        float eval_1(const SurfaceInteraction &) const override { return 1.f; }
        Color3f mean() const override { return Color3f(0.f); }
        std::string to_string() const override { return "SplitTexture"; }
    };
    Properties props("principled");
    props.set_object("metallic", std::make_shared<SplitTexture>());
    auto bsdf = PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, props);
    Vector3f wi = direction_from_angles(30.f, 0.f), wo = direction_from_angles(50.f, 120.f);
    // Fully metallic: no diffuse.
    EXPECT_TRUE(bsdf->eval(component_ctx(0), make_si(wi), wo).is_black());
}
