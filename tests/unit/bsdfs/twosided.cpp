// The two-sided adapter: components and their side flags, nesting rules, the back side as the
// mirrored front side, a second BSDF for the back, component index shifting, eval/pdf/sample
// consistency on both sides, energy and chi-square from the back side.

#include "bsdf_checks.h"
#include "draws.h"

#include <facet/texture.h>
#include <facet/xml.h>

using namespace facet;
using namespace bsdf_checks;

namespace {

Vector3f mirror(const Vector3f &v) { return {v.x, v.y, -v.z}; }

std::shared_ptr<BSDF> rough_conductor(double alpha) {
    return make_bsdf("roughconductor", {{"alpha", alpha}, {"material", std::string("Au")}});
}

} // namespace

TEST(TwoSided, CreationAndFlags) {
    auto diffuse = make_bsdf("diffuse");
    auto one = make_nested("twosided", {diffuse});
    ASSERT_EQ(one->component_count(), 2u);
    EXPECT_EQ(one->flags(0),
              BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide | BSDFFlags::WiSideOnly);
    EXPECT_EQ(one->flags(1),
              BSDFFlags::DiffuseReflection | BSDFFlags::BackSide | BSDFFlags::WiSideOnly);
    EXPECT_EQ(one->flags(), BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide |
                                BSDFFlags::BackSide | BSDFFlags::WiSideOnly);
    EXPECT_NE(one->to_string().find("TwoSided"), std::string::npos);
    EXPECT_NE(one->to_string().find("Diffuse"), std::string::npos);

    auto two = make_nested("twosided", {make_bsdf("plastic"), rough_conductor(0.2)});
    ASSERT_EQ(two->component_count(), 3u);
    EXPECT_EQ(two->flags(0), BSDFFlags::DeltaReflection | BSDFFlags::SeparableDelta |
                                 BSDFFlags::FrontSide | BSDFFlags::WiSideOnly);
    EXPECT_EQ(two->flags(1),
              BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide | BSDFFlags::WiSideOnly);
    EXPECT_EQ(two->flags(2), BSDFFlags::GlossyReflection | BSDFFlags::BackSide |
                                 BSDFFlags::Polarizing | BSDFFlags::WiSideOnly);
    EXPECT_NE(two->to_string().find("back"), std::string::npos);

    // A front-and-back BSDF has its side flags replaced per half.
    auto glass = make_nested("twosided", {make_bsdf("dielectric")}, {{"allow_transmission", true}});
    ASSERT_EQ(glass->component_count(), 4u);
    EXPECT_EQ(glass->flags(0),
              BSDFFlags::DeltaReflection | BSDFFlags::FrontSide | BSDFFlags::Polarizing);
    EXPECT_EQ(glass->flags(3), BSDFFlags::DeltaTransmission | BSDFFlags::BackSide |
                                   BSDFFlags::NonSymmetric | BSDFFlags::Polarizing);

    Properties props("twosided");
    props.set_object("_arg_0", diffuse);
    props.set_bool("allow_transmission", false);
    PluginRegistry::instance().create(ObjectType::BSDF, props);
    std::string doc = PluginRegistry::instance().descriptor("twosided", ObjectType::BSDF).doc;
    for (const std::string &name : props.requested_names())
        EXPECT_NE(doc.find("| " + name + " |"), std::string::npos) << name;
}

TEST(TwoSided, RejectsBadNesting) {
    expect_nested_error("twosided", {}, {}, "twosided needs a nested BSDF");
    auto d = make_bsdf("diffuse");
    expect_nested_error("twosided", {d, d, d}, {}, "at most two nested BSDFs");
    expect_nested_error("twosided", {make_bsdf("dielectric")}, {},
                        "unless allow_transmission is true");
    expect_nested_error("twosided", {d, make_bsdf("roughdielectric")}, {}, "transmits light");
    expect_nested_error("twosided", {d}, {{"allow_transmission", std::string("yes")}},
                        "allow_transmission");
    expect_nested_error("twosided", {d}, {{"reflectance", 0.3}}, "reflectance");
    // A nested object that is not a BSDF is not silently ignored.
    Properties props("twosided");
    props.set_object("_arg_0", d);
    props.set_object("_arg_1", std::make_shared<ConstantTexture>(Color3f(0.5f)));
    EXPECT_THROW(PluginRegistry::instance().create(ObjectType::BSDF, props), Error);
}

TEST(TwoSided, BackSideIsTheMirroredFrontSide) {
    PCG32 rng(3);
    for (auto nested : {make_bsdf("diffuse", {{"reflectance", Color3f(0.2f, 0.5f, 0.7f)}}),
                        rough_conductor(0.3), make_bsdf("plastic"), make_bsdf("roughplastic")}) {
        auto bsdf = make_nested("twosided", {nested});
        for (int i = 0; i < 300; ++i) {
            Vector3f wi = random_direction(rng, true), wo = random_direction(rng, true);
            SurfaceInteraction front = make_si(wi), back = make_si(mirror(wi));
            // Front side: exactly the nested BSDF.
            EXPECT_EQ(bsdf->eval(BSDFContext(), front, wo), nested->eval(BSDFContext(), front, wo));
            EXPECT_EQ(bsdf->pdf(BSDFContext(), front, wo), nested->pdf(BSDFContext(), front, wo));
            // Back side: the front mirrored through the surface.
            EXPECT_EQ(bsdf->eval(BSDFContext(), back, mirror(wo)),
                      nested->eval(BSDFContext(), front, wo));
            EXPECT_EQ(bsdf->pdf(BSDFContext(), back, mirror(wo)),
                      nested->pdf(BSDFContext(), front, wo));
            // No light crosses the surface.
            EXPECT_TRUE(bsdf->eval(BSDFContext(), back, wo).is_black());
            EXPECT_TRUE(bsdf->eval(BSDFContext(), front, mirror(wo)).is_black());

            float s1 = rng.next_float();
            Point2f s2 = next_point2f(rng);
            auto [bs_f, w_f] = bsdf->sample(BSDFContext(), front, s1, s2);
            auto [bs_b, w_b] = bsdf->sample(BSDFContext(), back, s1, s2);
            EXPECT_EQ(w_f, w_b);
            if (w_f.is_black()) continue;
            EXPECT_EQ(bs_b.wo, mirror(bs_f.wo));
            EXPECT_EQ(bs_b.pdf, bs_f.pdf);
            EXPECT_EQ(bs_b.sampled_type, bs_f.sampled_type);
            // Component indices of the back side follow the front side's.
            EXPECT_EQ(bs_b.sampled_component, bs_f.sampled_component + nested->component_count());
        }
        EXPECT_EQ(bsdf->eval_diffuse_reflectance(make_si(Vector3f(0.f, 0.f, -1.f))),
                  nested->eval_diffuse_reflectance(make_si(Vector3f(0.f, 0.f, 1.f))));
    }
}

TEST(TwoSided, SecondBSDFOnTheBack) {
    auto front = make_bsdf("diffuse", {{"reflectance", 0.8}});
    auto back = rough_conductor(0.2);
    auto bsdf = make_nested("twosided", {front, back});
    PCG32 rng(4);
    for (int i = 0; i < 200; ++i) {
        Vector3f wi = random_direction(rng, true), wo = random_direction(rng, true);
        EXPECT_EQ(bsdf->eval(BSDFContext(), make_si(wi), wo),
                  front->eval(BSDFContext(), make_si(wi), wo));
        EXPECT_EQ(bsdf->eval(BSDFContext(), make_si(mirror(wi)), mirror(wo)),
                  back->eval(BSDFContext(), make_si(wi), wo));
        EXPECT_EQ(bsdf->pdf(BSDFContext(), make_si(mirror(wi)), mirror(wo)),
                  back->pdf(BSDFContext(), make_si(wi), wo));
    }
    EXPECT_EQ(bsdf->eval_diffuse_reflectance(make_si(Vector3f(0.f, 0.f, 1.f))), Color3f(0.8f));
    EXPECT_EQ(bsdf->eval_diffuse_reflectance(make_si(Vector3f(0.f, 0.f, -1.f))), Color3f(0.f));
}

TEST(TwoSided, ComponentIndicesAreShifted) {
    // Components: 0, 1 = plastic's mirror and diffuse lobes (front); 2 = roughconductor (back).
    auto bsdf = make_nested("twosided", {make_bsdf("plastic"), rough_conductor(0.3)});
    Vector3f wi = direction_from_angles(40.f, 10.f), wo = direction_from_angles(35.f, 200.f);
    SurfaceInteraction front = make_si(wi), back = make_si(mirror(wi));
    // Front components do not answer from the back, and the other way round.
    for (uint32_t c : {0u, 1u}) {
        EXPECT_TRUE(bsdf->eval(component_ctx(c), back, mirror(wo)).is_black()) << c;
        EXPECT_EQ(bsdf->pdf(component_ctx(c), back, mirror(wo)), 0.f) << c;
        EXPECT_TRUE(
            bsdf->sample(component_ctx(c), back, 0.5f, Point2f(0.3f, 0.6f)).second.is_black())
            << c;
    }
    EXPECT_TRUE(bsdf->eval(component_ctx(2), front, wo).is_black());
    EXPECT_TRUE(bsdf->sample(component_ctx(2), front, 0.5f, Point2f(0.3f, 0.6f)).second.is_black());
    EXPECT_FALSE(bsdf->eval(component_ctx(1), front, wo).is_black());
    // Component 2 is the back BSDF's component 0.
    EXPECT_FALSE(bsdf->eval(component_ctx(2), back, mirror(wo)).is_black());
    auto [bs, weight] = bsdf->sample(component_ctx(2), back, 0.5f, Point2f(0.3f, 0.6f));
    ASSERT_FALSE(weight.is_black());
    EXPECT_EQ(bs.sampled_component, 2u);
    EXPECT_LT(bs.wo.z, 0.f);
    auto [bs_f, w_f] = bsdf->sample(component_ctx(0), front, 0.5f, Point2f(0.3f, 0.6f));
    EXPECT_EQ(bs_f.sampled_component, 0u);
    EXPECT_EQ(bs_f.sampled_type, BSDFFlags::DeltaReflection);
}

TEST(TwoSided, SampleWeightMatchesEvalPdf) {
    std::vector<std::shared_ptr<BSDF>> bsdfs = {
        make_nested("twosided", {make_bsdf("diffuse")}),
        make_nested("twosided", {rough_conductor(0.1)}),
        make_nested("twosided", {make_bsdf("roughplastic",
                                           {{"distribution", std::string("ggx")}, {"alpha", 0.3}}),
                                 make_bsdf("plastic")}),
        make_nested("twosided", {make_bsdf("roughdielectric", {{"alpha", 0.3}})},
                    {{"allow_transmission", true}}),
    };
    for (const auto &bsdf : bsdfs) {
        EXPECT_GT(check_sample_eval_pdf(*bsdf, BSDFContext(), true, 2000, 5), 1000)
            << bsdf->to_string();
        BSDFContext importance(TransportMode::Importance);
        EXPECT_GT(check_sample_eval_pdf(*bsdf, importance, true, 500, 6), 200) << bsdf->to_string();
    }
}

TEST(TwoSided, ReciprocityOnBothSides) {
    PCG32 rng(8);
    auto bsdf = make_nested("twosided", {rough_conductor(0.3), make_bsdf("roughplastic")});
    for (int i = 0; i < 300; ++i) {
        Vector3f wi = random_direction(rng, true), wo = random_direction(rng, true);
        if (i % 2) {
            wi = mirror(wi);
            wo = mirror(wo);
        }
        Color3f f_io = bsdf->eval(BSDFContext(), make_si(wi), wo) / std::abs(wo.z);
        Color3f f_oi = bsdf->eval(BSDFContext(), make_si(wo), wi) / std::abs(wi.z);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(f_io[c], f_oi[c], 1e-4f * std::max(f_io[c], f_oi[c]) + 1e-7f);
    }
}

TEST(TwoSided, WhiteFurnaceOnBothSides) {
    auto bsdf = make_nested("twosided", {make_bsdf("diffuse", {{"reflectance", 1.0}})});
    for (float theta : {0.f, 50.f, 130.f, 180.f}) {
        Color3f albedo = furnace(*bsdf, BSDFContext(), direction_from_angles(theta, 30.f), 20000);
        EXPECT_NEAR(albedo.r, 1.f, 1e-5f) << theta;
    }
    auto mirror_ish = make_nested("twosided", {make_bsdf("roughconductor", {{"alpha", 0.2}})});
    for (float theta : {20.f, 160.f}) {
        Color3f albedo =
            furnace(*mirror_ish, BSDFContext(), direction_from_angles(theta, 30.f), 20000);
        EXPECT_LE(albedo.max(), 1.f + 5e-3f) << theta;
        EXPECT_GT(albedo.max(), 0.95f) << theta;
    }
}

TEST(TwoSided, LoadsFromXml) {
    auto obj = load_string(R"(<bsdf version="3.0.0" type="twosided">
        <bsdf type="diffuse"><rgb name="reflectance" value="0.1, 0.2, 0.3"/></bsdf>
    </bsdf>)");
    auto bsdf = std::dynamic_pointer_cast<BSDF>(obj);
    ASSERT_TRUE(bsdf);
    SurfaceInteraction back = make_si(Vector3f(0.f, 0.f, -1.f));
    Color3f value = bsdf->eval(BSDFContext(), back, Vector3f(0.f, 0.f, -1.f));
    EXPECT_NEAR(value.g, 0.2f * InvPi, 1e-6f);
}

// Chi-square tests of this plugin's sampling: tests/chi2/configs.txt (label chi2).

TEST(TwoSided, ReflectsOnlyToWiSide) {
    // Both sides reflect: light leaves to the side wi comes from, whichever it is.
    EXPECT_GT(check_wi_side_only(*make_nested("twosided", {make_bsdf("diffuse")})), 1000);
    EXPECT_GT(
        check_wi_side_only(*make_nested("twosided", {make_bsdf("plastic"), rough_conductor(0.7)})),
        1000);
    auto glass = make_nested("twosided", {make_bsdf("dielectric")}, {{"allow_transmission", true}});
    EXPECT_FALSE(has_flag(glass->flags(), BSDFFlags::WiSideOnly));
}
