// The blend of two BSDFs: components, parameters, the extreme weights, the blended eval and pdf,
// component routing, textured weights, consistency (the sample weight of a mixture), energy and
// chi-square.

#include "bsdf_checks.h"
#include "draws.h"

#include <facet/texture.h>
#include <facet/xml.h>

using namespace facet;
using namespace bsdf_checks;

namespace {

std::shared_ptr<BSDF> rough_conductor(double alpha = 0.2) {
    return make_bsdf("roughconductor", {{"alpha", alpha}});
}

} // namespace

TEST(BlendBSDF, CreationAndFlags) {
    auto bsdf =
        make_nested("blendbsdf", {make_bsdf("plastic"), rough_conductor()}, {{"weight", 0.3}});
    ASSERT_EQ(bsdf->component_count(), 3u);
    EXPECT_EQ(bsdf->flags(0),
              BSDFFlags::DeltaReflection | BSDFFlags::FrontSide | BSDFFlags::WiSideOnly);
    EXPECT_EQ(bsdf->flags(1),
              BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide | BSDFFlags::WiSideOnly);
    EXPECT_EQ(bsdf->flags(2), BSDFFlags::GlossyReflection | BSDFFlags::FrontSide |
                                  BSDFFlags::Polarizing | BSDFFlags::WiSideOnly);
    // Both reflect only to wi's side: so does the blend.
    EXPECT_EQ(bsdf->flags(), bsdf->flags(0) | bsdf->flags(1) | bsdf->flags(2));
    auto with_glass = make_nested("blendbsdf", {make_bsdf("diffuse"), make_bsdf("dielectric")},
                                  {{"weight", 0.3}});
    EXPECT_FALSE(has_flag(with_glass->flags(), BSDFFlags::WiSideOnly));
    EXPECT_NE(bsdf->to_string().find("BlendBSDF"), std::string::npos);

    Properties textured("blendbsdf");
    textured.set_object("weight", std::make_shared<RampTexture>());
    textured.set_object("_arg_0", make_bsdf("diffuse"));
    textured.set_object("_arg_1", make_bsdf("dielectric"));
    auto t = PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, textured);
    ASSERT_EQ(t->component_count(), 3u);
    EXPECT_TRUE(has_flag(t->flags(2), BSDFFlags::SpatiallyVarying));
    EXPECT_TRUE(has_flag(t->flags(), BSDFFlags::DeltaTransmission));
    std::string doc = PluginRegistry::instance().descriptor("blendbsdf", ObjectType::BSDF).doc;
    for (const std::string &name : textured.requested_names())
        EXPECT_NE(doc.find("| " + name + " |"), std::string::npos) << name;
}

TEST(BlendBSDF, RejectsBadParameters) {
    auto d = make_bsdf("diffuse");
    expect_nested_error("blendbsdf", {}, {}, "exactly two nested BSDFs, found 0");
    expect_nested_error("blendbsdf", {d}, {}, "exactly two nested BSDFs, found 1");
    expect_nested_error("blendbsdf", {d, d, d}, {}, "found a third");
    expect_nested_error("blendbsdf", {d, d}, {{"weight", 1.5}},
                        "weight must be in [0, 1], found 1.5");
    expect_nested_error("blendbsdf", {d, d}, {{"weight", -0.5}}, "weight must be in [0, 1]");
    expect_nested_error("blendbsdf", {d, d}, {{"weight", std::string("half")}}, "weight");
    // Mitsuba 3 has no default weight: leaving it out is an error that says what is expected.
    expect_nested_error("blendbsdf", {d, d}, {}, "blendbsdf needs a \"weight\"");
    expect_nested_error("blendbsdf", {d, d}, {{"weight", 0.5}, {"opacity", 0.5}}, "opacity");
}

TEST(BlendBSDF, ExtremeWeightsSelectOneBSDF) {
    auto first = make_bsdf("roughplastic", {{"alpha", 0.3}});
    auto second = rough_conductor(0.1);
    PCG32 rng(3);
    for (double w : {0.0, 1.0}) {
        auto bsdf = make_nested("blendbsdf", {first, second}, {{"weight", w}});
        const auto &only = w == 0.0 ? first : second;
        for (int i = 0; i < 200; ++i) {
            Vector3f wi = random_direction(rng, true), wo = random_direction(rng, true);
            SurfaceInteraction si = make_si(wi);
            EXPECT_EQ(bsdf->eval(BSDFContext(), si, wo), only->eval(BSDFContext(), si, wo));
            EXPECT_EQ(bsdf->pdf(BSDFContext(), si, wo), only->pdf(BSDFContext(), si, wo));
            float s1 = rng.next_float();
            Point2f s2 = next_point2f(rng);
            auto [bs, weight] = bsdf->sample(BSDFContext(), si, s1, s2);
            auto [bs_o, weight_o] = only->sample(BSDFContext(), si, s1, s2);
            EXPECT_EQ(bs.wo, bs_o.wo);
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(weight[c], weight_o[c], 1e-5f * weight_o[c]);
        }
    }
}

TEST(BlendBSDF, EvalAndPdfAreBlended) {
    auto first = make_bsdf("diffuse", {{"reflectance", Color3f(0.9f, 0.5f, 0.1f)}});
    auto second = rough_conductor(0.3);
    auto bsdf = make_nested("blendbsdf", {first, second}, {{"weight", 0.35}});
    PCG32 rng(4);
    for (int i = 0; i < 200; ++i) {
        Vector3f wi = random_direction(rng, true), wo = random_direction(rng, true);
        SurfaceInteraction si = make_si(wi);
        Color3f expected = first->eval(BSDFContext(), si, wo) * 0.65f +
                           second->eval(BSDFContext(), si, wo) * 0.35f;
        Color3f value = bsdf->eval(BSDFContext(), si, wo);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(value[c], expected[c], 1e-6f * expected[c] + 1e-9f);
        float pdf =
            0.65f * first->pdf(BSDFContext(), si, wo) + 0.35f * second->pdf(BSDFContext(), si, wo);
        EXPECT_NEAR(bsdf->pdf(BSDFContext(), si, wo), pdf, 1e-6f * pdf);
    }
    EXPECT_NEAR(bsdf->eval_diffuse_reflectance(make_si(Vector3f(0.f, 0.f, 1.f))).r, 0.65f * 0.9f,
                1e-6f);
}

TEST(BlendBSDF, DeltaSamplesAreWeightedByTheBlend) {
    // Mitsuba 3 weights a sample by the blend on its direction, a delta lobe included: its
    // discrete weight and probability count like a value and a density, and the other BSDF adds
    // its eval and pdf there. A mirror blended with a diffuse at weight w thus returns
    // (w + (1 - w) rho cos/pi) / (w + (1 - w) cos/pi), not 1, and keeps its delta flag.
    const float rho = 0.1f, w = 0.1f;
    auto bsdf = make_nested(
        "blendbsdf", {make_bsdf("diffuse", {{"reflectance", double(rho)}}), make_bsdf("conductor")},
        {{"weight", double(w)}});
    SurfaceInteraction si = make_si(direction_from_angles(40.f, 30.f));
    // sample1 = 0.05 <= w picks the conductor.
    auto [bs, weight] = bsdf->sample(BSDFContext(), si, 0.05f, Point2f(0.3f, 0.3f));
    EXPECT_EQ(bs.sampled_type, BSDFFlags::DeltaReflection);
    EXPECT_EQ(bs.sampled_component, 1u); // the conductor's component 0, after diffuse's one
    float cos_o = bs.wo.z;
    EXPECT_NEAR(cos_o, std::cos(40.f * Pi / 180.f), 1e-5f);
    float pdf = w + (1.f - w) * cos_o * InvPi;
    EXPECT_NEAR(bs.pdf, pdf, 1e-5f * pdf);
    float expected = (w + (1.f - w) * rho * cos_o * InvPi) / pdf;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(weight[c], expected, 1e-5f) << c;
    EXPECT_LT(weight.r, 0.45f); // far from the mirror's own weight of 1

    // The same blend at weight 0.9: the mirror dominates, the weight comes close to 1.
    auto mostly_mirror = make_nested(
        "blendbsdf", {make_bsdf("diffuse", {{"reflectance", double(rho)}}), make_bsdf("conductor")},
        {{"weight", 0.9}});
    auto [bs9, weight9] = mostly_mirror->sample(BSDFContext(), si, 0.5f, Point2f(0.3f, 0.3f));
    EXPECT_EQ(bs9.sampled_type, BSDFFlags::DeltaReflection);
    float pdf9 = 0.9f + 0.1f * cos_o * InvPi;
    EXPECT_NEAR(weight9.g, (0.9f + 0.1f * rho * cos_o * InvPi) / pdf9, 1e-5f);

    // A diffuse sample of the same blend: the mirror adds nothing off its direction.
    auto [bs_d, weight_d] = bsdf->sample(BSDFContext(), si, 0.5f, Point2f(0.3f, 0.3f));
    EXPECT_EQ(bs_d.sampled_type, BSDFFlags::DiffuseReflection);
    EXPECT_NEAR(weight_d.r, rho, 1e-5f);
    EXPECT_NEAR(bs_d.pdf, (1.f - w) * bs_d.wo.z * InvPi, 1e-5f);
}

TEST(BlendBSDF, DeltaLobesAreNotSeparable) {
    // For the same reason a blend's delta lobe sampled alone (w times the mirror) is not what
    // its samples bring through it on average (they add the other BSDF's value): the blend
    // clears SeparableDelta from the nested plastic's coat, so that no integrator counts the
    // coat's light by its lobe alone.
    auto plastic = make_bsdf("plastic");
    ASSERT_TRUE(has_flag(plastic->flags(0), BSDFFlags::SeparableDelta));
    auto bsdf = make_nested("blendbsdf", {make_bsdf("diffuse", {{"reflectance", 0.8}}), plastic},
                            {{"weight", 0.3}});
    for (uint32_t k = 0; k < bsdf->component_count(); ++k)
        EXPECT_FALSE(has_flag(bsdf->flags(k), BSDFFlags::SeparableDelta)) << k;
    const SurfaceInteraction si = make_si(direction_from_angles(30.f, 10.f));
    const Color3f alone = bsdf->sample(component_ctx(1), si, 0.5f, Point2f(0.5f)).second;
    const Color3f share = delta_share(*bsdf, si, 1);
    EXPECT_GT(share.r, 1.2f * alone.r) << "the blend's coat samples carry the diffuse too";
}

TEST(BlendBSDF, ComponentsAreRouted) {
    auto first = make_bsdf("plastic");
    auto second = rough_conductor(0.3);
    auto bsdf = make_nested("blendbsdf", {first, second}, {{"weight", 0.25}});
    SurfaceInteraction si = make_si(direction_from_angles(45.f, 0.f));
    Vector3f wo = direction_from_angles(45.f, 180.f);
    // Component 2 is the conductor's component 0, weighted by 0.25, with its own pdf.
    EXPECT_NEAR(bsdf->eval(component_ctx(2), si, wo).r,
                0.25f * second->eval(BSDFContext(), si, wo).r, 1e-6f);
    EXPECT_EQ(bsdf->pdf(component_ctx(2), si, wo), second->pdf(BSDFContext(), si, wo));
    auto [bs, weight] = bsdf->sample(component_ctx(2), si, 0.7f, Point2f(0.4f, 0.6f));
    auto [bs_s, weight_s] = second->sample(BSDFContext(), si, 0.7f, Point2f(0.4f, 0.6f));
    EXPECT_EQ(bs.sampled_component, 2u);
    EXPECT_EQ(bs.wo, bs_s.wo);
    EXPECT_NEAR(weight.r, 0.25f * weight_s.r, 1e-6f * weight_s.r);
    // Component 1 is the plastic's diffuse lobe, weighted by 0.75.
    EXPECT_NEAR(bsdf->eval(component_ctx(1), si, wo).r,
                0.75f * first->eval(component_ctx(1), si, wo).r, 1e-7f);
    EXPECT_EQ(bsdf->pdf(component_ctx(1), si, wo), first->pdf(component_ctx(1), si, wo));
    auto [bs0, w0] = bsdf->sample(component_ctx(0), si, 0.5f, Point2f(0.5f));
    EXPECT_EQ(bs0.sampled_type, BSDFFlags::DeltaReflection);
    EXPECT_EQ(bs0.sampled_component, 0u);
    for (uint32_t c = 0; c < 3; ++c)
        EXPECT_GT(check_sample_eval_pdf(*bsdf, component_ctx(c), false, 300, 10 + c),
                  c == 0 ? -1 : 150)
            << c;
}

TEST(BlendBSDF, TexturedWeightIsEvaluatedPerPoint) {
    Properties props("blendbsdf");
    props.set_object("weight", std::make_shared<RampTexture>());
    auto first = make_bsdf("diffuse", {{"reflectance", 0.2}});
    auto second = make_bsdf("diffuse", {{"reflectance", 0.8}});
    props.set_object("_arg_0", first);
    props.set_object("_arg_1", second);
    auto bsdf = PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, props);
    Vector3f wo = direction_from_angles(0.f, 0.f);
    for (float u : {0.f, 0.3f, 1.f}) {
        SurfaceInteraction si = make_si(direction_from_angles(30.f, 0.f));
        si.uv = Point2f(u, 0.5f);
        EXPECT_NEAR(bsdf->eval(BSDFContext(), si, wo).r, (0.2f * (1.f - u) + 0.8f * u) * InvPi,
                    1e-6f);
        auto [bs, weight] = bsdf->sample(BSDFContext(), si, 0.5f, Point2f(0.3f, 0.3f));
        EXPECT_NEAR(weight.r, 0.2f * (1.f - u) + 0.8f * u, 1e-5f);
    }
}

TEST(BlendBSDF, SampleWeightMatchesEvalPdf) {
    std::vector<std::shared_ptr<BSDF>> bsdfs = {
        make_nested("blendbsdf", {make_bsdf("diffuse"), rough_conductor(0.2)}, {{"weight", 0.3}}),
        make_nested("blendbsdf",
                    {make_bsdf("roughdielectric", {{"alpha", 0.5}}), make_bsdf("diffuse")},
                    {{"weight", 0.6}}),
        make_nested("blendbsdf",
                    {rough_conductor(0.5), make_bsdf("roughdielectric", {{"alpha", 0.5}})},
                    {{"weight", 0.5}}),
        make_nested("blendbsdf",
                    {make_bsdf("plastic"), make_bsdf("roughplastic", {{"alpha", 0.1}})},
                    {{"weight", 0.8}}),
    };
    for (const auto &bsdf : bsdfs)
        EXPECT_GT(check_sample_eval_pdf(*bsdf, BSDFContext(), true, 2000, 5), 500)
            << bsdf->to_string();
}

TEST(BlendBSDF, ReciprocityAndFurnace) {
    auto bsdf = make_nested("blendbsdf",
                            {make_bsdf("roughplastic", {{"alpha", 0.2}}), rough_conductor(0.3)},
                            {{"weight", 0.4}});
    PCG32 rng(9);
    for (int i = 0; i < 300; ++i) {
        Vector3f wi = random_direction(rng, true), wo = random_direction(rng, true);
        Color3f f_io = bsdf->eval(BSDFContext(), make_si(wi), wo) / wo.z;
        Color3f f_oi = bsdf->eval(BSDFContext(), make_si(wo), wi) / wi.z;
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(f_io[c], f_oi[c], 1e-4f * std::max(f_io[c], f_oi[c]) + 1e-7f);
    }
    // Two white diffuse BSDFs blend to a white one; mixed ones stay below one.
    auto white = make_nested("blendbsdf",
                             {make_bsdf("diffuse", {{"reflectance", 1.0}}),
                              make_bsdf("diffuse", {{"reflectance", 1.0}})},
                             {{"weight", 0.2}});
    EXPECT_NEAR(furnace(*white, BSDFContext(), direction_from_angles(30.f, 0.f), 20000).r, 1.f,
                1e-4f);
    auto glass = make_nested("blendbsdf",
                             {make_bsdf("roughdielectric", {{"alpha", 0.3}}), rough_conductor(0.3)},
                             {{"weight", 0.5}});
    for (float theta : {10.f, 60.f, 120.f})
        EXPECT_LE(furnace(*glass, BSDFContext(), direction_from_angles(theta, 0.f), 20000).max(),
                  1.f + 5e-3f);
}

TEST(BlendBSDF, LoadsFromXml) {
    auto bsdf =
        std::dynamic_pointer_cast<BSDF>(load_string(R"(<bsdf version="3.0.0" type="blendbsdf">
        <float name="weight" value="0.25"/>
        <bsdf type="diffuse"><float name="reflectance" value="0.4"/></bsdf>
        <bsdf type="diffuse"><float name="reflectance" value="0.8"/></bsdf>
    </bsdf>)"));
    ASSERT_TRUE(bsdf);
    Color3f value =
        bsdf->eval(BSDFContext(), make_si(Vector3f(0.f, 0.f, 1.f)), Vector3f(0.f, 0.f, 1.f));
    EXPECT_NEAR(value.r, (0.75f * 0.4f + 0.25f * 0.8f) * InvPi, 1e-6f);
}

// Chi-square tests of this plugin's sampling: tests/chi2/configs.txt (label chi2).

TEST(BlendBSDF, ReflectsOnlyToWiSide) {
    EXPECT_GT(check_wi_side_only(*make_nested(
                  "blendbsdf", {make_bsdf("diffuse"), rough_conductor(0.6)}, {{"weight", 0.4}})),
              500);
}
