// The rough plastic: flags, parameters, the glossy coating's closed form, the transmittance
// table, eval/pdf/sample consistency, reciprocity, energy and chi-square.

#include "bsdf_checks.h"

#include <facet/fresnel.h>
#include <facet/microfacet.h>
#include <facet/texture.h>

using namespace facet;
using namespace bsdf_checks;

namespace {

const float DefaultEta = 1.49f / 1.000277f;

struct Config {
    const char *name;
    Params params;
};

std::vector<Config> configs() {
    return {
        {"BeckmannDefaults", {}},
        {"BeckmannSharp",
         {{"alpha", 0.05}, {"specular_reflectance", 0.7}, {"diffuse_reflectance", 0.1}}},
        {"BeckmannRoughAll", {{"alpha", 0.7}, {"sample_visible", false}}},
        {"GGX", {{"distribution", std::string("ggx")}, {"alpha", 0.25}}},
        {"GGXAllNonlinear",
         {{"distribution", std::string("ggx")},
          {"alpha", 0.4},
          {"sample_visible", false},
          {"nonlinear", true},
          {"diffuse_reflectance", Color3f(0.9f, 0.4f, 0.1f)}}},
        {"GGXDense", {{"distribution", std::string("ggx")}, {"alpha", 0.15}, {"int_ior", 2.4}}},
    };
}

} // namespace

TEST(RoughPlastic, CreationAndFlags) {
    auto bsdf = make_bsdf("roughplastic");
    ASSERT_EQ(bsdf->component_count(), 2u);
    EXPECT_EQ(bsdf->flags(0),
              BSDFFlags::GlossyReflection | BSDFFlags::FrontSide | BSDFFlags::WiSideOnly);
    EXPECT_EQ(bsdf->flags(1),
              BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide | BSDFFlags::WiSideOnly);
    EXPECT_EQ(bsdf->flags(), bsdf->flags(0) | bsdf->flags(1));
    EXPECT_NE(bsdf->to_string().find("RoughPlastic"), std::string::npos);
    EXPECT_NE(bsdf->to_string().find("beckmann"), std::string::npos);
    // Equal alpha_u and alpha_v are isotropic and accepted.
    auto equal = make_bsdf("roughplastic", {{"alpha_u", 0.2}, {"alpha_v", 0.2}});
    EXPECT_FALSE(has_flag(equal->flags(), BSDFFlags::Anisotropic));
    expect_documented("roughplastic");
    expect_documented("roughplastic", {{"distribution", std::string("ggx")},
                                       {"alpha", 0.3},
                                       {"sample_visible", false},
                                       {"specular_reflectance", 0.5},
                                       {"nonlinear", true},
                                       {"int_ior", 1.6},
                                       {"ext_ior", 1.1}});
}

TEST(RoughPlastic, RejectsBadParameters) {
    expect_error("roughplastic", {{"alpha_u", 0.1}, {"alpha_v", 0.3}}, "isotropic only");
    expect_error("roughplastic", {{"int_ior", 1.3}, {"ext_ior", 1.3}},
                 "int_ior and ext_ior must differ");
    expect_error("roughplastic", {{"distribution", std::string("phong")}},
                 "distribution must be beckmann or ggx");
    expect_error("roughplastic", {{"alpha", -0.2}}, "alpha must be a roughness >= 0");
    expect_error("roughplastic", {{"alpha", 0.1}, {"alpha_u", 0.1}, {"alpha_v", 0.1}},
                 "either alpha or both alpha_u and alpha_v");
    expect_error("roughplastic", {{"alpha_u", 0.1}}, "alpha_u and alpha_v must be given together");
    expect_error("roughplastic", {{"int_ior", std::string("unobtainium")}}, "unknown IOR name");
    expect_error("roughplastic", {{"ext_ior", -1.0}}, "ext_ior must be a positive index");
    expect_error("roughplastic", {{"sample_visible", std::string("yes")}}, "sample_visible");
    expect_error("roughplastic", {{"material", std::string("Cu")}}, "material");
    Properties textured("roughplastic");
    textured.set_object("alpha", std::make_shared<ConstantTexture>(Color3f(0.2f)));
    try {
        PluginRegistry::instance().create(ObjectType::BSDF, textured);
        ADD_FAILURE() << "a textured alpha was accepted";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("must be a number here"), std::string::npos)
            << e.what();
    }
}

TEST(RoughPlastic, GlossyLobeClosedForm) {
    // The glossy component is F·D·G/(4 cos θi), evaluated here from the microfacet header.
    PCG32 rng(5);
    for (const char *distribution : {"beckmann", "ggx"}) {
        auto bsdf = make_bsdf("roughplastic", {{"distribution", std::string(distribution)},
                                               {"alpha", 0.3},
                                               {"specular_reflectance", 0.8}});
        MicrofacetDistribution distr(std::string(distribution) == "ggx" ? MicrofacetType::GGX
                                                                        : MicrofacetType::Beckmann,
                                     0.3f);
        for (int i = 0; i < 100; ++i) {
            Vector3f wi = random_direction(rng, true), wo = random_direction(rng, true);
            Vector3f h = normalize(wi + wo);
            float expected = 0.8f * fresnel_dielectric(dot(wi, h), DefaultEta).F * distr.eval(h) *
                             distr.G(wi, wo, h) / (4.f * wi.z);
            float value = bsdf->eval(component_ctx(0), make_si(wi), wo).r;
            EXPECT_NEAR(value, expected, 1e-4f * expected + 1e-7f) << distribution;
        }
    }
}

TEST(RoughPlastic, DiffuseLobeApproachesSmoothPlastic) {
    // At small roughness the coating's transmittance is 1 − F (smooth Fresnel), so the diffuse
    // lobe tends to plastic's (the internal reflectances differ: rough vs the fdr fit, so compare
    // shapes, i.e. ratios between directions).
    auto rough = make_bsdf("roughplastic", {{"alpha", 0.01}});
    auto smooth = make_bsdf("plastic");
    Vector3f wi = direction_from_angles(30.f, 0.f);
    float ref_r = rough->eval(component_ctx(1), make_si(wi), Vector3f(0.f, 0.f, 1.f)).r;
    float ref_s = smooth->eval(component_ctx(1), make_si(wi), Vector3f(0.f, 0.f, 1.f)).r;
    for (float theta : {10.f, 40.f, 60.f, 75.f}) {
        Vector3f wo = direction_from_angles(theta, 160.f);
        float r = rough->eval(component_ctx(1), make_si(wi), wo).r / ref_r;
        float s = smooth->eval(component_ctx(1), make_si(wi), wo).r / ref_s;
        EXPECT_NEAR(r, s, 0.01f * s) << theta;
    }
    // Normal incidence, diffuse alone: weight = ρ/(1 − fdr)/η²·T(1)·T(cos θo), T(1) ≈ 1 − F(0).
    float F0 = fresnel_dielectric(1.f, DefaultEta).F;
    SurfaceInteraction si = make_si(Vector3f(0.f, 0.f, 1.f));
    Color3f at_normal = rough->eval(component_ctx(1), si, Vector3f(0.f, 0.f, 1.f));
    Color3f smooth_normal = smooth->eval(component_ctx(1), si, Vector3f(0.f, 0.f, 1.f));
    float fdr_smooth = fresnel_diffuse_reflectance(1.f / DefaultEta);
    EXPECT_NEAR(smooth_normal.r,
                0.5f / (1.f - fdr_smooth) / sqr(DefaultEta) * sqr(1.f - F0) * InvPi, 1e-6f);
    EXPECT_GT(at_normal.r, 0.f);
}

TEST(RoughPlastic, TransmittanceMatchesTheRoughDielectric) {
    // The diffuse lobe is proportional to T(cos θi): its ratios between incident angles must be
    // those of the energy a roughdielectric with the same coating transmits (Monte Carlo mean of
    // its transmission-only sample weights in importance mode, no radiance scaling).
    for (const char *distribution : {"beckmann", "ggx"}) {
        Params coating = {
            {"distribution", std::string(distribution)}, {"alpha", 0.3}, {"int_ior", 1.5}};
        auto plastic = make_bsdf("roughplastic", coating);
        auto dielectric = make_bsdf("roughdielectric", coating);
        BSDFContext transmission(TransportMode::Importance);
        transmission.component = 1;
        Vector3f up(0.f, 0.f, 1.f);
        float T_normal = furnace(*dielectric, transmission, up, 40000).r;
        float d_normal = plastic->eval(component_ctx(1), make_si(up), up).r;
        EXPECT_GT(T_normal, 0.9f);
        EXPECT_LT(T_normal, 1.f - 0.03f); // at least the smooth F(0) = 4 % is reflected
        // The glossy lobe is chosen with probability (1 − T)·w / ((1 − T)·w + T·(1 − w)), where
        // w = 1/(1 + 0.5) for the default reflectances.
        float w = 1.f / 1.5f,
              p_spec = (1.f - T_normal) * w / ((1.f - T_normal) * w + T_normal * (1.f - w));
        int n = 10000, glossy = 0;
        for (int i = 0; i < n; ++i) {
            auto [bs, weight] = plastic->sample(BSDFContext(), make_si(up),
                                                (float(i) + 0.5f) / float(n), Point2f(0.3f, 0.7f));
            glossy += bs.sampled_component == 0;
        }
        EXPECT_NEAR(float(glossy) / float(n), p_spec, 2e-3f) << distribution;
        for (float theta : {30.f, 60.f, 75.f, 85.f}) {
            Vector3f wi = direction_from_angles(theta, 0.f);
            float T = furnace(*dielectric, transmission, wi, 40000).r;
            float ratio = plastic->eval(component_ctx(1), make_si(wi), up).r / d_normal;
            EXPECT_NEAR(ratio, T / T_normal, 0.01f) << distribution << " theta " << theta;
        }
    }
}

TEST(RoughPlastic, SampleWeightMatchesEvalPdf) {
    for (const Config &c : configs()) {
        auto bsdf = make_bsdf("roughplastic", c.params);
        EXPECT_GT(check_sample_eval_pdf(*bsdf, BSDFContext(), false, 2000, 3), 1500) << c.name;
        EXPECT_GT(check_sample_eval_pdf(*bsdf, component_ctx(0), false, 500, 4), 250) << c.name;
        EXPECT_GT(check_sample_eval_pdf(*bsdf, component_ctx(1), false, 500, 5), 450) << c.name;
    }
}

TEST(RoughPlastic, Reciprocity) {
    // Both lobes are symmetric: F·D·G/(4 cos θi cos θo) and T(cos θi)·T(cos θo)·const.
    PCG32 rng(12);
    for (const Config &c : configs()) {
        auto bsdf = make_bsdf("roughplastic", c.params);
        for (int i = 0; i < 300; ++i) {
            Vector3f wi = random_direction(rng, true), wo = random_direction(rng, true);
            Color3f f_io = bsdf->eval(BSDFContext(), make_si(wi), wo) / wo.z;
            Color3f f_oi = bsdf->eval(BSDFContext(), make_si(wo), wi) / wi.z;
            for (int ch = 0; ch < 3; ++ch)
                EXPECT_NEAR(f_io[ch], f_oi[ch], 1e-4f * std::max(f_io[ch], f_oi[ch]) + 1e-7f)
                    << c.name;
        }
    }
}

TEST(RoughPlastic, BackSideIsBlack) {
    auto bsdf = make_bsdf("roughplastic");
    Vector3f below = normalize(Vector3f(0.2f, 0.1f, -0.6f)),
             above = normalize(Vector3f(-0.2f, 0.1f, 0.6f));
    for (float s1 : {0.01f, 0.99f})
        EXPECT_TRUE(
            bsdf->sample(BSDFContext(), make_si(below), s1, Point2f(0.3f, 0.4f)).second.is_black());
    EXPECT_TRUE(bsdf->eval(BSDFContext(), make_si(below), above).is_black());
    EXPECT_TRUE(bsdf->eval(BSDFContext(), make_si(above), below).is_black());
    EXPECT_EQ(bsdf->pdf(BSDFContext(), make_si(above), below), 0.f);
    BSDFContext delta_only;
    delta_only.type_mask = uint32_t(BSDFFlags::Delta);
    EXPECT_TRUE(bsdf->eval(delta_only, make_si(above), above).is_black());
    EXPECT_EQ(bsdf->pdf(delta_only, make_si(above), above), 0.f);
}

TEST(RoughPlastic, WhiteFurnaceAtMostOne) {
    PCG32 rng(13);
    for (const Config &c : configs()) {
        // A white base: the config's own diffuse_reflectance is replaced.
        Params white;
        for (const auto &p : c.params)
            if (p.first != "diffuse_reflectance") white.push_back(p);
        white.push_back({"diffuse_reflectance", 1.0});
        auto bsdf = make_bsdf("roughplastic", white);
        for (int i = 0; i < 4; ++i) {
            Vector3f wi = random_direction(rng, true);
            Color3f albedo = furnace(*bsdf, BSDFContext(), wi, 20000);
            EXPECT_LE(albedo.max(), 1.f + 1e-2f) << c.name << " wi " << wi;
            EXPECT_GT(std::min(albedo.r, std::min(albedo.g, albedo.b)), 0.5f) << c.name;
        }
    }
}

// Chi-square tests of this plugin's sampling: tests/chi2/configs.txt (label chi2).

TEST(RoughPlastic, ReflectsOnlyToWiSide) {
    EXPECT_GT(check_wi_side_only(*make_bsdf("roughplastic")), 500);
    EXPECT_GT(check_wi_side_only(*make_bsdf(
                  "roughplastic", {{"alpha", 0.6}, {"distribution", std::string("ggx")}})),
              500);
}
