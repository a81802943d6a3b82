// The opacity mask: components, parameters, the pass-through (Null) lobe, opacity scaling of
// eval and pdf, single-part contexts, textured opacity, consistency, energy and chi-square.

#include "bsdf_checks.h"
#include "draws.h"

#include <facet/texture.h>
#include <facet/xml.h>

using namespace facet;
using namespace bsdf_checks;

namespace {

std::shared_ptr<BSDF> rough_conductor() { return make_bsdf("roughconductor", {{"alpha", 0.3}}); }

} // namespace

TEST(Mask, CreationAndFlags) {
    auto bsdf = make_nested("mask", {make_bsdf("plastic")});
    ASSERT_EQ(bsdf->component_count(), 3u);
    EXPECT_EQ(bsdf->flags(0), BSDFFlags::DeltaReflection | BSDFFlags::SeparableDelta |
                                  BSDFFlags::FrontSide | BSDFFlags::WiSideOnly);
    EXPECT_EQ(bsdf->flags(1),
              BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide | BSDFFlags::WiSideOnly);
    EXPECT_EQ(bsdf->flags(2), BSDFFlags::Null | BSDFFlags::FrontSide | BSDFFlags::BackSide);
    // Light passes through: not WiSideOnly, though the plastic's components are.
    EXPECT_EQ(bsdf->flags(),
              (bsdf->flags(0) | bsdf->flags(1) | bsdf->flags(2)) & ~BSDFFlags::WiSideOnly);
    EXPECT_NE(bsdf->to_string().find("Mask"), std::string::npos);
    EXPECT_NE(bsdf->to_string().find("Plastic"), std::string::npos);

    Properties textured("mask");
    textured.set_object("opacity", std::make_shared<RampTexture>());
    textured.set_object("_arg_0", rough_conductor());
    auto t = PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, textured);
    EXPECT_TRUE(has_flag(t->flags(1), BSDFFlags::SpatiallyVarying));
    std::string doc = PluginRegistry::instance().descriptor("mask", ObjectType::BSDF).doc;
    for (const std::string &name : textured.requested_names())
        EXPECT_NE(doc.find("| " + name + " |"), std::string::npos) << name;
}

TEST(Mask, RejectsBadParameters) {
    expect_nested_error("mask", {}, {}, "mask needs a nested BSDF");
    auto d = make_bsdf("diffuse");
    expect_nested_error("mask", {d, d}, {}, "exactly one nested BSDF");
    expect_nested_error("mask", {d}, {{"opacity", 1.5}}, "opacity must be in [0, 1], found 1.5");
    expect_nested_error("mask", {d}, {{"opacity", -0.1}}, "opacity must be in [0, 1]");
    expect_nested_error("mask", {d}, {{"opacity", std::string("half")}}, "opacity");
    expect_nested_error("mask", {d}, {{"alpha", 0.5}}, "alpha");
}

TEST(Mask, OpacityZeroIsPureNullTransmission) {
    auto bsdf = make_nested("mask", {rough_conductor()}, {{"opacity", 0.0}});
    PCG32 rng(2);
    for (int i = 0; i < 200; ++i) {
        Vector3f wi = random_direction(rng, false), wo = random_direction(rng, false);
        SurfaceInteraction si = make_si(wi);
        auto [bs, weight] = bsdf->sample(BSDFContext(), si, rng.next_float(), Point2f(0.3f, 0.6f));
        EXPECT_EQ(bs.wo, -wi);
        EXPECT_EQ(weight, Color3f(1.f));
        EXPECT_EQ(bs.pdf, 1.f);
        EXPECT_EQ(bs.eta, 1.f);
        EXPECT_EQ(bs.sampled_type, BSDFFlags::Null);
        EXPECT_EQ(bs.sampled_component, 1u);
        EXPECT_TRUE(bsdf->eval(BSDFContext(), si, wo).is_black());
        EXPECT_EQ(bsdf->pdf(BSDFContext(), si, wo), 0.f);
        EXPECT_EQ(bsdf->eval_null_transmission(si), Color3f(1.f));
    }
}

TEST(Mask, OpacityOneIsTheNestedBSDF) {
    auto nested = rough_conductor();
    auto bsdf = make_nested("mask", {nested}, {{"opacity", 1.0}});
    PCG32 rng(3);
    for (int i = 0; i < 200; ++i) {
        Vector3f wi = random_direction(rng, true), wo = random_direction(rng, true);
        SurfaceInteraction si = make_si(wi);
        EXPECT_EQ(bsdf->eval(BSDFContext(), si, wo), nested->eval(BSDFContext(), si, wo));
        EXPECT_EQ(bsdf->pdf(BSDFContext(), si, wo), nested->pdf(BSDFContext(), si, wo));
        float s1 = rng.next_float();
        Point2f s2 = next_point2f(rng);
        auto [bs, weight] = bsdf->sample(BSDFContext(), si, s1, s2);
        auto [bs_n, weight_n] = nested->sample(BSDFContext(), si, s1, s2);
        EXPECT_EQ(weight, weight_n);
        EXPECT_EQ(bs.wo, bs_n.wo);
        EXPECT_EQ(bs.pdf, bs_n.pdf);
        EXPECT_EQ(bsdf->eval_null_transmission(si), Color3f(0.f));
    }
}

TEST(Mask, EvalAndPdfScaleWithOpacity) {
    auto nested = make_bsdf("roughplastic", {{"alpha", 0.2}});
    auto bsdf = make_nested("mask", {nested}, {{"opacity", 0.3}});
    PCG32 rng(4);
    for (int i = 0; i < 200; ++i) {
        Vector3f wi = random_direction(rng, true), wo = random_direction(rng, true);
        SurfaceInteraction si = make_si(wi);
        Color3f v = bsdf->eval(BSDFContext(), si, wo), vn = nested->eval(BSDFContext(), si, wo);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(v[c], 0.3f * vn[c], 1e-6f * vn[c]);
        EXPECT_NEAR(bsdf->pdf(BSDFContext(), si, wo), 0.3f * nested->pdf(BSDFContext(), si, wo),
                    1e-6f * nested->pdf(BSDFContext(), si, wo));
        EXPECT_NEAR(bsdf->eval_null_transmission(si).g, 0.7f, 1e-6f);
    }
    // The fraction of pass-through samples is 1 − opacity.
    SurfaceInteraction si = make_si(direction_from_angles(30.f, 0.f));
    int null_count = 0, n = 20000;
    for (int i = 0; i < n; ++i) {
        auto [bs, weight] =
            bsdf->sample(BSDFContext(), si, (float(i) + 0.5f) / float(n), Point2f(0.4f, 0.3f));
        if (bs.sampled_type == BSDFFlags::Null) {
            ++null_count;
            EXPECT_NEAR(bs.pdf, 0.7f, 1e-6f);
            EXPECT_EQ(weight, Color3f(1.f));
        }
    }
    EXPECT_NEAR(double(null_count) / n, 0.7, 1e-3);
}

TEST(Mask, SinglePartContexts) {
    auto nested = rough_conductor();
    auto bsdf = make_nested("mask", {nested}, {{"opacity", 0.25}});
    SurfaceInteraction si = make_si(direction_from_angles(40.f, 30.f));
    // Pass-through alone (component 1): always taken, weight 1 − opacity.
    auto [bs, weight] = bsdf->sample(component_ctx(1), si, 0.1f, Point2f(0.3f, 0.6f));
    EXPECT_EQ(bs.sampled_type, BSDFFlags::Null);
    EXPECT_EQ(bs.pdf, 1.f);
    EXPECT_NEAR(weight.r, 0.75f, 1e-6f);
    Vector3f wo = direction_from_angles(40.f, 200.f);
    EXPECT_TRUE(bsdf->eval(component_ctx(1), si, wo).is_black());
    EXPECT_EQ(bsdf->pdf(component_ctx(1), si, wo), 0.f);
    // Nested alone (component 0): always taken, weight opacity·nested weight, nested pdf.
    auto [bs0, w0] = bsdf->sample(component_ctx(0), si, 0.9f, Point2f(0.3f, 0.6f));
    auto [bsn, wn] = nested->sample(BSDFContext(), si, 0.9f, Point2f(0.3f, 0.6f));
    EXPECT_EQ(bs0.sampled_type, BSDFFlags::GlossyReflection);
    EXPECT_EQ(bs0.wo, bsn.wo);
    EXPECT_EQ(bs0.pdf, bsn.pdf);
    EXPECT_NEAR(w0.r, 0.25f * wn.r, 1e-6f * wn.r);
    EXPECT_EQ(bsdf->pdf(component_ctx(0), si, wo), nested->pdf(BSDFContext(), si, wo));
    // Null excluded by the type mask: the same as component 0.
    BSDFContext no_null;
    no_null.type_mask = uint32_t(BSDFFlags::All & ~BSDFFlags::Null);
    auto [bs_m, w_m] = bsdf->sample(no_null, si, 0.9f, Point2f(0.3f, 0.6f));
    EXPECT_EQ(w_m, w0);
    EXPECT_GT(check_sample_eval_pdf(*bsdf, component_ctx(0), true, 500, 2), 200);
    EXPECT_GT(check_sample_eval_pdf(*bsdf, no_null, true, 500, 3), 200);
}

TEST(Mask, TexturedOpacityIsEvaluatedPerPoint) {
    Properties props("mask");
    props.set_object("opacity", std::make_shared<RampTexture>());
    auto nested = make_bsdf("diffuse");
    props.set_object("_arg_0", nested);
    auto bsdf = PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, props);
    Vector3f wo = direction_from_angles(20.f, 0.f);
    for (float u : {0.f, 0.25f, 0.9f}) {
        SurfaceInteraction si = make_si(direction_from_angles(50.f, 90.f));
        si.uv = Point2f(u, 0.5f);
        EXPECT_NEAR(bsdf->eval(BSDFContext(), si, wo).r, u * nested->eval(BSDFContext(), si, wo).r,
                    1e-7f);
        EXPECT_NEAR(bsdf->eval_null_transmission(si).r, 1.f - u, 1e-7f);
    }
}

TEST(Mask, SampleWeightMatchesEvalPdf) {
    for (auto nested : {rough_conductor(), make_bsdf("plastic"), make_bsdf("roughplastic"),
                        make_bsdf("roughdielectric", {{"alpha", 0.3}})}) {
        auto bsdf = make_nested("mask", {nested}, {{"opacity", 0.6}});
        EXPECT_GT(check_sample_eval_pdf(*bsdf, BSDFContext(), true, 2000, 4), 300)
            << nested->to_string();
    }
}

TEST(Mask, WhiteFurnace) {
    // Pass-through carries 1 − opacity, the nested BSDF opacity × its albedo.
    auto nested = make_bsdf("diffuse", {{"reflectance", 0.8}});
    auto bsdf = make_nested("mask", {nested}, {{"opacity", 0.4}});
    Color3f albedo = furnace(*bsdf, BSDFContext(), direction_from_angles(35.f, 0.f), 40000);
    EXPECT_NEAR(albedo.r, 0.6f + 0.4f * 0.8f, 0.01f);
    auto glass =
        make_nested("mask", {make_bsdf("roughdielectric", {{"alpha", 0.3}})}, {{"opacity", 0.5}});
    for (float theta : {10.f, 60.f, 120.f})
        EXPECT_LE(furnace(*glass, BSDFContext(), direction_from_angles(theta, 0.f), 20000).max(),
                  1.f + 5e-3f)
            << theta;
}

TEST(Mask, LoadsFromXml) {
    auto bsdf = std::dynamic_pointer_cast<BSDF>(load_string(R"(<bsdf version="3.0.0" type="mask">
        <float name="opacity" value="0.2"/>
        <bsdf type="diffuse"/>
    </bsdf>)"));
    ASSERT_TRUE(bsdf);
    EXPECT_NEAR(bsdf->eval_null_transmission(make_si(Vector3f(0.f, 0.f, 1.f))).r, 0.8f, 1e-6f);
}

// Chi-square tests of this plugin's sampling: tests/chi2/configs.txt (label chi2).
