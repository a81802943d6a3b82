// PluginRegistry: loading checks, error messages, unqueried properties, static registration.
#include <facet/mode.h>
#include <facet/plugin.h>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <functional>
#include <thread>

using namespace facet;

#ifndef FACET_TEST_PLUGIN_DIR
#error "FACET_TEST_PLUGIN_DIR must point at the folder of the test-only plugin libraries"
#endif

namespace {

const std::string PluginDir = FACET_TEST_PLUGIN_DIR;

std::string lib(const std::string &name) { return PluginDir + "/" + name + ".so"; }

class StaticDiffuse : public Object {
public:
    explicit StaticDiffuse(const Properties &props) { props.get_float("reflectance", 0.5); }
    ObjectType type() const override { return ObjectType::BSDF; }
};

const PluginDescriptor StaticDiffuseDesc{
    FACET_ABI_VERSION,
    ObjectType::BSDF,
    "staticdiffuse",
    "A statically registered test plugin",
    "| reflectance | float | 0.5 | |",
    [](const Properties &props) -> Object * { return new StaticDiffuse(props); }};

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

class Registry : public ::testing::Test {
protected:
    void SetUp() override {
        reg.add_search_dir(PluginDir);
        reg.register_static(&StaticDiffuseDesc);
    }
    PluginRegistry &reg = PluginRegistry::instance();
};

const Location ObjLoc{"scene.xml", 10, 3};

Properties props_for(const std::string &plugin) {
    Properties p(plugin);
    p.set_location(ObjLoc);
    return p;
}

} // namespace

TEST_F(Registry, RefusesOtherAbiVersion) {
    std::string msg = error_of([&] { reg.load_library(lib("badabi")); });
    EXPECT_TRUE(contains(msg, lib("badabi"))) << msg;
    EXPECT_TRUE(contains(msg, fmt::format("ABI version {}", FACET_ABI_VERSION + 1))) << msg;
    EXPECT_TRUE(contains(msg, fmt::format("ABI version {}", FACET_ABI_VERSION))) << msg;
    EXPECT_TRUE(contains(msg, "rebuild")) << msg;
    // Also through the name lookup.
    msg = error_of([&] { reg.descriptor("badabi", ObjectType::BSDF); });
    EXPECT_TRUE(contains(msg, "badabi.so") && contains(msg, "ABI")) << msg;
}

TEST_F(Registry, RefusesLibraryWithoutDescriptor) {
    std::string msg = error_of([&] { reg.load_library(lib("nosymbol")); });
    EXPECT_TRUE(contains(msg, lib("nosymbol"))) << msg;
    EXPECT_TRUE(contains(msg, "is not a facet plugin")) << msg;
    EXPECT_TRUE(contains(msg, "facet_plugin_descriptor")) << msg;
}

TEST_F(Registry, RefusesMissingFile) {
    std::string msg = error_of([&] { reg.load_library(PluginDir + "/doesnotexist.so"); });
    EXPECT_TRUE(contains(msg, "doesnotexist.so")) << msg;
}

TEST_F(Registry, RefusesWrongKind) {
    std::string msg = error_of([&] { reg.descriptor("wrongkind", ObjectType::BSDF); });
    EXPECT_TRUE(contains(msg, "\"wrongkind\"")) << msg;
    EXPECT_TRUE(contains(msg, "is an emitter plugin, but a bsdf was expected")) << msg;
    EXPECT_TRUE(contains(msg, "bsdf")) << msg;
    // Once loaded, the same check applies, and through create() with the object's location.
    EXPECT_EQ(reg.descriptor("wrongkind").kind, ObjectType::Emitter);
    msg = error_of([&] { reg.create(ObjectType::BSDF, props_for("wrongkind")); });
    EXPECT_TRUE(contains(msg, "scene.xml:10:3") && contains(msg, "emitter") &&
                contains(msg, "bsdf"))
        << msg;
    msg = error_of([&] { reg.load_library(lib("wrongkind"), ObjectType::BSDF); });
    EXPECT_TRUE(contains(msg, lib("wrongkind")) && contains(msg, "emitter")) << msg;
}

TEST_F(Registry, RefusesNameMismatch) {
    std::string msg = error_of([&] { reg.load_library(lib("misnamed")); });
    EXPECT_TRUE(contains(msg, lib("misnamed"))) << msg;
    EXPECT_TRUE(contains(msg, "othername")) << msg;
}

TEST_F(Registry, UnknownPluginSuggestsClosestAndListsKnown) {
    std::string msg = error_of([&] { reg.descriptor("staticdifuse", ObjectType::BSDF); });
    EXPECT_TRUE(contains(msg, "unknown bsdf plugin \"staticdifuse\"")) << msg;
    EXPECT_TRUE(contains(msg, "did you mean \"staticdiffuse\"?")) << msg;
    EXPECT_TRUE(contains(msg, "Known bsdf plugins: ")) << msg;
    EXPECT_TRUE(contains(msg, "testgood")) << msg;
    // Other kinds and libraries that fail to load are not listed.
    EXPECT_FALSE(contains(msg, "wrongkind")) << msg;
    EXPECT_FALSE(contains(msg, "nosymbol")) << msg;
    EXPECT_FALSE(contains(msg, "badabi")) << msg;

    msg = error_of([&] { reg.descriptor("zzzzzzzzzzzz", ObjectType::BSDF); });
    EXPECT_TRUE(contains(msg, "unknown bsdf plugin")) << msg;
    EXPECT_FALSE(contains(msg, "did you mean")) << msg;
}

TEST_F(Registry, AvailableListsByKind) {
    auto bsdfs = reg.available(ObjectType::BSDF);
    auto emitters = reg.available(ObjectType::Emitter);
    auto has = [](const std::vector<std::string> &v, const std::string &n) {
        return std::find(v.begin(), v.end(), n) != v.end();
    };
    EXPECT_TRUE(has(bsdfs, "testgood"));
    EXPECT_TRUE(has(bsdfs, "staticdiffuse"));
    EXPECT_FALSE(has(bsdfs, "wrongkind"));
    EXPECT_TRUE(has(emitters, "wrongkind"));
    EXPECT_TRUE(std::is_sorted(bsdfs.begin(), bsdfs.end()));
    auto all = reg.available();
    EXPECT_TRUE(has(all, "testgood") && has(all, "wrongkind"));
    EXPECT_FALSE(has(all, "nosymbol") || has(all, "badabi") || has(all, "misnamed"));
}

TEST_F(Registry, CreatesObjectsWithTheirId) {
    Properties p = props_for("testgood");
    p.set("alpha", 0.25);
    p.set_id("mat1");
    auto obj = reg.create(ObjectType::BSDF, p);
    ASSERT_NE(obj, nullptr);
    EXPECT_EQ(obj->type(), ObjectType::BSDF);
    EXPECT_EQ(obj->id(), "mat1");
    EXPECT_EQ(obj->to_string(), "TestGood[alpha=0.25]");
    EXPECT_EQ(reg.descriptor("testgood").name, std::string("testgood"));

    auto s = reg.create(ObjectType::BSDF, props_for("staticdiffuse"));
    EXPECT_EQ(s->type(), ObjectType::BSDF);
}

TEST_F(Registry, APluginIsRefusedInAModeItDoesNotRenderIn) {
    // testgood is exported with the plain macro: rgb and mono only.
    for (ColourMode mode : {ColourMode::Spectral, ColourMode::SpectralPolarized}) {
        Properties p = props_for("testgood");
        p.set_mode(mode);
        try {
            reg.create(ObjectType::BSDF, p);
            ADD_FAILURE() << "testgood was accepted in " << mode_name(mode);
        } catch (const Error &e) {
            EXPECT_TRUE(contains(e.what(), fmt::format("the bsdf plugin \"testgood\" does not "
                                                       "render in the mode {} (it renders in: "
                                                       "scalar_rgb, scalar_mono)",
                                                       mode_name(mode))))
                << e.what();
            EXPECT_EQ(e.location().to_string(), "scene.xml:10:3");
        }
    }
    for (ColourMode mode : {ColourMode::RGB, ColourMode::Mono}) {
        Properties p = props_for("testgood");
        p.set_mode(mode);
        EXPECT_NE(reg.create(ObjectType::BSDF, p), nullptr);
    }
}

TEST_F(Registry, UnqueriedPropertiesAreAnErrorWithTheirLocation) {
    Properties p = props_for("testgood");
    p.set("alpha", 0.25, {"scene.xml", 11, 5});
    p.set("bogus", 0.1, {"scene.xml", 12, 5});
    p.set("color", Color3f(0.5f), {"scene.xml", 13, 5});
    try {
        reg.create(ObjectType::BSDF, p);
        FAIL() << "no error";
    } catch (const Error &e) {
        std::string msg = e.what();
        EXPECT_EQ(e.location().to_string(), "scene.xml:10:3");
        EXPECT_TRUE(contains(msg, "Found 2 unreferenced properties in bsdf plugin of type "
                                  "\"testgood\":"))
            << msg;
        EXPECT_TRUE(contains(msg, "- float \"bogus\" (scene.xml:12:5): 0.1")) << msg;
        EXPECT_TRUE(contains(msg, "- rgb \"color\" (scene.xml:13:5): [0.5, 0.5, 0.5]")) << msg;
        EXPECT_FALSE(contains(msg, "alpha")) << msg;
    }
}

TEST_F(Registry, LenientModeOnlyWarns) {
    Properties p = props_for("testgood");
    p.set("bogus", 0.1, {"scene.xml", 12, 5});
    LogLevel old = Logger::level();
    Logger::set_level(LogLevel::Warn);
    size_t before = Logger::warning_count();
    std::shared_ptr<Object> obj;
    EXPECT_NO_THROW(obj = reg.create(ObjectType::BSDF, p, true));
    Logger::set_level(old);
    EXPECT_NE(obj, nullptr);
    EXPECT_EQ(Logger::warning_count(), before + 1);
    // check_unqueried on its own.
    Properties q = props_for("x");
    q.set("unused", int64_t(3), {"scene.xml", 20, 1});
    EXPECT_THROW(check_unqueried(q, ObjectType::Shape, false), Error);
    q.mark_queried("unused");
    EXPECT_NO_THROW(check_unqueried(q, ObjectType::Shape, false));
}

TEST_F(Registry, PluginErrorsAreWrapped) {
    Properties p = props_for("testgood");
    p.set("fail", true, {"scene.xml", 15, 7});
    std::string msg = error_of([&] { reg.create(ObjectType::BSDF, p); });
    EXPECT_TRUE(
        contains(msg, "failed to instantiate bsdf plugin of type \"testgood\": asked to fail"))
        << msg;
    // The entry's location when the plugin gave one ...
    EXPECT_TRUE(contains(msg, "scene.xml:15:7")) << msg;
    // ... else the object's.
    Properties q = props_for("testgood");
    q.set("alpha", 2.0);
    msg = error_of([&] { reg.create(ObjectType::BSDF, q); });
    EXPECT_TRUE(contains(msg, "scene.xml:10:3: failed to instantiate bsdf plugin of type "
                              "\"testgood\": alpha must be in [0, 1]"))
        << msg;
}

TEST_F(Registry, SceneIsNotAPlugin) {
    EXPECT_THROW(reg.create(ObjectType::Scene, props_for("scene")), Error);
}

TEST_F(Registry, SearchPathOrder) {
    reg.add_search_dir("/nonexistent/first");
    setenv("FACET_PLUGIN_PATH", "/nonexistent/env1:/nonexistent/env2", 1);
    auto path = reg.search_path();
    unsetenv("FACET_PLUGIN_PATH");
    auto pos = [&](const std::string &d) {
        return std::find(path.begin(), path.end(), d) - path.begin();
    };
    ASSERT_LT(pos("/nonexistent/first"), long(path.size()));
    EXPECT_LT(pos(PluginDir), pos("/nonexistent/env1"));
    EXPECT_LT(pos("/nonexistent/first"), pos("/nonexistent/env1"));
    EXPECT_LT(pos("/nonexistent/env1"), pos("/nonexistent/env2"));
    EXPECT_EQ(pos("/nonexistent/env2"), long(path.size()) - 2);
    // Last: the plugin folder next to libfacet (lib/facet/plugins in the build tree).
    std::filesystem::path last(path.back());
    EXPECT_EQ(last.filename(), "plugins");
    EXPECT_EQ(last.parent_path().filename(), "facet");
#ifdef FACET_BINARY_DIR
    EXPECT_EQ(
        std::filesystem::weakly_canonical(last),
        std::filesystem::weakly_canonical(std::string(FACET_BINARY_DIR) + "/lib/facet/plugins"));
#endif
}

TEST_F(Registry, ConcurrentLookups) {
    std::vector<std::thread> threads;
    std::atomic<int> ok{0};
    for (int i = 0; i < 4; ++i)
        threads.emplace_back([&] {
            for (int k = 0; k < 50; ++k)
                if (reg.descriptor("testgood", ObjectType::BSDF).kind == ObjectType::BSDF) ++ok;
        });
    for (auto &t : threads) t.join();
    EXPECT_EQ(ok.load(), 200);
}

TEST(EditDistance, Levenshtein) {
    EXPECT_EQ(edit_distance("", ""), 0u);
    EXPECT_EQ(edit_distance("abc", ""), 3u);
    EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
    EXPECT_EQ(edit_distance("difuse", "diffuse"), 1u);
    EXPECT_EQ(edit_distance("conductor", "conductro"), 2u);
}

TEST(EditDistance, ClosestName) {
    std::vector<std::string> names{"diffuse", "dielectric", "conductor", "roughconductor"};
    EXPECT_EQ(closest_name("difuse", names), "diffuse");
    EXPECT_EQ(closest_name("roughconductr", names), "roughconductor");
    EXPECT_EQ(closest_name("plastic", names), "");
    EXPECT_EQ(closest_name("x", {}), "");
}
