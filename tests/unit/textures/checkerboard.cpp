// The checkerboard texture: the 2 × 2 pattern over the unit square and its repetition, defaults,
// to_uv, nested textures, mean/max/eval_1, errors, and use as a BSDF parameter.

#include "texture_lookup.h"

#include <facet/bsdf.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>
#include <facet/xml.h>

#include <fmt/format.h>
#include <gtest/gtest.h>

using namespace facet;

namespace {

std::shared_ptr<Texture> make_checkerboard(Properties &props) {
    props.set_plugin_name("checkerboard");
    return PluginRegistry::instance().create_as<Texture>(ObjectType::Texture, props);
}

void expect_error(Properties &props, const std::string &fragment) {
    try {
        make_checkerboard(props);
        ADD_FAILURE() << "expected an error containing \"" << fragment << "\"";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
}

/// A texture that is u everywhere (to check that nested textures are evaluated at the point).
class RampTexture final : public Texture {
public:
    Color3f eval(const SurfaceInteraction &si) const override { return Color3f(si.uv.x, 0.f, 1.f); }
    Color3f mean() const override { return Color3f(0.5f, 0.f, 1.f); }
    std::string to_string() const override { return "RampTexture"; }
};

} // namespace

TEST(Checkerboard, DefaultPattern) {
    Properties defaults;
    auto tex = make_checkerboard(defaults);
    // color0 = 0.4 where u and v are in the same half, color1 = 0.2 elsewhere.
    EXPECT_EQ(tex->eval(at_uv(0.25f, 0.25f)), Color3f(0.4f));
    EXPECT_EQ(tex->eval(at_uv(0.75f, 0.75f)), Color3f(0.4f));
    EXPECT_EQ(tex->eval(at_uv(0.75f, 0.25f)), Color3f(0.2f));
    EXPECT_EQ(tex->eval(at_uv(0.25f, 0.75f)), Color3f(0.2f));
    // Repeats with period 1 in both directions, negative coordinates included.
    for (float du : {-3.f, -1.f, 1.f, 2.f, 10.f})
        for (float dv : {-2.f, 0.f, 5.f})
            for (float u : {0.1f, 0.6f})
                for (float v : {0.3f, 0.9f})
                    EXPECT_EQ(tex->eval(at_uv(u + du, v + dv)), tex->eval(at_uv(u, v)))
                        << u + du << "," << v + dv;
    EXPECT_EQ(tex->eval(at_uv(-0.25f, 0.25f)), Color3f(0.2f));
    // Scalar queries see the opposite squares (Mitsuba 3's eval_1): color1 where the halves agree.
    EXPECT_FLOAT_EQ(tex->eval_1(at_uv(0.1f, 0.1f)), 0.2f);
    EXPECT_FLOAT_EQ(tex->eval_1(at_uv(0.6f, 0.6f)), 0.2f);
    EXPECT_FLOAT_EQ(tex->eval_1(at_uv(0.6f, 0.1f)), 0.4f);
    EXPECT_FLOAT_EQ(tex->eval_1(at_uv(0.1f, 0.6f)), 0.4f);
    EXPECT_NEAR(tex->mean().r, 0.3f, 1e-7f);
    EXPECT_EQ(tex->max(), 0.4f);
    EXPECT_TRUE(tex->is_spatially_varying());
    EXPECT_NE(tex->to_string().find("Checkerboard"), std::string::npos);
}

TEST(Checkerboard, ColoursToUvAndNestedTextures) {
    Properties props;
    props.set_color("color0", Color3f(1.f, 0.f, 0.f));
    props.set_object("color1", std::make_shared<RampTexture>());
    props.set_transform("to_uv", Transform::scale(Vector3f(4.f, 4.f, 1.f)));
    auto tex = make_checkerboard(props);
    // 8 × 8 checks: uv (0.05, 0.05) -> (0.2, 0.2): color0; (0.15, 0.05) -> (0.6, 0.2): color1.
    EXPECT_EQ(tex->eval(at_uv(0.05f, 0.05f)), Color3f(1.f, 0.f, 0.f));
    EXPECT_EQ(tex->eval(at_uv(0.15f, 0.05f)), Color3f(0.15f, 0.f, 1.f)); // the ramp at u = 0.15
    EXPECT_EQ(tex->eval(at_uv(0.3f, 0.3f)), Color3f(1.f, 0.f, 0.f));     // (1.2, 1.2)
    EXPECT_EQ(tex->eval(at_uv(0.3f, 0.4f)), Color3f(0.3f, 0.f, 1.f));    // (1.2, 1.6)
    EXPECT_EQ(tex->mean(), Color3f(0.75f, 0.f, 0.5f));
    EXPECT_FLOAT_EQ(tex->max(), 1.f);

    // Counting over a fine grid: half of the unit square is each colour.
    Properties plain_props;
    auto plain = make_checkerboard(plain_props);
    int n = 200, count0 = 0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            count0 += plain->eval(at_uv((i + 0.5f) / n, (j + 0.5f) / n)) == Color3f(0.4f);
    EXPECT_EQ(count0, n * n / 2);
}

TEST(Checkerboard, RejectsBadParameters) {
    Properties bad_color;
    bad_color.set_string("color0", "red");
    expect_error(bad_color, "color0");
    Properties bad_transform;
    bad_transform.set_float("to_uv", 2.0);
    expect_error(bad_transform, "to_uv");
    Properties unknown;
    unknown.set_float("scale", 2.0);
    expect_error(unknown, "scale");

    Properties all;
    all.set_float("color0", 0.1);
    make_checkerboard(all);
    std::string doc =
        PluginRegistry::instance().descriptor("checkerboard", ObjectType::Texture).doc;
    EXPECT_EQ(all.requested_names().size(), 3u);
    for (const std::string &name : all.requested_names())
        EXPECT_NE(doc.find("| " + name + " |"), std::string::npos) << name;
}

TEST(Checkerboard, WorksAsABSDFParameter) {
    auto bsdf = std::dynamic_pointer_cast<BSDF>(load_string(R"(<bsdf version="3.0.0" type="diffuse">
        <texture type="checkerboard" name="reflectance">
            <rgb name="color0" value="0.9, 0.9, 0.9"/>
            <float name="color1" value="0.1"/>
        </texture>
    </bsdf>)"));
    ASSERT_TRUE(bsdf);
    EXPECT_TRUE(has_flag(bsdf->flags(), BSDFFlags::SpatiallyVarying));
    Vector3f up(0.f, 0.f, 1.f);
    EXPECT_NEAR(bsdf->eval(BSDFContext(), at_uv(0.2f, 0.2f), up).r, 0.9f * InvPi, 1e-6f);
    EXPECT_NEAR(bsdf->eval(BSDFContext(), at_uv(0.7f, 0.2f), up).r, 0.1f * InvPi, 1e-6f);

    // As a blend weight (a scalar query, so the squares are swapped): weight 1 (color1) where the
    // u and v halves agree, 0 (color0) where they differ.
    auto blend =
        std::dynamic_pointer_cast<BSDF>(load_string(R"(<bsdf version="3.0.0" type="blendbsdf">
        <texture type="checkerboard" name="weight">
            <float name="color0" value="0"/>
            <float name="color1" value="1"/>
        </texture>
        <bsdf type="diffuse"><float name="reflectance" value="0.2"/></bsdf>
        <bsdf type="diffuse"><float name="reflectance" value="0.6"/></bsdf>
    </bsdf>)"));
    ASSERT_TRUE(blend);
    EXPECT_NEAR(blend->eval(BSDFContext(), at_uv(0.2f, 0.2f), up).r, 0.6f * InvPi, 1e-6f);
    EXPECT_NEAR(blend->eval(BSDFContext(), at_uv(0.2f, 0.7f), up).r, 0.2f * InvPi, 1e-6f);
}

// Mitsuba 3 evaluates a checkerboard with eval() for colours and eval_1() for scalars, and the
// two pick opposite squares: a checkerboard `alpha` and a checkerboard `reflectance` with the
// same colours disagree at every point. Every scalar consumer must go through eval_1.
TEST(Checkerboard, ScalarAndColourQueriesPickOppositeSquares) {
    const char *checker = R"(<texture type="checkerboard" name="{}">
            <float name="color0" value="{}"/>
            <float name="color1" value="{}"/>
        </texture>)";
    auto with = [&](const char *name, const char *c0, const char *c1) {
        return fmt::format(fmt::runtime(checker), name, c0, c1);
    };
    auto load_bsdf = [](const std::string &xml) {
        auto bsdf = std::dynamic_pointer_cast<BSDF>(load_string(xml));
        EXPECT_TRUE(bsdf);
        return bsdf;
    };
    Vector3f wo = normalize(Vector3f(0.3f, -0.2f, 0.9f));
    auto at = [&](float u, float v) {
        SurfaceInteraction si = at_uv(u, v);
        si.wi = normalize(Vector3f(-0.25f, 0.1f, 0.95f));
        return si;
    };
    const float same[2] = {0.2f, 0.7f}, differ[2] = {0.7f, 0.2f};

    // The colour query: reflectance 0.1 (color0) where the halves agree.
    auto diffuse = load_bsdf(fmt::format(R"(<bsdf version="3.0.0" type="diffuse">{}</bsdf>)",
                                         with("reflectance", "0.1", "0.3")));
    EXPECT_NEAR(diffuse->eval(BSDFContext(), at(same[0], same[0]), wo).g, 0.1f * InvPi * wo.z,
                1e-6f);
    EXPECT_NEAR(diffuse->eval(BSDFContext(), at(differ[0], differ[1]), wo).g, 0.3f * InvPi * wo.z,
                1e-6f);

    // The scalar query, same colours: roughness 0.3 (color1) where the halves agree.
    for (const char *type : {"roughconductor", "roughdielectric"}) {
        auto textured = load_bsdf(fmt::format(R"(<bsdf version="3.0.0" type="{}">{}</bsdf>)", type,
                                              with("alpha", "0.1", "0.3")));
        auto rough = load_bsdf(fmt::format(
            R"(<bsdf version="3.0.0" type="{}"><float name="alpha" value="0.3"/></bsdf>)", type));
        auto smooth = load_bsdf(fmt::format(
            R"(<bsdf version="3.0.0" type="{}"><float name="alpha" value="0.1"/></bsdf>)", type));
        for (float u : {same[0], same[1]}) {
            SurfaceInteraction si = at(u, u);
            EXPECT_EQ(textured->eval(BSDFContext(), si, wo), rough->eval(BSDFContext(), si, wo))
                << type;
            EXPECT_NE(textured->eval(BSDFContext(), si, wo), smooth->eval(BSDFContext(), si, wo))
                << type;
        }
        SurfaceInteraction si = at(differ[0], differ[1]);
        EXPECT_EQ(textured->eval(BSDFContext(), si, wo), smooth->eval(BSDFContext(), si, wo))
            << type;
    }

    // Anisotropic roughness: alpha_u and alpha_v are scalar queries too.
    auto aniso =
        load_bsdf(fmt::format(R"(<bsdf version="3.0.0" type="roughconductor">{}{}</bsdf>)",
                              with("alpha_u", "0.05", "0.5"), with("alpha_v", "0.35", "0.06")));
    auto aniso_same = load_bsdf(R"(<bsdf version="3.0.0" type="roughconductor">
        <float name="alpha_u" value="0.5"/><float name="alpha_v" value="0.06"/></bsdf>)");
    EXPECT_EQ(aniso->eval(BSDFContext(), at(same[0], same[0]), wo),
              aniso_same->eval(BSDFContext(), at(same[0], same[0]), wo));

    // Mask opacity: 1 (color1) where the halves agree, 0 (color0) where they differ.
    auto mask = load_bsdf(fmt::format(R"(<bsdf version="3.0.0" type="mask">{}
        <bsdf type="diffuse"><float name="reflectance" value="0.5"/></bsdf></bsdf>)",
                                      with("opacity", "0", "1")));
    EXPECT_NEAR(mask->eval(BSDFContext(), at(same[0], same[0]), wo).r, 0.5f * InvPi * wo.z, 1e-6f);
    EXPECT_EQ(mask->eval(BSDFContext(), at(differ[0], differ[1]), wo), Color3f(0.f));
    EXPECT_EQ(mask->eval_null_transmission(at(differ[0], differ[1])), Color3f(1.f));
}
