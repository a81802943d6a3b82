// Properties: typed getters, conversions, error messages, queried tracking, textures.
#include <facet/properties.h>
#include <facet/texture.h>

#include <gtest/gtest.h>

#include <functional>

using namespace facet;

namespace {

/// An object of some kind other than texture.
class DummyObject : public Object {
public:
    explicit DummyObject(ObjectType t) : m_type(t) {}
    ObjectType type() const override { return m_type; }
    std::string to_string() const override { return "dummy"; }

private:
    ObjectType m_type;
};

class DummyTexture : public Texture {
public:
    Color3f eval(const SurfaceInteraction &) const override { return Color3f(0.25f); }
    Color3f mean() const override { return Color3f(0.25f); }
    std::string to_string() const override { return "checker"; }
};

std::string error_of(const std::function<void()> &f) {
    try {
        f();
    } catch (const Error &e) {
        return e.what();
    }
    return "(no error)";
}

bool contains(const std::string &s, const std::string &part) {
    return s.find(part) != std::string::npos;
}

const Location Loc12{"scene.xml", 12, 5};
const Location ObjLoc{"scene.xml", 10, 3};

Properties sample_props() {
    Properties p("roughconductor");
    p.set_location(ObjLoc);
    p.set("alpha", 0.1, Loc12);
    p.set("count", int64_t(4), {"scene.xml", 13, 5});
    p.set("name", std::string("gold"), {"scene.xml", 14, 5});
    p.set("twosided", true);
    p.set("up", Vector3f(0, 1, 0));
    p.set("tint", Color3f(0.5f, 0.25f, 1.f));
    p.set("to_world", Transform::translate({1, 2, 3}));
    return p;
}

} // namespace

TEST(Properties, TypedGetters) {
    Properties p = sample_props();
    EXPECT_EQ(p.plugin_name(), "roughconductor");
    EXPECT_DOUBLE_EQ(p.get_float("alpha"), 0.1);
    EXPECT_EQ(p.get_int("count"), 4);
    EXPECT_EQ(p.get_string("name"), "gold");
    EXPECT_TRUE(p.get_bool("twosided"));
    EXPECT_EQ(p.get_vector("up"), Vector3f(0, 1, 0));
    EXPECT_EQ(p.get_color("tint"), Color3f(0.5f, 0.25f, 1.f));
    EXPECT_EQ(p.get_transform("to_world"), Transform::translate({1, 2, 3}));
    EXPECT_EQ(p.type("alpha"), Properties::Type::Float);
    EXPECT_EQ(p.type("tint"), Properties::Type::Color);
    EXPECT_EQ(p.location("alpha").to_string(), "scene.xml:12:5");
}

TEST(Properties, DefaultsWhenAbsent) {
    Properties p;
    EXPECT_DOUBLE_EQ(p.get_float("x", 2.5), 2.5);
    EXPECT_EQ(p.get_int("n", 7), 7);
    EXPECT_EQ(p.get_string("s", "abc"), "abc");
    EXPECT_FALSE(p.get_bool("b", false));
    EXPECT_EQ(p.get_vector("v", Vector3f(1, 2, 3)), Vector3f(1, 2, 3));
    EXPECT_EQ(p.get_color("c", Color3f(0.1f)), Color3f(0.1f));
    EXPECT_TRUE(p.get_transform("t", Transform()).is_identity());
    // Absent names are still recorded as requested.
    std::vector<std::string> expected{"x", "n", "s", "b", "v", "c", "t"};
    EXPECT_EQ(p.requested_names(), expected);
}

TEST(Properties, Conversions) {
    Properties p;
    p.set("i", int64_t(3));
    p.set("f", 0.75);
    p.set("v", Vector3f(0.1f, 0.2f, 0.3f));
    SpectrumData flat;
    flat.uniform = false;
    flat.wavelengths = {360, 830};
    flat.values = {0.5, 0.5};
    p.set("s", flat);
    p.set("u", SpectrumData::constant(2.0));
    // Integer -> float.
    EXPECT_DOUBLE_EQ(p.get_float("i"), 3.0);
    // Float -> grey, vector -> rgb, spectrum -> rgb with the kind.
    EXPECT_EQ(p.get_color("f"), Color3f(0.75f));
    EXPECT_EQ(p.get_color("v"), Color3f(0.1f, 0.2f, 0.3f));
    Color3f s = p.get_color("s");
    EXPECT_NEAR(s.r, 0.5f, 1e-3f);
    EXPECT_NEAR(s.g, 0.5f, 1e-3f);
    EXPECT_NEAR(s.b, 0.5f, 1e-3f);
    EXPECT_EQ(p.get_color("u", SpectrumKind::Reflectance), Color3f(2.f));
    Color3f e = p.get_color("u", SpectrumKind::Emission);
    EXPECT_NEAR(e.r, 2 * 1.204794f, 1e-4f);
    EXPECT_NEAR(e.b, 2 * 0.908916f, 1e-4f);
    // But a float is not an integer.
    std::string msg = error_of([&] { p.get_int("f"); });
    EXPECT_TRUE(contains(msg, "\"f\"") && contains(msg, "float") && contains(msg, "integer"))
        << msg;
}

TEST(Properties, WrongTypeNamesParameterTypesAndLocation) {
    Properties p("dielectric");
    p.set_location(ObjLoc);
    p.set("alpha", std::string("rough"), Loc12);
    try {
        p.get_float("alpha");
        FAIL() << "no error";
    } catch (const Error &e) {
        std::string msg = e.what();
        EXPECT_TRUE(contains(msg, "\"alpha\"")) << msg;
        EXPECT_TRUE(contains(msg, "string")) << msg;
        EXPECT_TRUE(contains(msg, "float")) << msg;
        EXPECT_TRUE(contains(msg, "scene.xml:12:5")) << msg;
        EXPECT_EQ(e.location().line, 12);
    }
    // The same for the other getters.
    for (auto get : std::vector<std::function<void()>>{
             [&] { p.get_bool("alpha"); }, [&] { p.get_int("alpha"); },
             [&] { p.get_vector("alpha"); }, [&] { p.get_color("alpha"); },
             [&] { p.get_transform("alpha"); }, [&] { p.texture("alpha"); }})
        EXPECT_TRUE(contains(error_of(get), "has type string")) << error_of(get);
}

TEST(Properties, MissingRequiredParameter) {
    Properties p("bitmap");
    p.set_location(ObjLoc);
    try {
        p.get_string("filename");
        FAIL() << "no error";
    } catch (const Error &e) {
        std::string msg = e.what();
        EXPECT_TRUE(contains(msg, "missing required parameter \"filename\"")) << msg;
        EXPECT_TRUE(contains(msg, "scene.xml:10:3")) << msg;
    }
    EXPECT_TRUE(contains(error_of([&] { p.texture("reflectance"); }), "\"reflectance\""));
}

TEST(Properties, DuplicateSetIsAnError) {
    Properties p;
    p.set("alpha", 0.1, Loc12);
    std::string msg = error_of([&] { p.set("alpha", 0.2, {"scene.xml", 20, 1}); });
    EXPECT_TRUE(contains(msg, "property \"alpha\" was specified multiple times")) << msg;
    EXPECT_TRUE(contains(msg, "scene.xml:20:1")) << msg;
    EXPECT_DOUBLE_EQ(p.get_float("alpha"), 0.1);
    p.set("alpha", 0.3, {}, true);
    EXPECT_DOUBLE_EQ(p.get_float("alpha"), 0.3);
    EXPECT_EQ(p.names().size(), 1u);
    EXPECT_TRUE(p.remove("alpha"));
    EXPECT_FALSE(p.remove("alpha"));
    EXPECT_FALSE(p.has("alpha"));
}

TEST(Properties, QueriedTracking) {
    Properties p = sample_props();
    EXPECT_FALSE(p.was_queried("alpha"));
    p.get_float("alpha");
    p.get_string("name", "x");
    EXPECT_TRUE(p.was_queried("alpha"));
    EXPECT_TRUE(p.was_queried("name"));
    // has() alone does not consume an entry.
    EXPECT_TRUE(p.has("count"));
    EXPECT_FALSE(p.was_queried("count"));
    p.mark_queried("up");
    std::vector<std::string> expected{"count", "twosided", "tint", "to_world"};
    EXPECT_EQ(p.unqueried(), expected);
    // A failed typed read still counts as a query (the entry was looked at).
    EXPECT_THROW(p.get_string("count"), Error);
    EXPECT_TRUE(p.was_queried("count"));
}

TEST(Properties, EntryToString) {
    Properties p = sample_props();
    EXPECT_EQ(p.entry_to_string("alpha"), "float \"alpha\": 0.1");
    EXPECT_EQ(p.entry_to_string("count"), "integer \"count\": 4");
    EXPECT_EQ(p.entry_to_string("name"), "string \"name\": \"gold\"");
    EXPECT_EQ(p.entry_to_string("tint"), "rgb \"tint\": [0.5, 0.25, 1]");
    EXPECT_EQ(p.entry_to_string("twosided"), "boolean \"twosided\": true");
    p.set("radiance", parse_spectrum_pairs("400:1, 500:2"));
    EXPECT_EQ(p.entry_to_string("radiance"), "spectrum \"radiance\": 400:1, 500:2");
    p.set("bsdf", std::make_shared<DummyObject>(ObjectType::BSDF));
    EXPECT_EQ(p.entry_to_string("bsdf"), "bsdf \"bsdf\": dummy");
}

TEST(Properties, TextureVariants) {
    Properties p;
    p.set("f", 0.5);
    p.set("i", int64_t(1));
    p.set("c", Color3f(0.1f, 0.2f, 0.3f));
    p.set("s", SpectrumData::constant(0.4));
    auto checker = std::make_shared<DummyTexture>();
    p.set("tex", checker);
    p.set("bsdf", std::make_shared<DummyObject>(ObjectType::BSDF));

    EXPECT_EQ(p.texture("f")->mean(), Color3f(0.5f));
    EXPECT_FALSE(p.texture("f")->is_spatially_varying());
    EXPECT_NE(std::dynamic_pointer_cast<ConstantTexture>(p.texture("f")), nullptr);
    EXPECT_EQ(p.texture("i")->mean(), Color3f(1.f));
    EXPECT_EQ(p.texture("c")->mean(), Color3f(0.1f, 0.2f, 0.3f));
    EXPECT_EQ(p.texture("s")->mean(), Color3f(0.4f));
    EXPECT_NEAR(p.texture("s", SpectrumKind::Emission)->mean().r, 0.4f * 1.204794f, 1e-5f);
    EXPECT_EQ(p.texture("tex"), checker);
    EXPECT_EQ(p.texture("tex", 0.9f), checker);
    std::string msg = error_of([&] { p.texture("bsdf"); });
    EXPECT_TRUE(contains(msg, "\"bsdf\"") && contains(msg, "texture")) << msg;
    // Absent: the default, as a constant.
    EXPECT_EQ(p.texture("missing", 0.7f)->mean(), Color3f(0.7f));
    EXPECT_EQ(p.texture("missing", Color3f(0.1f, 0.2f, 0.3f))->mean(), Color3f(0.1f, 0.2f, 0.3f));
    EXPECT_TRUE(contains(error_of([&] { p.texture("missing"); }), "missing required parameter"));
    EXPECT_TRUE(p.unqueried().empty());
}

TEST(Properties, ObjectsInOrder) {
    Properties p;
    auto a = std::make_shared<DummyObject>(ObjectType::Shape);
    auto b = std::make_shared<DummyObject>(ObjectType::Emitter);
    p.set("_arg_0", a);
    p.set("alpha", 0.1);
    p.set("light", b);
    auto objs = p.objects();
    ASSERT_EQ(objs.size(), 2u);
    EXPECT_EQ(objs[0].first, "_arg_0");
    EXPECT_EQ(objs[0].second, a);
    EXPECT_EQ(objs[1].first, "light");
    EXPECT_EQ(objs[1].second, b);
    // Listing does not consume them.
    EXPECT_EQ(p.unqueried().size(), 3u);
    // Typed access: right kind, wrong kind, absent.
    EXPECT_EQ(p.get_object<Object>("light"), b);
    EXPECT_EQ(p.get_object<Texture>("nothing"), nullptr);
    EXPECT_THROW(p.get_object<Texture>("light"), Error);
    EXPECT_THROW(p.get_object<Object>("alpha"), Error);
}

TEST(Properties, ConstantTextureToString) {
    EXPECT_TRUE(contains(ConstantTexture(Color3f(0.5f)).to_string(), "0.5"));
}
