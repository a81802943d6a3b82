// The rough dielectric: flags, parameters, eval/pdf/sample consistency on both sides and in both
// transport modes, Snell's law about the microfacet normal, the η² radiance scaling, generalised
// reciprocity, single-lobe contexts, energy and chi-square of the sampling.

#include "bsdf_checks.h"
#include "draws.h"

#include <facet/fresnel.h>
#include <facet/microfacet.h>

using namespace facet;
using namespace bsdf_checks;

namespace {

struct Config {
    const char *name;
    Params params;
};

std::vector<Config> configs() {
    return {
        {"BeckmannVisible", {{"alpha", 0.3}}},
        {"BeckmannAllNormals", {{"alpha", 0.3}, {"sample_visible", false}}},
        {"BeckmannAnisoVisible",
         {{"alpha_u", 0.4}, {"alpha_v", 0.1}, {"int_ior", std::string("diamond")}}},
        {"GGXVisible", {{"distribution", std::string("ggx")}, {"alpha", 0.2}}},
        {"GGXAllNormals",
         {{"distribution", std::string("ggx")}, {"alpha", 0.2}, {"sample_visible", false}}},
        {"GGXAnisoAll",
         {{"distribution", std::string("ggx")},
          {"alpha_u", 0.05},
          {"alpha_v", 0.5},
          {"sample_visible", false}}},
        {"DenserOutside",
         {{"distribution", std::string("ggx")},
          {"alpha", 0.4},
          {"int_ior", 1.0},
          {"ext_ior", 1.5}}},
    };
}

BSDFContext make_ctx(TransportMode mode, uint32_t component = uint32_t(-1)) {
    BSDFContext ctx(mode);
    ctx.component = component;
    return ctx;
}

float relative_eta(const BSDF &bsdf) {
    // η_it for light arriving from outside at normal incidence.
    auto [bs, w] = bsdf.sample(make_ctx(TransportMode::Importance, 1),
                               make_si(Vector3f(0.f, 0.f, 1.f)), 0.5f, Point2f(0.5f, 0.5f));
    return bs.eta;
}

} // namespace

TEST(RoughDielectric, CreationAndFlags) {
    auto bsdf = make_bsdf("roughdielectric");
    ASSERT_EQ(bsdf->component_count(), 2u);
    BSDFFlags sides = BSDFFlags::FrontSide | BSDFFlags::BackSide;
    EXPECT_EQ(bsdf->flags(0), BSDFFlags::GlossyReflection | sides);
    EXPECT_EQ(bsdf->flags(1), BSDFFlags::GlossyTransmission | sides | BSDFFlags::NonSymmetric);
    auto aniso = make_bsdf("roughdielectric", {{"alpha_u", 0.1}, {"alpha_v", 0.3}});
    EXPECT_TRUE(has_flag(aniso->flags(0), BSDFFlags::Anisotropic));
    EXPECT_TRUE(has_flag(aniso->flags(1), BSDFFlags::Anisotropic));
    EXPECT_NE(bsdf->to_string().find("RoughDielectric"), std::string::npos);
    EXPECT_NEAR(relative_eta(*bsdf), 1.5046f / 1.000277f, 1e-5f);
    expect_documented(
        "roughdielectric",
        {{"alpha", 0.1}, {"specular_reflectance", 0.5}, {"specular_transmittance", 0.5}});
    expect_documented("roughdielectric", {{"alpha_u", 0.1}, {"alpha_v", 0.2}});
}

TEST(RoughDielectric, RejectsBadParameters) {
    expect_error("roughdielectric", {{"distribution", std::string("blinn")}},
                 "distribution must be beckmann or ggx");
    expect_error("roughdielectric", {{"alpha", 0.1}, {"alpha_v", 0.1}}, "either alpha or both");
    expect_error("roughdielectric", {{"alpha_u", 0.1}}, "must be given together");
    expect_error("roughdielectric", {{"alpha", -1.0}}, "alpha must be a roughness >= 0");
    expect_error("roughdielectric", {{"int_ior", std::string("glass")}}, "unknown IOR name");
    expect_error("roughdielectric", {{"ext_ior", -1.0}}, "ext_ior must be a positive index");
    expect_error("roughdielectric", {{"material", std::string("Cu")}}, "material");
}

TEST(RoughDielectric, SampleWeightMatchesEvalPdf) {
    for (const Config &c : configs()) {
        auto bsdf = make_bsdf("roughdielectric", c.params);
        for (TransportMode mode : {TransportMode::Radiance, TransportMode::Importance}) {
            int checked = check_sample_eval_pdf(*bsdf, make_ctx(mode), true, 2000, 5);
            EXPECT_GT(checked, 1500) << c.name;
            // Single-lobe contexts: the lobe is always taken and its pdf carries no F.
            EXPECT_GT(check_sample_eval_pdf(*bsdf, make_ctx(mode, 0), true, 500, 6), 300) << c.name;
            EXPECT_GT(check_sample_eval_pdf(*bsdf, make_ctx(mode, 1), true, 500, 7), 200) << c.name;
        }
    }
}

TEST(RoughDielectric, RefractionFollowsSnellsLawAboutTheMicronormal) {
    for (const Config &c : configs()) {
        auto bsdf = make_bsdf("roughdielectric", c.params);
        float eta = relative_eta(*bsdf);
        PCG32 rng(31);
        int refracted = 0;
        for (int i = 0; i < 3000; ++i) {
            SurfaceInteraction si = make_si(random_direction(rng, false));
            float s1 = rng.next_float();
            auto [bs, weight] = bsdf->sample(BSDFContext(), si, s1, next_point2f(rng));
            if (weight.is_black() || bs.sampled_type != BSDFFlags::GlossyTransmission) continue;
            ++refracted;
            float cos_i = si.wi.z;
            EXPECT_LT(bs.wo.z * cos_i, 0.f);
            float eta_i = cos_i > 0.f ? 1.f : eta, eta_t = cos_i > 0.f ? eta : 1.f;
            EXPECT_NEAR(bs.eta, eta_t / eta_i, 1e-5f);
            // The refracting facet's normal is the generalised half vector of wi and wo.
            Vector3f m = normalize(si.wi * eta_i + bs.wo * eta_t);
            float sin_i = std::sqrt(std::max(0.f, 1.f - sqr(dot(si.wi, m))));
            float sin_t = std::sqrt(std::max(0.f, 1.f - sqr(dot(bs.wo, m))));
            EXPECT_NEAR(eta_i * sin_i, eta_t * sin_t, 1e-3f) << c.name;
            // wi, wo and m are coplanar.
            EXPECT_NEAR(dot(cross(si.wi, bs.wo), m), 0.f, 1e-4f) << c.name;
        }
        EXPECT_GT(refracted, 500) << c.name;
    }
}

TEST(RoughDielectric, RadianceScalingAndGeneralisedReciprocity) {
    // Transmission: the radiance-mode value is the importance-mode value over η² (η = η_t/η_i),
    // so f_radiance(wi, wo) = f_importance(wo, wi); reflection is symmetric in both modes.
    PCG32 rng(17);
    for (const Config &c : configs()) {
        auto bsdf = make_bsdf("roughdielectric", c.params);
        float eta = relative_eta(*bsdf);
        BSDFContext rad(TransportMode::Radiance), imp(TransportMode::Importance);
        int transmitted = 0;
        for (int i = 0; i < 1000; ++i) {
            // Sampled pairs (most random pairs carry no transmission) and random pairs.
            Vector3f wi = random_direction(rng, false), wo = random_direction(rng, false);
            if (i % 2 == 0) {
                float s1 = rng.next_float();
                auto [bs, weight] = bsdf->sample(rad, make_si(wi), s1, next_point2f(rng));
                if (!weight.is_black()) wo = bs.wo;
            }
            if (wi.z * wo.z < 0.f) {
                // Near the facet's critical angle (light grazing the facet on the rare side),
                // F depends on cos θ through 1 − η²sin²θ, which float cannot resolve: skip.
                float eta_it = wi.z > 0.f ? eta : 1.f / eta;
                Vector3f h = normalize(wi + wo * eta_it);
                if (std::min(absdot(wi, h), absdot(wo, h)) < 0.1f) continue;
            }
            float f_rad = bsdf->eval(rad, make_si(wi), wo).r / std::abs(wo.z);
            float f_imp = bsdf->eval(imp, make_si(wi), wo).r / std::abs(wo.z);
            float f_imp_swapped = bsdf->eval(imp, make_si(wo), wi).r / std::abs(wi.z);
            float f_rad_swapped = bsdf->eval(rad, make_si(wo), wi).r / std::abs(wi.z);
            float tol = 2e-4f * std::max({f_rad, f_imp, f_imp_swapped}) + 1e-7f;
            EXPECT_NEAR(f_rad, f_imp_swapped, tol) << c.name << " wi " << wi << " wo " << wo;
            if (wi.z * wo.z > 0.f) {
                EXPECT_NEAR(f_rad, f_imp, tol) << c.name;
                EXPECT_NEAR(f_rad, f_rad_swapped, tol) << c.name;
            } else if (f_imp > 0.f) {
                ++transmitted;
                float eta_it = wi.z > 0.f ? eta : 1.f / eta;
                EXPECT_NEAR(f_rad, f_imp / (eta_it * eta_it), 1e-5f * f_imp) << c.name;
            }
        }
        EXPECT_GT(transmitted, 150) << c.name;
    }
}

TEST(RoughDielectric, SingleLobeContexts) {
    auto bsdf = make_bsdf("roughdielectric", {{"alpha", 0.3}});
    PCG32 rng(2);
    for (int i = 0; i < 500; ++i) {
        SurfaceInteraction si = make_si(random_direction(rng, false));
        float s1 = rng.next_float();
        Point2f s2 = next_point2f(rng);
        auto [r, wr] = bsdf->sample(make_ctx(TransportMode::Radiance, 0), si, s1, s2);
        if (!wr.is_black()) {
            EXPECT_EQ(r.sampled_type, BSDFFlags::GlossyReflection);
            EXPECT_EQ(r.sampled_component, 0u);
            EXPECT_GT(r.wo.z * si.wi.z, 0.f);
        }
        auto [t, wt] = bsdf->sample(make_ctx(TransportMode::Radiance, 1), si, s1, s2);
        if (!wt.is_black()) {
            EXPECT_EQ(t.sampled_type, BSDFFlags::GlossyTransmission);
            EXPECT_EQ(t.sampled_component, 1u);
            EXPECT_LT(t.wo.z * si.wi.z, 0.f);
        }
        // The other lobe is invisible to eval and pdf.
        Vector3f flipped(r.wo.x, r.wo.y, -r.wo.z);
        if (!wr.is_black()) {
            EXPECT_TRUE(bsdf->eval(make_ctx(TransportMode::Radiance, 1), si, r.wo).is_black());
            EXPECT_EQ(bsdf->pdf(make_ctx(TransportMode::Radiance, 1), si, r.wo), 0.f);
            EXPECT_TRUE(bsdf->eval(make_ctx(TransportMode::Radiance, 0), si, flipped).is_black());
        }
    }
    BSDFContext delta;
    delta.type_mask = uint32_t(BSDFFlags::Delta);
    SurfaceInteraction si = make_si(normalize(Vector3f(0.2f, 0.f, 1.f)));
    EXPECT_TRUE(bsdf->sample(delta, si, 0.5f, Point2f(0.5f)).second.is_black());
    EXPECT_TRUE(bsdf->eval(delta, si, Vector3f(0.f, 0.f, -1.f)).is_black());
}

TEST(RoughDielectric, WhiteFurnaceAtMostOne) {
    // Importance mode (no η² in the weights): the albedo never exceeds one, from either side.
    PCG32 rng(19);
    for (const Config &c : configs()) {
        auto bsdf = make_bsdf("roughdielectric", c.params);
        for (int i = 0; i < 4; ++i) {
            Vector3f wi = random_direction(rng, false);
            Color3f albedo = furnace(*bsdf, BSDFContext(TransportMode::Importance), wi, 20000);
            EXPECT_LE(albedo.r, 1.f + 5e-3f) << c.name << " wi " << wi;
            EXPECT_GT(albedo.r, 0.5f) << c.name << " wi " << wi;
        }
    }
    // Nearly smooth glass keeps almost all the energy: only masking loses some.
    auto smooth =
        make_bsdf("roughdielectric", {{"distribution", std::string("ggx")}, {"alpha", 0.02}});
    for (float z : {1.f, -1.f}) {
        Color3f albedo =
            furnace(*smooth, BSDFContext(TransportMode::Importance), Vector3f(0.f, 0.f, z), 20000);
        EXPECT_NEAR(albedo.r, 1.f, 5e-3f) << z;
        // Radiance mode with the η² compensation is the same energy.
        Color3f radiance =
            furnace(*smooth, BSDFContext(TransportMode::Radiance), Vector3f(0.f, 0.f, z), 20000);
        EXPECT_NEAR(radiance.r, albedo.r, 1e-4f) << z;
    }
}

// Chi-square tests of this plugin's sampling: tests/chi2/configs.txt (label chi2).
