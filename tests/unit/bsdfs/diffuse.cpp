// The diffuse BSDF: creation, eval/pdf/sample consistency, energy, reciprocity and the back side
// (its chi-square tests are lines of tests/chi2/configs.txt).

#include "bsdf_checks.h"
#include "draws.h"

#include <facet/bsdf.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/random.h>
#include <facet/texture.h>
#include <facet/warp.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace bsdf_checks;

namespace {

std::shared_ptr<BSDF> make_diffuse(const Color3f &reflectance) {
    return make_bsdf("diffuse", {{"reflectance", reflectance}});
}

} // namespace

TEST(BSDFCreation, Diffuse) {
    auto bsdf = make_bsdf("diffuse");
    ASSERT_TRUE(bsdf);
    EXPECT_EQ(bsdf->component_count(), 1u);
    EXPECT_EQ(bsdf->flags(),
              BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide | BSDFFlags::WiSideOnly);
    EXPECT_EQ(bsdf->flags(0),
              BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide | BSDFFlags::WiSideOnly);
    EXPECT_FALSE(bsdf->needs_differentials());
    EXPECT_FALSE(bsdf->to_string().empty());

    // The default reflectance is 0.5.
    SurfaceInteraction si = make_si(Vector3f(0.f, 0.f, 1.f));
    expect_color_near(bsdf->eval_diffuse_reflectance(si), Color3f(0.5f), 1e-6f);
    expect_color_near(bsdf->eval(BSDFContext(), si, Vector3f(0.f, 0.f, 1.f)), Color3f(0.5f * InvPi),
                      1e-6f);
}

TEST(BSDFCreation, DiffuseRejectsBadParameters) {
    Properties props("diffuse");
    props.set_string("reflectance", "blue");
    EXPECT_THROW(PluginRegistry::instance().create(ObjectType::BSDF, props), Error);

    Properties typo("diffuse");
    typo.set_float("reflectence", 0.3);
    EXPECT_THROW(PluginRegistry::instance().create(ObjectType::BSDF, typo), Error);
}

TEST(BSDFEval, DiffuseValue) {
    Color3f rho(0.2f, 0.5f, 0.9f);
    auto bsdf = make_diffuse(rho);
    SurfaceInteraction si = make_si(normalize(Vector3f(0.3f, -0.2f, 0.8f)));
    Vector3f wo = normalize(Vector3f(-0.5f, 0.1f, 0.4f));
    expect_color_near(bsdf->eval(BSDFContext(), si, wo), rho * (InvPi * wo.z), 1e-6f);
    EXPECT_NEAR(bsdf->pdf(BSDFContext(), si, wo), wo.z * InvPi, 1e-6f);
    auto [value, pdf] = bsdf->eval_pdf(BSDFContext(), si, wo);
    expect_color_near(value, bsdf->eval(BSDFContext(), si, wo), 1e-6f);
    EXPECT_EQ(pdf, bsdf->pdf(BSDFContext(), si, wo));
}

TEST(BSDFEval, DiffuseTexturedReflectance) {
    auto bsdf = std::dynamic_pointer_cast<BSDF>(load_string(R"(
        <bsdf version="3.0.0" type="diffuse">
            <texture type="checkerboard" name="reflectance">
                <rgb name="color0" value="0.1, 0.2, 0.3"/>
                <rgb name="color1" value="0.7, 0.8, 0.9"/>
            </texture>
        </bsdf>)"));
    ASSERT_TRUE(bsdf);
    EXPECT_TRUE(has_flag(bsdf->flags(), BSDFFlags::SpatiallyVarying));
    EXPECT_TRUE(has_flag(bsdf->flags(), BSDFFlags::DiffuseReflection));
    BSDFContext ctx;
    Vector3f wo = normalize(Vector3f(0.3f, 0.1f, 0.8f));
    SurfaceInteraction si = make_si(Vector3f(0.f, 0.f, 1.f));
    const std::pair<Point2f, Color3f> cases[] = {
        {Point2f(0.25f, 0.25f), Color3f(0.1f, 0.2f, 0.3f)},
        {Point2f(0.75f, 0.25f), Color3f(0.7f, 0.8f, 0.9f)},
        {Point2f(0.75f, 0.75f), Color3f(0.1f, 0.2f, 0.3f)}};
    for (const auto &[uv, rho] : cases) {
        si.uv = uv;
        expect_color_near(bsdf->eval_diffuse_reflectance(si), rho, 1e-6f);
        expect_color_near(bsdf->eval(ctx, si, wo), rho * (InvPi * wo.z), 1e-6f);
        expect_color_near(bsdf->sample(ctx, si, 0.5f, Point2f(0.3f, 0.6f)).second, rho, 1e-6f);
    }
}

TEST(BSDFSampling, DiffuseConsistency) {
    auto bsdf = make_diffuse(Color3f(0.3f, 0.6f, 0.8f));
    PCG32 rng(7);
    BSDFContext ctx;
    int checked = 0;
    for (int i = 0; i < 10000; ++i) {
        SurfaceInteraction si = make_si(random_direction(rng, true));
        float s1 = rng.next_float();
        auto [bs, weight] = bsdf->sample(ctx, si, s1, next_point2f(rng));
        if (weight.is_black()) continue;
        ++checked;
        EXPECT_EQ(bs.sampled_type, BSDFFlags::DiffuseReflection);
        EXPECT_EQ(bs.sampled_component, 0u);
        EXPECT_EQ(bs.eta, 1.f);
        EXPECT_GT(bs.wo.z, 0.f);
        EXPECT_NEAR(norm(bs.wo), 1.f, 1e-5f);
        float pdf = bsdf->pdf(ctx, si, bs.wo);
        EXPECT_NEAR(bs.pdf, pdf, 1e-4f * pdf);
        Color3f expected = bsdf->eval(ctx, si, bs.wo) / pdf;
        expect_color_near(weight, expected, 1e-4f);
    }
    EXPECT_GT(checked, 9990);
}

TEST(BSDFEnergy, DiffuseAlbedoEqualsReflectance) {
    // E[weight] = ∫ f cos θo dωo = ρ; the weight of cosine sampling is exactly ρ, so compare the
    // Monte Carlo estimate of the same integral with uniform hemisphere sampling of eval().
    Color3f rho(0.25f, 0.5f, 1.f);
    auto bsdf = make_diffuse(rho);
    PCG32 rng(11);
    BSDFContext ctx;
    SurfaceInteraction si = make_si(normalize(Vector3f(0.4f, 0.1f, 0.7f)));
    const int n = 200000;
    double sum_w[3] = {0, 0, 0}, sum_u[3] = {0, 0, 0}, sum_u2 = 0;
    for (int i = 0; i < n; ++i) {
        float s1 = rng.next_float();
        auto [bs, weight] = bsdf->sample(ctx, si, s1, next_point2f(rng));
        Vector3f wo = warp::square_to_uniform_hemisphere(next_point2f(rng));
        Color3f f = bsdf->eval(ctx, si, wo) / warp::square_to_uniform_hemisphere_pdf(wo);
        for (int c = 0; c < 3; ++c) {
            sum_w[c] += weight[c];
            sum_u[c] += f[c];
        }
        sum_u2 += double(f.b) * f.b;
    }
    // Uniform estimator of ρ_b = 1: variance = (4/3 - 1) ρ² per sample, so σ ≈ 0.0013 here.
    double sigma_b = std::sqrt((sum_u2 / n - sqr(sum_u[2] / n)) / n);
    EXPECT_LT(sigma_b, 0.002);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(sum_w[c] / n, rho[c], 1e-5 * rho[c]);
        EXPECT_NEAR(sum_u[c] / n, rho[c], 4.0 * sigma_b * rho[c]);
    }
}

TEST(BSDFReciprocity, Diffuse) {
    auto bsdf = make_diffuse(Color3f(0.7f, 0.4f, 0.1f));
    PCG32 rng(3);
    BSDFContext ctx;
    for (int i = 0; i < 1000; ++i) {
        Vector3f a = random_direction(rng, true), b = random_direction(rng, true);
        // eval includes cos θo: divide it out on both sides.
        Color3f f_ab = bsdf->eval(ctx, make_si(a), b) / b.z;
        Color3f f_ba = bsdf->eval(ctx, make_si(b), a) / a.z;
        expect_color_near(f_ab, f_ba, 1e-5f);
    }
}

TEST(BSDFEval, DiffuseBackSideIsBlack) {
    auto bsdf = make_diffuse(Color3f(0.8f));
    BSDFContext ctx;
    Vector3f up = normalize(Vector3f(0.1f, 0.2f, 0.9f)),
             down = normalize(Vector3f(0.3f, 0.f, -0.6f));
    // Incident from below.
    SurfaceInteraction below = make_si(down);
    EXPECT_TRUE(bsdf->eval(ctx, below, up).is_black());
    EXPECT_TRUE(bsdf->eval(ctx, below, down).is_black());
    EXPECT_EQ(bsdf->pdf(ctx, below, up), 0.f);
    auto [bs, weight] = bsdf->sample(ctx, below, 0.5f, Point2f(0.3f, 0.6f));
    EXPECT_TRUE(weight.is_black());
    // Outgoing below.
    SurfaceInteraction above = make_si(up);
    EXPECT_TRUE(bsdf->eval(ctx, above, down).is_black());
    EXPECT_EQ(bsdf->pdf(ctx, above, down), 0.f);
    auto [value, pdf] = bsdf->eval_pdf(ctx, above, down);
    EXPECT_TRUE(value.is_black());
    EXPECT_EQ(pdf, 0.f);
}

TEST(BSDFEval, DiffuseRespectsContext) {
    auto bsdf = make_diffuse(Color3f(0.8f));
    SurfaceInteraction si = make_si(Vector3f(0.f, 0.f, 1.f));
    Vector3f wo = normalize(Vector3f(0.2f, 0.2f, 0.9f));

    BSDFContext glossy_only;
    glossy_only.type_mask = uint32_t(BSDFFlags::Glossy);
    EXPECT_TRUE(bsdf->eval(glossy_only, si, wo).is_black());
    EXPECT_EQ(bsdf->pdf(glossy_only, si, wo), 0.f);
    EXPECT_TRUE(bsdf->sample(glossy_only, si, 0.5f, Point2f(0.5f, 0.5f)).second.is_black());

    BSDFContext other_component;
    other_component.component = 1;
    EXPECT_TRUE(bsdf->eval(other_component, si, wo).is_black());
    EXPECT_TRUE(bsdf->sample(other_component, si, 0.5f, Point2f(0.5f, 0.5f)).second.is_black());

    BSDFContext component0;
    component0.component = 0;
    EXPECT_FALSE(bsdf->eval(component0, si, wo).is_black());
}

// Chi-square tests of this plugin's sampling: tests/chi2/configs.txt (label chi2).

namespace {

/// A user's texture, not made by the plugin registry: the same colour everywhere, or one that
/// varies with u.
class UserTexture final : public Texture {
public:
    UserTexture(const Color3f &value, bool varying) : m_value(value), m_varying(varying) {}
    Color3f eval(const SurfaceInteraction &si) const override {
        return m_varying ? m_value * si.uv.x : m_value;
    }
    Color3f mean() const override { return m_varying ? m_value * 0.5f : m_value; }
    bool is_spatially_varying() const override { return m_varying; }

private:
    Color3f m_value;
    bool m_varying;
};

} // namespace

TEST(BSDFEval, DiffuseTakesAnyTexturesConstantTheSameWay) {
    // A texture that is not spatially varying is evaluated once (its mean()), whichever class it
    // is: a user's constant gives bit for bit the BSDF values of a plain rgb; a varying one is
    // evaluated at every point.
    const Color3f rho(0.2f, 0.5f, 0.9f);
    auto plain = make_diffuse(rho);
    Properties constant("diffuse"), varying("diffuse");
    constant.set_object("reflectance", std::make_shared<UserTexture>(rho, false));
    varying.set_object("reflectance", std::make_shared<UserTexture>(rho, true));
    auto user = PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, constant);
    auto user_varying = PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, varying);
    SurfaceInteraction si = make_si(normalize(Vector3f(0.3f, -0.2f, 0.8f)));
    const Vector3f wo = normalize(Vector3f(-0.5f, 0.1f, 0.4f));
    for (float u : {0.f, 0.25f, 1.f}) {
        si.uv = Point2f(u, 0.5f);
        const Color3f a = plain->eval(BSDFContext(), si, wo), b = user->eval(BSDFContext(), si, wo);
        EXPECT_EQ(a.r, b.r);
        EXPECT_EQ(a.g, b.g);
        EXPECT_EQ(a.b, b.b);
        expect_color_near(user_varying->eval_diffuse_reflectance(si), rho * u, 1e-7f);
    }
}

TEST(Diffuse, ReflectsOnlyToWiSide) { EXPECT_GT(check_wi_side_only(*make_bsdf("diffuse")), 500); }
