// The rough conductor: flags, parameters, eval closed form, eval/pdf/sample consistency,
// chi-square of the sampling, reciprocity, energy and textured roughness.

#include "bsdf_checks.h"

#include <facet/conductor_data.h>
#include <facet/fresnel.h>
#include <facet/microfacet.h>

using namespace facet;
using namespace bsdf_checks;

namespace {

/// A roughness that varies over the surface: 0.05 + 0.5·u.
class RoughnessRamp final : public Texture {
public:
    Color3f eval(const SurfaceInteraction &si) const override {
        return Color3f(0.05f + 0.5f * si.uv.x);
    }
    Color3f mean() const override { return Color3f(0.3f); }
    std::string to_string() const override { return "RoughnessRamp"; }
};

struct Config {
    const char *name;
    Params params;
};

std::vector<Config> configs() {
    return {
        {"BeckmannVisible", {{"alpha", 0.2}}},
        {"BeckmannAllNormals", {{"alpha", 0.2}, {"sample_visible", false}}},
        {"BeckmannAnisoVisible", {{"alpha_u", 0.2}, {"alpha_v", 0.05}}},
        {"BeckmannAnisoAll", {{"alpha_u", 0.2}, {"alpha_v", 0.05}, {"sample_visible", false}}},
        {"GGXVisible", {{"distribution", std::string("ggx")}, {"alpha", 0.3}}},
        {"GGXAllNormals",
         {{"distribution", std::string("ggx")}, {"alpha", 0.3}, {"sample_visible", false}}},
        {"GGXAnisoVisible",
         {{"distribution", std::string("ggx")},
          {"alpha_u", 0.05},
          {"alpha_v", 0.4},
          {"material", std::string("Cu")}}},
        {"GGXAnisoAll",
         {{"distribution", std::string("ggx")},
          {"alpha_u", 0.05},
          {"alpha_v", 0.4},
          {"sample_visible", false},
          {"material", std::string("Au")}}},
    };
}

} // namespace

TEST(RoughConductor, CreationAndFlags) {
    auto bsdf = make_bsdf("roughconductor");
    ASSERT_EQ(bsdf->component_count(), 1u);
    EXPECT_EQ(bsdf->flags(), BSDFFlags::GlossyReflection | BSDFFlags::FrontSide |
                                 BSDFFlags::Polarizing | BSDFFlags::WiSideOnly);
    auto aniso = make_bsdf("roughconductor", {{"alpha_u", 0.1}, {"alpha_v", 0.3}});
    EXPECT_EQ(aniso->flags(), BSDFFlags::GlossyReflection | BSDFFlags::FrontSide |
                                  BSDFFlags::Anisotropic | BSDFFlags::Polarizing |
                                  BSDFFlags::WiSideOnly);
    auto equal = make_bsdf("roughconductor", {{"alpha_u", 0.2}, {"alpha_v", 0.2}});
    EXPECT_FALSE(has_flag(equal->flags(), BSDFFlags::Anisotropic));
    EXPECT_NE(bsdf->to_string().find("RoughConductor"), std::string::npos);
    EXPECT_NE(bsdf->to_string().find("beckmann"), std::string::npos);
    expect_documented("roughconductor", {{"alpha", 0.1}});
    expect_documented("roughconductor", {{"alpha_u", 0.1},
                                         {"alpha_v", 0.2},
                                         {"eta", 0.2},
                                         {"k", 3.0},
                                         {"specular_reflectance", 0.5}});
}

TEST(RoughConductor, RejectsBadParameters) {
    expect_error("roughconductor", {{"distribution", std::string("phong")}},
                 "distribution must be beckmann or ggx");
    expect_error("roughconductor", {{"alpha", 0.1}, {"alpha_u", 0.1}, {"alpha_v", 0.1}},
                 "either alpha or both alpha_u and alpha_v");
    expect_error("roughconductor", {{"alpha_u", 0.1}},
                 "alpha_u and alpha_v must be given together");
    expect_error("roughconductor", {{"alpha_v", 0.1}},
                 "alpha_u and alpha_v must be given together");
    expect_error("roughconductor", {{"alpha", -0.2}}, "alpha must be a roughness >= 0");
    expect_error("roughconductor", {{"material", std::string("Cu")}, {"eta", 0.2}}, "not both");
    expect_error("roughconductor", {{"material", std::string("Copper")}},
                 "unknown conductor material");
    expect_error("roughconductor", {{"sample_visible", std::string("yes")}}, "sample_visible");
    expect_error("roughconductor", {{"int_ior", 1.5}}, "int_ior");
}

TEST(RoughConductor, EvalClosedFormAtNormalIncidence) {
    // wi = wo = n: h = n, D = 1/(π α²), G = 1, so f·cos θo = F(1)/(4π α²).
    for (const char *distribution : {"beckmann", "ggx"}) {
        auto bsdf = make_bsdf("roughconductor", {{"distribution", std::string(distribution)},
                                                 {"alpha", 0.3},
                                                 {"material", std::string("Al")}});
        SurfaceInteraction si = make_si(Vector3f(0.f, 0.f, 1.f));
        auto [eta, k] = conductor_eta_k("Al");
        Color3f expected = fresnel_conductor(1.f, eta, k) / (4.f * Pi * 0.09f);
        Color3f value = bsdf->eval(BSDFContext(), si, Vector3f(0.f, 0.f, 1.f));
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(value[c], expected[c], 1e-5f * expected[c]) << distribution;
    }
}

TEST(RoughConductor, SampleWeightMatchesEvalPdf) {
    for (const Config &c : configs()) {
        auto bsdf = make_bsdf("roughconductor", c.params);
        int checked = check_sample_eval_pdf(*bsdf, BSDFContext(), false, 2000, 3);
        EXPECT_GT(checked, 1000) << c.name;
    }
}

TEST(RoughConductor, Reciprocity) {
    // f(wi, wo) = f(wo, wi), with f = eval / |cos θo|.
    PCG32 rng(12);
    for (const Config &c : configs()) {
        auto bsdf = make_bsdf("roughconductor", c.params);
        for (int i = 0; i < 500; ++i) {
            Vector3f wi = random_direction(rng, true), wo = random_direction(rng, true);
            float f_io = bsdf->eval(BSDFContext(), make_si(wi), wo).g / wo.z;
            float f_oi = bsdf->eval(BSDFContext(), make_si(wo), wi).g / wi.z;
            EXPECT_NEAR(f_io, f_oi, 1e-4f * std::max(f_io, f_oi) + 1e-7f) << c.name;
        }
    }
}

TEST(RoughConductor, BackSideIsBlack) {
    auto bsdf = make_bsdf("roughconductor");
    Vector3f below = normalize(Vector3f(0.2f, 0.1f, -0.6f)),
             above = normalize(Vector3f(-0.2f, 0.1f, 0.6f));
    EXPECT_TRUE(
        bsdf->sample(BSDFContext(), make_si(below), 0.5f, Point2f(0.3f, 0.4f)).second.is_black());
    EXPECT_TRUE(bsdf->eval(BSDFContext(), make_si(below), above).is_black());
    EXPECT_TRUE(bsdf->eval(BSDFContext(), make_si(above), below).is_black());
    EXPECT_EQ(bsdf->pdf(BSDFContext(), make_si(above), below), 0.f);
    BSDFContext delta_only;
    delta_only.type_mask = uint32_t(BSDFFlags::Delta);
    EXPECT_TRUE(bsdf->eval(delta_only, make_si(above), above).is_black());
    EXPECT_EQ(bsdf->pdf(delta_only, make_si(above), above), 0.f);
    EXPECT_TRUE(
        bsdf->sample(delta_only, make_si(above), 0.5f, Point2f(0.3f, 0.4f)).second.is_black());
}

TEST(SlowRoughConductor, WhiteFurnaceAtMostOne) {
    // A perfect mirror (material none) loses only what G masks: close to one at low roughness.
    PCG32 rng(13);
    for (const Config &c : configs()) {
        Params params = c.params;
        bool has_material = false;
        for (auto &p : params) has_material |= p.first == "material";
        if (!has_material) params.push_back({"material", std::string("none")});
        auto bsdf = make_bsdf("roughconductor", params);
        for (int i = 0; i < 5; ++i) {
            Vector3f wi = random_direction(rng, true);
            Color3f albedo = furnace(*bsdf, BSDFContext(), wi, 20000);
            EXPECT_LE(albedo.max(), 1.f + 5e-3f) << c.name << " wi " << wi;
        }
    }
    auto smooth =
        make_bsdf("roughconductor", {{"distribution", std::string("ggx")}, {"alpha", 0.05}});
    EXPECT_NEAR(furnace(*smooth, BSDFContext(), Vector3f(0.f, 0.f, 1.f), 20000).r, 1.f, 5e-3f);
}

TEST(RoughConductor, TexturedRoughnessIsEvaluatedPerPoint) {
    Properties props("roughconductor");
    props.set_object("alpha", std::make_shared<RoughnessRamp>());
    auto textured = PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, props);
    EXPECT_TRUE(has_flag(textured->flags(), BSDFFlags::GlossyReflection));
    EXPECT_FALSE(has_flag(textured->flags(), BSDFFlags::Anisotropic));
    EXPECT_TRUE(has_flag(textured->flags(), BSDFFlags::SpatiallyVarying));
    EXPECT_FALSE(has_flag(make_bsdf("roughconductor")->flags(), BSDFFlags::SpatiallyVarying));
    for (float u : {0.f, 0.5f, 1.f}) {
        auto plain = make_bsdf("roughconductor", {{"alpha", double(0.05f + 0.5f * u)}});
        SurfaceInteraction si = make_si(normalize(Vector3f(0.3f, -0.2f, 0.8f)));
        si.uv = Point2f(u, 0.5f);
        Vector3f wo = normalize(Vector3f(-0.4f, 0.1f, 0.7f));
        EXPECT_NEAR(textured->eval(BSDFContext(), si, wo).r, plain->eval(BSDFContext(), si, wo).r,
                    1e-5f * plain->eval(BSDFContext(), si, wo).r)
            << u;
        EXPECT_NEAR(textured->pdf(BSDFContext(), si, wo), plain->pdf(BSDFContext(), si, wo),
                    1e-5f * plain->pdf(BSDFContext(), si, wo))
            << u;
        auto [bs_t, w_t] = textured->sample(BSDFContext(), si, 0.5f, Point2f(0.3f, 0.7f));
        auto [bs_p, w_p] = plain->sample(BSDFContext(), si, 0.5f, Point2f(0.3f, 0.7f));
        EXPECT_EQ(bs_t.wo, bs_p.wo);
        EXPECT_EQ(w_t, w_p);
    }
    // Separate textures for alpha_u and alpha_v make it anisotropic.
    Properties aniso("roughconductor");
    aniso.set_object("alpha_u", std::make_shared<RoughnessRamp>());
    aniso.set_float("alpha_v", 0.1);
    EXPECT_TRUE(
        has_flag(PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, aniso)->flags(),
                 BSDFFlags::Anisotropic));
}

// Chi-square tests of this plugin's sampling: tests/chi2/configs.txt (label chi2).

TEST(RoughConductor, ReflectsOnlyToWiSide) {
    // A wide lobe, so that many mirrored directions have light; and an anisotropic one.
    EXPECT_GT(check_wi_side_only(*make_bsdf("roughconductor", {{"alpha", 0.8}})), 500);
    EXPECT_GT(check_wi_side_only(*make_bsdf(
                  "roughconductor",
                  {{"alpha_u", 0.9}, {"alpha_v", 0.4}, {"distribution", std::string("ggx")}})),
              500);
}
