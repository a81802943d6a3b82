// Texture (u, v) gradients (eval_1_grad, used by bumpmap): bitmap's bilinear slope against
// finite differences of eval_1 (grey and luminance, through to_uv, across the wrap), zero for
// nearest filtering and for constants, checkerboard's per-square gradient, and the error of a
// texture without one.

#include "draws.h"
#include "texture_lookup.h"

#include <facet/image.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/random.h>
#include <facet/texture.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <unistd.h>

using namespace facet;
namespace fs = std::filesystem;

namespace {

class TextureGrad : public ::testing::Test {
protected:
    void SetUp() override {
        m_dir = fs::temp_directory_path() /
                ("facet_texgrad_" + std::to_string(::getpid()) + "_" +
                 ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::create_directories(m_dir);
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(m_dir, ec);
    }
    /// A w × h EXR of pseudo-random values in `channels` channels.
    std::string write_random(const std::string &name, int w, int h, int channels) const {
        Image img(w, h, channels);
        img.channel_names =
            channels == 1 ? std::vector<std::string>{"Y"} : std::vector<std::string>{"R", "G", "B"};
        PCG32 rng(11);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (int c = 0; c < channels; ++c) img.at(x, y, c) = rng.next_float();
        std::string p = (m_dir / name).string();
        write_image(p, img);
        return p;
    }
    static std::shared_ptr<Texture> bitmap(const std::string &path, const std::string &filter,
                                           const Transform &to_uv = Transform()) {
        Properties props("bitmap");
        props.set_string("filename", path);
        props.set_string("filter_type", filter);
        props.set_transform("to_uv", to_uv);
        return PluginRegistry::instance().create_as<Texture>(ObjectType::Texture, props);
    }
    /// Central differences of eval_1 agree with eval_1_grad away from texel-centre kinks.
    static void expect_matches_differences(const Texture &tex, uint64_t seed) {
        PCG32 rng(seed);
        const float h = 1e-4f;
        int checked = 0;
        for (int i = 0; i < 300; ++i) {
            float u = rng.next_float() * 3.f - 1.f, v = rng.next_float() * 3.f - 1.f;
            Vector2f g = tex.eval_1_grad(at_uv(u, v));
            float du = (tex.eval_1(at_uv(u + h, v)) - tex.eval_1(at_uv(u - h, v))) / (2.f * h);
            float dv = (tex.eval_1(at_uv(u, v + h)) - tex.eval_1(at_uv(u, v - h))) / (2.f * h);
            // A kink (texel centre) between the two probes makes the difference meaningless: the
            // slope jumps there, while elsewhere it only drifts with the bilinear cross term.
            Vector2f gu = tex.eval_1_grad(at_uv(u + h, v)), gl = tex.eval_1_grad(at_uv(u - h, v));
            Vector2f gv = tex.eval_1_grad(at_uv(u, v + h)), gd = tex.eval_1_grad(at_uv(u, v - h));
            if (std::abs(gu.x - gl.x) > 5e-2f * (1.f + std::abs(g.x)) ||
                std::abs(gv.y - gd.y) > 5e-2f * (1.f + std::abs(g.y)))
                continue;
            EXPECT_NEAR(g.x, du, 2e-2f * (1.f + std::abs(du))) << u << ", " << v;
            EXPECT_NEAR(g.y, dv, 2e-2f * (1.f + std::abs(dv))) << u << ", " << v;
            ++checked;
        }
        EXPECT_GT(checked, 200);
    }
    fs::path m_dir;
};

} // namespace

TEST_F(TextureGrad, BilinearGreyMatchesFiniteDifferences) {
    auto tex = bitmap(write_random("grey.exr", 5, 3, 1), "bilinear");
    expect_matches_differences(*tex, 1);
}

TEST_F(TextureGrad, BilinearColourIsTheLuminanceSlope) {
    auto tex = bitmap(write_random("rgb.exr", 4, 6, 3), "bilinear");
    expect_matches_differences(*tex, 2);
}

TEST_F(TextureGrad, ThroughToUv) {
    Transform to_uv = Transform::translate(Vector3f(0.3f, -0.1f, 0.f)) *
                      Transform::rotate(Vector3f(0.f, 0.f, 1.f), 30.f) *
                      Transform::scale(Vector3f(2.f, 3.f, 1.f));
    auto tex = bitmap(write_random("grey.exr", 4, 4, 1), "bilinear", to_uv);
    expect_matches_differences(*tex, 3);
}

TEST_F(TextureGrad, KnownSlopeOfTwoPixels) {
    // Pixels 0 and 1 of a 2 × 1 image: between their centres the value rises by (1 - 0) over
    // half the u range, a slope of 2; no change along v.
    Image img(2, 1, 1);
    img.channel_names = {"Y"};
    img.at(0, 0, 0) = 0.f;
    img.at(1, 0, 0) = 1.f;
    std::string p = (m_dir / "two.exr").string();
    write_image(p, img);
    Properties props("bitmap");
    props.set_string("filename", p);
    props.set_string("wrap_mode", "clamp");
    auto tex = PluginRegistry::instance().create_as<Texture>(ObjectType::Texture, props);
    Vector2f g = tex->eval_1_grad(at_uv(0.5f, 0.5f));
    EXPECT_NEAR(g.x, 2.f, 1e-5f);
    EXPECT_NEAR(g.y, 0.f, 1e-6f);
    // Clamped beyond the outer pixel centres: flat.
    EXPECT_NEAR(tex->eval_1_grad(at_uv(0.1f, 0.5f)).x, 0.f, 1e-6f);
}

TEST_F(TextureGrad, NearestAndConstantsAreFlat) {
    auto tex = bitmap(write_random("grey.exr", 5, 3, 1), "nearest");
    PCG32 rng(4);
    for (int i = 0; i < 50; ++i) {
        const Point2f q = next_point2f(rng);
        Vector2f g = tex->eval_1_grad(at_uv(q.x, q.y));
        EXPECT_EQ(g.x, 0.f);
        EXPECT_EQ(g.y, 0.f);
    }
    ConstantTexture c(Color3f(0.3f));
    EXPECT_EQ(c.eval_1_grad(at_uv(0.2f, 0.7f)).x, 0.f);
}

TEST_F(TextureGrad, CheckerboardUsesEachSquaresTexture) {
    auto slope = bitmap(write_random("grey.exr", 5, 3, 1), "bilinear");
    Properties props("checkerboard");
    props.set_object("color0", slope);
    props.set_float("color1", 0.25);
    auto board = PluginRegistry::instance().create_as<Texture>(ObjectType::Texture, props);
    // Mitsuba's checkerboard: colour 0 where u and v fall in the same half of [0, 1].
    SurfaceInteraction in0 = at_uv(0.2f, 0.3f), in1 = at_uv(0.7f, 0.3f);
    EXPECT_EQ(board->eval_1_grad(in0).x, slope->eval_1_grad(in0).x);
    EXPECT_EQ(board->eval_1_grad(in0).y, slope->eval_1_grad(in0).y);
    EXPECT_EQ(board->eval_1_grad(in1).x, 0.f);
}

TEST_F(TextureGrad, TexturesWithoutAGradientSayWhy) {
    class Plain final : public Texture {
    public:
        Color3f eval(const SurfaceInteraction &) const override { return Color3f(1.f); }
        Color3f mean() const override { return Color3f(1.f); }
        std::string to_string() const override { return "Plain"; }
    } plain;
    try {
        plain.eval_1_grad(at_uv(0.f, 0.f));
        ADD_FAILURE() << "no error";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("Plain provides no (u, v) gradient"),
                  std::string::npos)
            << e.what();
    }
}
