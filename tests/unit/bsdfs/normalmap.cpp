// normalmap, bumpmap and null: the perturbed frame (identity, tilt, flip_invalid_normals, the
// bump gradient), closed forms for a diffuse base, the terminator shadowing term, rejection of
// directions that change sides, sample weight == eval/pdf, energy, chi-square, errors and the
// null pass-through.

#include "../../../plugins/bsdfs/perturbed_bsdf.h"
#include "bsdf_checks.h"

#include <facet/texture.h>
#include <facet/xml.h>

using namespace facet;
using namespace bsdf_checks;

namespace {

/// A texture with a constant value and a constant (u, v) gradient (a tilted plane of heights).
class SlopeTexture final : public Texture {
public:
    SlopeTexture(float du, float dv) : m_grad(du, dv) {}
    Color3f eval(const SurfaceInteraction &si) const override {
        return Color3f(m_grad.x * si.uv.x + m_grad.y * si.uv.y);
    }
    Vector2f eval_1_grad(const SurfaceInteraction &) const override { return m_grad; }
    Color3f mean() const override { return Color3f(0.f); }
    std::string to_string() const override { return "SlopeTexture"; }

private:
    Vector2f m_grad;
};

/// A texture without a gradient.
class NoGradTexture final : public Texture {
public:
    Color3f eval(const SurfaceInteraction &) const override { return Color3f(0.5f); }
    Color3f mean() const override { return Color3f(0.5f); }
    std::string to_string() const override { return "NoGradTexture"; }
};

/// Texture value that encodes the unit normal n as (n + 1) / 2.
Color3f encode(const Vector3f &n) {
    return Color3f(0.5f * (n.x + 1.f), 0.5f * (n.y + 1.f), 0.5f * (n.z + 1.f));
}

std::shared_ptr<BSDF> normalmap(const Vector3f &n, const std::shared_ptr<BSDF> &nested,
                                const Params &params = {}) {
    Properties props = make_props("normalmap", params);
    props.set_object("normalmap", std::make_shared<ConstantTexture>(encode(normalize(n))));
    props.set_object("_arg_0", nested);
    return PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, props);
}

std::shared_ptr<BSDF> bumpmap(std::shared_ptr<Texture> height, const std::shared_ptr<BSDF> &nested,
                              const Params &params = {}) {
    Properties props = make_props("bumpmap", params);
    props.set_object("_arg_0", std::move(height));
    props.set_object("_arg_1", nested);
    return PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, props);
}

const PerturbedBSDF &perturbed(const std::shared_ptr<BSDF> &b) {
    return dynamic_cast<const PerturbedBSDF &>(*b);
}

float g1(const Vector3f &np, const Vector3f &wo) {
    float tan2_n = (1.f - np.z * np.z) / (np.z * np.z);
    float tan2_o = (1.f - wo.z * wo.z) / (wo.z * wo.z);
    float alpha2 = std::min(0.125f * tan2_n, 1.f);
    return 2.f / (1.f + std::sqrt(1.f + alpha2 * tan2_o));
}

} // namespace

TEST(NormalMap, CreationFlagsAndDocs) {
    auto d = make_bsdf("plastic");
    auto b = normalmap(Vector3f(0.f, 0.f, 1.f), d);
    ASSERT_EQ(b->component_count(), d->component_count());
    // The nested BSDF's sides are those of the perturbed frame: not WiSideOnly.
    for (size_t i = 0; i < d->component_count(); ++i)
        EXPECT_EQ(b->flags(i), d->flags(i) & ~BSDFFlags::WiSideOnly);
    EXPECT_TRUE(has_flag(d->flags(), BSDFFlags::WiSideOnly));
    EXPECT_FALSE(has_flag(b->flags(), BSDFFlags::WiSideOnly));
    EXPECT_NE(b->to_string().find("NormalMap"), std::string::npos);
    EXPECT_NE(b->to_string().find("Plastic"), std::string::npos);

    Properties textured("normalmap");
    textured.set_object("normalmap", std::make_shared<RampTexture>());
    textured.set_object("_arg_0", make_bsdf("diffuse"));
    auto t = PluginRegistry::instance().create_as<BSDF>(ObjectType::BSDF, textured);
    EXPECT_TRUE(has_flag(t->flags(0), BSDFFlags::SpatiallyVarying));
    std::string doc = PluginRegistry::instance().descriptor("normalmap", ObjectType::BSDF).doc;
    for (const std::string &name : textured.requested_names())
        EXPECT_NE(doc.find("| " + name + " |"), std::string::npos) << name;
}

TEST(NormalMap, RejectsBadParameters) {
    auto d = make_bsdf("diffuse");
    Properties none("normalmap");
    none.set_object("normalmap", std::make_shared<ConstantTexture>(Color3f(0.5f, 0.5f, 1.f)));
    try {
        PluginRegistry::instance().create(ObjectType::BSDF, none);
        ADD_FAILURE() << "no nested BSDF accepted";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("normalmap needs a nested BSDF"), std::string::npos);
    }
    expect_nested_error("normalmap", {d}, {}, "needs a \"normalmap\" texture");
    Properties two("normalmap");
    two.set_object("normalmap", std::make_shared<ConstantTexture>(Color3f(0.5f, 0.5f, 1.f)));
    two.set_object("_arg_0", d);
    two.set_object("_arg_1", d);
    try {
        PluginRegistry::instance().create(ObjectType::BSDF, two);
        ADD_FAILURE() << "two nested BSDFs accepted";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("exactly one nested BSDF"), std::string::npos);
    }
}

TEST(NormalMap, IdentityMapChangesNothing) {
    auto nested = make_bsdf("roughconductor", {{"alpha_u", 0.1}, {"alpha_v", 0.4}});
    auto b = normalmap(Vector3f(0.f, 0.f, 1.f), nested);
    PCG32 rng(3);
    for (int i = 0; i < 200; ++i) {
        SurfaceInteraction si = make_si(random_direction(rng, true));
        Vector3f wo = random_direction(rng, true);
        Color3f a = b->eval(BSDFContext(), si, wo), e = nested->eval(BSDFContext(), si, wo);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], e[c], 1e-5f * std::max(1.f, e[c]));
        EXPECT_NEAR(b->pdf(BSDFContext(), si, wo), nested->pdf(BSDFContext(), si, wo),
                    1e-5f * std::max(1.f, nested->pdf(BSDFContext(), si, wo)));
    }
}

TEST(NormalMap, TiltedDiffuseClosedForm) {
    // Diffuse in the tilted frame: R/π · <n_p, wo> · G(n_p, wo), zero where wo falls below the
    // perturbed horizon or wi, wo are on different sides of either frame.
    Vector3f np = normalize(Vector3f(0.4f, -0.2f, 1.f));
    const float R = 0.7f;
    for (bool shadowing : {true, false}) {
        auto b = normalmap(np, make_bsdf("diffuse", {{"reflectance", double(R)}}),
                           {{"use_shadowing_function", shadowing}});
        PCG32 rng(5);
        int nonzero = 0;
        for (int i = 0; i < 500; ++i) {
            Vector3f wi = random_direction(rng, true), wo = random_direction(rng, false);
            SurfaceInteraction si = make_si(wi);
            // Keep away from the flip (wi on the back of the perturbed frame).
            if (dot(wi, np) < 0.05f) continue;
            float expected = 0.f;
            if (wo.z > 0.f && dot(wo, np) > 0.f)
                expected = R * InvPi * dot(wo, np) * (shadowing ? g1(np, wo) : 1.f);
            float got = b->eval(BSDFContext(), si, wo).r;
            EXPECT_NEAR(got, expected, 1e-5f) << wi << " " << wo;
            nonzero += expected > 0.f;
        }
        EXPECT_GT(nonzero, 100);
    }
}

TEST(NormalMap, ShadowingTermIsOneForTheUnperturbedNormal) {
    EXPECT_FLOAT_EQ(shadow_terminator(Vector3f(0.f, 0.f, 1.f), normalize(Vector3f(1, 0, 0.1f))),
                    1.f);
    // A 60° tilt saturates alpha² at 1 (0.125 · tan² 60° = 0.375 is below; 80° is above).
    Vector3f n80 = direction_from_angles(80.f, 0.f), wo = direction_from_angles(70.f, 30.f);
    float t2 = Frame::tan_theta_2(wo);
    EXPECT_NEAR(shadow_terminator(n80, wo), 2.f / (1.f + std::sqrt(1.f + t2)), 1e-6f);
    EXPECT_LT(shadow_terminator(direction_from_angles(30.f, 0.f), wo), 1.f);
    EXPECT_EQ(shadow_terminator(n80, Vector3f(1.f, 0.f, 0.f)), 0.f);
}

TEST(NormalMap, FlipInvalidNormals) {
    // wi lies behind the perturbed normal: with the flag the tangential part is mirrored.
    Vector3f n = normalize(Vector3f(1.f, 1.f, 1.f));
    Vector3f wi = normalize(Vector3f(-1.f, -1.f, 0.5f));
    SurfaceInteraction si = make_si(wi);
    auto on = normalmap(n, make_bsdf("diffuse"));
    auto off = normalmap(n, make_bsdf("diffuse"), {{"flip_invalid_normals", false}});
    Vector3f n_on = perturbed(on).local_frame(si).n, n_off = perturbed(off).local_frame(si).n;
    EXPECT_NEAR(n_on.x, -n.x, 1e-6f);
    EXPECT_NEAR(n_on.y, -n.y, 1e-6f);
    EXPECT_NEAR(n_on.z, n.z, 1e-6f);
    EXPECT_NEAR(n_off.x, n.x, 1e-6f);
    EXPECT_GT(dot(wi, n_on), 0.f);
    // Without the flip wi is below the perturbed diffuse surface: nothing is reflected.
    Vector3f wo = Vector3f(0.f, 0.f, 1.f);
    EXPECT_EQ(off->eval(BSDFContext(), si, wo).r, 0.f);
    EXPECT_GT(on->eval(BSDFContext(), si, wo).r, 0.f);
    // The frame stays orthonormal, its tangent in the plane of x and n.
    Frame f = perturbed(on).local_frame(si);
    EXPECT_NEAR(dot(f.s, f.n), 0.f, 1e-6f);
    EXPECT_NEAR(dot(f.t, f.n), 0.f, 1e-6f);
    EXPECT_NEAR(norm(f.s), 1.f, 1e-6f);
    Vector3f s = normalize(Vector3f(1.f, 0.f, 0.f) - f.n * f.n.x);
    EXPECT_NEAR(dot(f.s, s), 1.f, 1e-6f);
    EXPECT_NEAR(norm(cross(f.n, f.s) - f.t), 0.f, 1e-6f);
}

TEST(NormalMap, SampleMatchesEvalAndPdf) {
    Vector3f np = normalize(Vector3f(0.3f, 0.25f, 1.f));
    for (const auto &nested : {make_bsdf("diffuse"), make_bsdf("roughconductor", {{"alpha", 0.2}}),
                               make_bsdf("roughplastic", {{"alpha", 0.3}})}) {
        auto b = normalmap(np, nested);
        EXPECT_GT(check_sample_eval_pdf(*b, BSDFContext(), false), 1000) << nested->to_string();
        for (float theta : {0.f, 40.f, 80.f})
            EXPECT_LE(furnace(*b, BSDFContext(), direction_from_angles(theta, 20.f), 20000).max(),
                      1.f + 5e-3f)
                << theta;
    }
}

TEST(BumpMap, NormalFromTheHeightGradient) {
    const float a = 0.8f, b = -0.5f, scale = 0.3f;
    auto bump = bumpmap(std::make_shared<SlopeTexture>(a, b), make_bsdf("diffuse"),
                        {{"scale", double(scale)}});
    SurfaceInteraction si = make_si(Vector3f(0.f, 0.f, 1.f));
    Vector3f n = perturbed(bump).local_frame(si).n;
    Vector3f expected = normalize(Vector3f(-scale * a, -scale * b, 1.f));
    EXPECT_NEAR(n.x, expected.x, 1e-6f);
    EXPECT_NEAR(n.y, expected.y, 1e-6f);
    EXPECT_NEAR(n.z, expected.z, 1e-6f);

    // Longer tangents (a surface whose uv spans less distance) tilt the normal less.
    si.dp_du = Vector3f(2.f, 0.f, 0.f);
    si.dp_dv = Vector3f(0.f, 4.f, 0.f);
    n = perturbed(bump).local_frame(si).n;
    expected = normalize(Vector3f(-scale * a * 4.f, -scale * b * 2.f, 8.f));
    EXPECT_NEAR(n.x, expected.x, 1e-6f);
    EXPECT_NEAR(n.y, expected.y, 1e-6f);

    // A flat height field changes nothing.
    auto flat = bumpmap(std::make_shared<SlopeTexture>(0.f, 0.f), make_bsdf("diffuse"));
    n = perturbed(flat).local_frame(make_si(Vector3f(0.f, 0.f, 1.f))).n;
    EXPECT_EQ(n, Vector3f(0.f, 0.f, 1.f));
}

TEST(BumpMap, RejectsBadParameters) {
    auto d = make_bsdf("diffuse");
    auto slope = std::make_shared<SlopeTexture>(1.f, 0.f);
    try {
        bumpmap(std::make_shared<NoGradTexture>(), d);
        ADD_FAILURE() << "a texture without a gradient was accepted";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("cannot serve as a height field"), std::string::npos)
            << e.what();
    }
    expect_nested_error("bumpmap", {d}, {}, "bumpmap needs a nested height texture");
    Properties no_bsdf("bumpmap");
    no_bsdf.set_object("_arg_0", slope);
    try {
        PluginRegistry::instance().create(ObjectType::BSDF, no_bsdf);
        ADD_FAILURE() << "no nested BSDF accepted";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("bumpmap needs a nested BSDF"), std::string::npos);
    }
    Properties two("bumpmap");
    two.set_object("_arg_0", slope);
    two.set_object("_arg_1", slope);
    two.set_object("_arg_2", d);
    try {
        PluginRegistry::instance().create(ObjectType::BSDF, two);
        ADD_FAILURE() << "two height textures accepted";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("exactly one nested height texture"),
                  std::string::npos);
    }
}

TEST(BumpMap, SampleMatchesEvalAndPdfAndDocs) {
    auto bump = bumpmap(std::make_shared<SlopeTexture>(1.5f, 0.7f),
                        make_bsdf("roughconductor", {{"alpha", 0.3}}), {{"scale", 0.5}});
    EXPECT_GT(check_sample_eval_pdf(*bump, BSDFContext(), false), 1000);
    EXPECT_LE(furnace(*bump, BSDFContext(), direction_from_angles(50.f, 0.f), 20000).max(),
              1.f + 5e-3f);
    Properties props("bumpmap");
    props.set_object("_arg_0", std::make_shared<SlopeTexture>(1.f, 0.f));
    props.set_object("_arg_1", make_bsdf("diffuse"));
    PluginRegistry::instance().create(ObjectType::BSDF, props);
    std::string doc = PluginRegistry::instance().descriptor("bumpmap", ObjectType::BSDF).doc;
    for (const std::string &name : props.requested_names())
        EXPECT_NE(doc.find("| " + name + " |"), std::string::npos) << name;
}

TEST(NullBSDF, PassesEverythingThrough) {
    auto b = make_bsdf("null");
    ASSERT_EQ(b->component_count(), 1u);
    EXPECT_EQ(b->flags(0), BSDFFlags::Null | BSDFFlags::FrontSide | BSDFFlags::BackSide);
    EXPECT_FALSE(has_flag(b->flags(), BSDFFlags::Smooth));
    PCG32 rng(9);
    for (int i = 0; i < 100; ++i) {
        Vector3f wi = random_direction(rng, false), wo = random_direction(rng, false);
        SurfaceInteraction si = make_si(wi);
        auto [bs, weight] = b->sample(BSDFContext(), si, rng.next_float(), Point2f(0.2f, 0.9f));
        EXPECT_EQ(bs.wo, -wi);
        EXPECT_EQ(weight, Color3f(1.f));
        EXPECT_EQ(bs.pdf, 1.f);
        EXPECT_EQ(bs.eta, 1.f);
        EXPECT_EQ(bs.sampled_type, BSDFFlags::Null);
        EXPECT_EQ(b->eval(BSDFContext(), si, wo), Color3f(0.f));
        EXPECT_EQ(b->pdf(BSDFContext(), si, wo), 0.f);
        EXPECT_EQ(b->eval_null_transmission(si), Color3f(1.f));
    }
    BSDFContext no_null;
    no_null.type_mask = uint32_t(BSDFFlags::All) & ~uint32_t(BSDFFlags::Null);
    EXPECT_TRUE(
        b->sample(no_null, make_si(Vector3f(0, 0, 1)), 0.5f, Point2f(0.5f)).second.is_black());
    expect_error("null", {{"reflectance", 0.5}}, "reflectance");
}

TEST(NormalMap, LoadsFromXml) {
    auto bsdf =
        std::dynamic_pointer_cast<BSDF>(load_string(R"(<bsdf version="3.0.0" type="normalmap">
        <texture type="rawconstant" name="normalmap">
            <vector name="value" value="0.5, 0.5, 1"/>
        </texture>
        <boolean name="use_shadowing_function" value="false"/>
        <bsdf type="diffuse"/>
    </bsdf>)"));
    ASSERT_TRUE(bsdf);
    SurfaceInteraction si = make_si(Vector3f(0.f, 0.f, 1.f));
    EXPECT_NEAR(bsdf->eval(BSDFContext(), si, Vector3f(0.f, 0.f, 1.f)).r, 0.5f * InvPi, 1e-6f);
}
