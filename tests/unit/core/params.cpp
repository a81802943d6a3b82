// traverse(): listing a loaded scene's parameters, changing them in place, and the rule that a
// render after update() is the render of a fresh load of the edited scene, bit for bit.
#include <facet/params.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <unistd.h>

using namespace facet;

namespace {

/// A small scene: a path integrator, a perspective sensor, a textured floor, a box that may be
/// moved, a sphere, and a rectangle light. `v` overrides the pieces by name.
std::string scene_xml(std::map<std::string, std::string> v = {}) {
    std::map<std::string, std::string> d = {
        {"max_depth", R"(<integer name="max_depth" value="4"/>)"},
        {"sensor_to_world", R"(<lookat origin="0, 2, 6" target="0, 0.5, 0" up="0, 1, 0"/>)"},
        {"width", "24"},
        {"albedo", "0.7, 0.2, 0.1"},
        {"color0", "0.1"},
        {"box_to_world", ""},
        {"radius", "0.5"},
        {"radiance", "8, 6, 4"},
        {"options", ""},
    };
    for (auto &[k, value] : v) d[k] = value;
    return fmt::format(R"(<scene version="3.0.0">{options}
    <integrator type="path">{max_depth}</integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world">{sensor_to_world}</transform>
        <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
        <film type="hdrfilm"><integer name="width" value="{width}"/>
            <integer name="height" value="16"/><rfilter type="box"/></film>
    </sensor>
    <bsdf type="diffuse" id="wall"><rgb name="reflectance" value="{albedo}"/></bsdf>
    <shape type="rectangle" id="floor">
        <transform name="to_world"><rotate x="1" angle="-90"/><scale value="4"/></transform>
        <bsdf type="diffuse"><texture type="checkerboard" name="reflectance">
            <float name="color0" value="{color0}"/><float name="color1" value="0.8"/>
        </texture></bsdf>
    </shape>
    <shape type="cube">{box_to_world}<ref id="wall"/></shape>
    <shape type="sphere"><point name="center" value="1.5, 0.5, 0"/>
        <float name="radius" value="{radius}"/><ref id="wall"/></shape>
    <shape type="rectangle">
        <transform name="to_world"><rotate x="1" angle="90"/><translate y="3"/></transform>
        <emitter type="area"><rgb name="radiance" value="{radiance}"/></emitter>
    </shape>
</scene>)",
                       fmt::arg("max_depth", d["max_depth"]),
                       fmt::arg("sensor_to_world", d["sensor_to_world"]),
                       fmt::arg("width", d["width"]), fmt::arg("albedo", d["albedo"]),
                       fmt::arg("color0", d["color0"]), fmt::arg("box_to_world", d["box_to_world"]),
                       fmt::arg("radius", d["radius"]), fmt::arg("radiance", d["radiance"]),
                       fmt::arg("options", d["options"]));
}

std::shared_ptr<Scene> load(const std::string &xml) {
    return std::dynamic_pointer_cast<Scene>(load_string(xml));
}

Image render_image(const Scene &scene) {
    RenderOptions opts;
    opts.progress = false;
    opts.threads = 2;
    opts.seed = 7;
    return render(scene, *scene.sensors().front(), opts).image;
}

bool same_pixels(const Image &a, const Image &b) {
    return a.width == b.width && a.height == b.height && a.channels == b.channels &&
           std::memcmp(a.data.data(), b.data.data(), a.data.size() * sizeof(float)) == 0;
}

/// A transform as the 16 numbers of a <matrix>, and as the Transform such a matrix gives.
const float kBoxRows[16] = {0.5f, 0.f, 0.f,  -1.f, 0.f, 0.75f, 0.f, 0.75f,
                            0.f,  0.f, 0.5f, 0.5f, 0.f, 0.f,   0.f, 1.f};
std::string matrix_xml(const float (&rows)[16]) {
    std::string s;
    for (float v : rows) s += fmt::format("{} ", v);
    return R"(<matrix value=")" + s + R"("/>)";
}

/// The scene option that makes the Embree scene two-level.
const char *const kTwoLevel = R"(<boolean name="embree_two_level" value="true"/>)";

} // namespace

TEST(Params, ListsTheValuesOfEveryObjectByPath) {
    auto scene = load(scene_xml());
    SceneParameters params = traverse(scene);
    const auto &keys = params.keys();
    for (const char *key : {"integrator.max_depth", "sensor.fov", "sensor.to_world",
                            "sensor.sampler.sample_count", "sensor.film.width", "wall.reflectance",
                            "floor.to_world", "floor.bsdf.reflectance.color0", "shape_2.center",
                            "shape_2.radius", "shape_3.to_world", "shape_3.emitter.radiance"})
        EXPECT_NE(std::find(keys.begin(), keys.end(), key), keys.end()) << key;
    EXPECT_EQ(params.type("wall.reflectance"), Properties::Type::Color);
    EXPECT_EQ(params.type("sensor.film.width"), Properties::Type::Integer);
    EXPECT_EQ(params.type("sensor.to_world"), Properties::Type::Transform);
    EXPECT_EQ(std::get<int64_t>(params.get("integrator.max_depth")), 4);
    // The cube leaves to_world at its default: settable, not listed.
    EXPECT_TRUE(params.has("shape_1.to_world"));
    EXPECT_FALSE(params.is_set("shape_1.to_world"));
    EXPECT_EQ(std::find(keys.begin(), keys.end(), "shape_1.to_world"), keys.end());
}

TEST(Params, UnknownKeysAndWrongTypesAreClearErrors) {
    SceneParameters params = traverse(load(scene_xml()));
    try {
        params.set("wall.reflectnce", Color3f(0.5f));
        FAIL() << "expected an error";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("did you mean \"wall.reflectance\""),
                  std::string::npos)
            << e.what();
    }
    try {
        params.set("sensor.film.width", std::string("wide"));
        FAIL() << "expected an error";
    } catch (const Error &e) {
        EXPECT_NE(std::string(e.what()).find("has type integer, not string"), std::string::npos)
            << e.what();
    }
    params.set("sensor.fov", int64_t(30)); // an integer for a float
    EXPECT_EQ(std::get<double>(params.get("sensor.fov")), 30.0);
    EXPECT_EQ(params.pending(), 1u);
}

namespace {

struct Edit {
    const char *name;
    std::function<void(SceneParameters &)> apply;
    std::map<std::string, std::string> xml; ///< the same edit in the scene's text
    bool geometry;                          ///< a shape is built again
};

} // namespace

TEST(Params, AnUpdatedSceneRendersAsTheEditedSceneLoadedAfresh) {
    Transform box(Matrix4f::from_rows(kBoxRows));
    const float cam[16] = {-1.f, 0.f, 0.f,  0.5f, 0.f, 1.f, 0.f, 1.f,
                           0.f,  0.f, -1.f, 5.f,  0.f, 0.f, 0.f, 1.f};
    std::vector<Edit> edits = {
        {"bsdf albedo",
         [](auto &p) { p.set("wall.reflectance", Color3f(0.2f, 0.3f, 0.7f)); },
         {{"albedo", "0.2, 0.3, 0.7"}},
         false},
        {"texture value",
         [](auto &p) { p.set("floor.bsdf.reflectance.color0", 0.45); },
         {{"color0", "0.45"}},
         false},
        {"emitter radiance",
         [](auto &p) { p.set("shape_3.emitter.radiance", Color3f(2.f, 9.f, 3.f)); },
         {{"radiance", "2, 9, 3"}},
         false},
        {"shape to_world (a default)",
         [&](auto &p) { p.set("shape_1.to_world", box); },
         {{"box_to_world",
           R"(<transform name="to_world">)" + matrix_xml(kBoxRows) + "</transform>"}},
         true},
        {"sphere radius",
         [](auto &p) { p.set("shape_2.radius", 0.25); },
         {{"radius", "0.25"}},
         true},
        {"sensor to_world",
         [&](auto &p) { p.set("sensor.to_world", Transform(Matrix4f::from_rows(cam))); },
         {{"sensor_to_world", matrix_xml(cam)}},
         false},
        {"film size",
         [](auto &p) { p.set("sensor.film.width", int64_t(20)); },
         {{"width", "20"}},
         false},
        {"integrator max_depth",
         [](auto &p) { p.set("integrator.max_depth", int64_t(2)); },
         {{"max_depth", R"(<integer name="max_depth" value="2"/>)"}},
         false},
    };
    // One-level (the default), where a changed shape builds the whole Embree scene again, and
    // two-level, where it builds its own structure and the top level.
    for (const char *options : {"", kTwoLevel}) {
        for (const Edit &edit : edits) {
            SCOPED_TRACE(std::string(edit.name) + (*options ? " (two-level)" : ""));
            auto xml = [&](std::map<std::string, std::string> v) {
                v["options"] = options;
                return scene_xml(v);
            };
            auto scene = load(xml({}));
            const Image before = render_image(*scene);
            SceneParameters params = traverse(scene);
            edit.apply(params);
            SceneUpdate u = params.update();
            EXPECT_EQ(u.shapes_created, edit.geometry ? 1u : 0u);
            EXPECT_EQ(u.accel_rebuilt, edit.geometry);
            EXPECT_EQ(u.geometries_built, edit.geometry ? (*options ? 1u : 4u) : 0u);
            const Image after = render_image(*scene);
            const Image fresh = render_image(*load(xml(edit.xml)));
            EXPECT_TRUE(same_pixels(after, fresh));
            EXPECT_FALSE(same_pixels(after, before)); // the edit shows
        }
    }
}

TEST(Params, ATwoLevelSceneRebuildsOnlyTheEditedShapes) {
    Transform box(Matrix4f::from_rows(kBoxRows));
    std::map<std::string, std::string> v = {{"options", kTwoLevel}};
    auto scene = load(scene_xml(v));
    ASSERT_TRUE(scene->two_level());
    SceneParameters params = traverse(scene);
    // Successive edits, each against the Embree scene the last one left.
    params.set("shape_1.to_world", box);
    EXPECT_EQ(params.update().geometries_built, 1u);
    v["box_to_world"] = R"(<transform name="to_world">)" + matrix_xml(kBoxRows) + "</transform>";
    EXPECT_TRUE(same_pixels(render_image(*scene), render_image(*load(scene_xml(v)))));

    params.set("shape_2.radius", 0.3);
    params.set("shape_1.to_world", Transform());
    EXPECT_EQ(params.update().geometries_built, 2u);
    v["radius"] = "0.3";
    v["box_to_world"] = "";
    EXPECT_TRUE(same_pixels(render_image(*scene), render_image(*load(scene_xml(v)))));

    // A value that does not touch geometry keeps every structure.
    params.set("wall.reflectance", Color3f(0.3f));
    EXPECT_EQ(params.update().geometries_built, 0u);
    v["albedo"] = "0.3, 0.3, 0.3";
    EXPECT_TRUE(same_pixels(render_image(*scene), render_image(*load(scene_xml(v)))));
}

TEST(Params, SharedObjectsAreRelinkedNotRebuilt) {
    auto scene = load(scene_xml());
    SceneParameters params = traverse(scene);
    params.set("wall.reflectance", Color3f(0.5f));
    SceneUpdate u = params.update();
    EXPECT_EQ(u.objects_created, 1u); // the BSDF alone
    EXPECT_EQ(u.shapes_relinked, 2u); // the cube and the sphere refer to it
    EXPECT_EQ(u.shapes_created, 0u);
    EXPECT_FALSE(u.accel_rebuilt);
    // A second traverse() sees the value, and updates compose.
    SceneParameters again = traverse(scene);
    EXPECT_EQ(std::get<Color3f>(again.get("wall.reflectance")).g, 0.5f);
    again.set("shape_3.emitter.radiance", Color3f(1.f));
    again.update();
    EXPECT_TRUE(
        same_pixels(render_image(*scene),
                    render_image(*load(scene_xml({{"albedo", "0.5"}, {"radiance", "1"}})))));
}

TEST(Params, AFailedUpdateLeavesTheSceneAsItWas) {
    auto scene = load(scene_xml());
    const Image before = render_image(*scene);
    SceneParameters params = traverse(scene);
    params.set("wall.reflectance", Color3f(0.1f));
    params.set("sensor.film.width", int64_t(-3)); // the film refuses it
    EXPECT_THROW(params.update(), Error);
    EXPECT_EQ(params.pending(), 0u);
    EXPECT_TRUE(same_pixels(render_image(*scene), before));
    EXPECT_EQ(std::get<Color3f>(params.get("wall.reflectance")).r, 0.7f);
}

TEST(Params, NoUpdateWhileTheSceneRenders) {
    auto scene = load(scene_xml());
    SceneParameters params = traverse(scene);
    params.set("wall.reflectance", Color3f(0.1f));
    {
        Scene::RenderLock rendering(*scene);
        try {
            params.update();
            FAIL() << "expected an error";
        } catch (const Error &e) {
            EXPECT_NE(std::string(e.what()).find("while a render of it is running"),
                      std::string::npos)
                << e.what();
        }
    }
    params.set("wall.reflectance", Color3f(0.1f));
    params.update(); // once the render is over
}

TEST(Params, ScenesBuiltWithoutADescriptionHaveNoParameters) {
    auto scene = std::make_shared<Scene>(Properties());
    EXPECT_THROW(traverse(scene), Error);
}

TEST(Params, ShapesBuiltAgainFindTheirFilesAsTheLoadDid) {
    // A mesh named relative to the scene's folder: update() must look for it there, not in the
    // current folder.
    namespace fs = std::filesystem;
    fs::path dir = fs::temp_directory_path() / fmt::format("facet_params_{}", ::getpid());
    fs::create_directories(dir / "meshes");
    {
        std::ofstream obj(dir / "meshes" / "quad.obj");
        obj << "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 2 3\nf 1 3 4\n";
    }
    const std::string body = R"(<shape type="obj"><string name="filename" value="meshes/quad.obj"/>
        {}</shape>)";
    const std::string moved =
        R"(<transform name="to_world">)" + matrix_xml(kBoxRows) + "</transform>";
    auto write = [&](const std::string &name, const std::string &shape) {
        std::string xml = scene_xml();
        xml.replace(xml.rfind("</scene>"), 8, fmt::format(body, shape) + "</scene>");
        std::ofstream(dir / name) << xml;
        return (dir / name).string();
    };
    auto scene = load_scene(write("a.xml", ""));
    SceneParameters params = traverse(scene);
    params.set("shape_4.to_world", Transform(Matrix4f::from_rows(kBoxRows)));
    EXPECT_EQ(params.update().shapes_created, 1u);
    EXPECT_TRUE(
        same_pixels(render_image(*scene), render_image(*load_scene(write("b.xml", moved)))));
    fs::remove_all(dir);
}

TEST(Params, MovingAnInstanceRendersAsTheEditedSceneLoadedAfresh) {
    auto xml = [](const char *options, const std::string &to_world) {
        return fmt::format(R"(<scene version="3.0.0">{}
    <integrator type="path"><integer name="max_depth" value="3"/></integrator>
    <sensor type="perspective">
        <transform name="to_world"><lookat origin="0, 2, 6" target="0, 0.5, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
        <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="16"/></film>
    </sensor>
    <shape type="shapegroup" id="group">
        <shape type="cube"><transform name="to_world"><scale value="0.4"/></transform></shape>
        <shape type="sphere"><point name="center" value="0, 0.8, 0"/><float name="radius" value="0.3"/></shape>
    </shape>
    <shape type="instance"><ref id="group"/>
        <transform name="to_world"><translate x="-1"/></transform></shape>
    <shape type="instance"><ref id="group"/><transform name="to_world">{}</transform></shape>
    <shape type="rectangle">
        <transform name="to_world"><rotate x="1" angle="90"/><translate y="3"/></transform>
        <emitter type="area"><rgb name="radiance" value="8, 6, 4"/></emitter>
    </shape>
</scene>)",
                           options, to_world);
    };
    for (const char *options : {"", kTwoLevel}) {
        SCOPED_TRACE(*options ? "two-level" : "one-level");
        auto scene = load(xml(options, R"(<translate x="1"/>)"));
        SceneParameters params = traverse(scene);
        params.set("shape_2.to_world", Transform(Matrix4f::from_rows(kBoxRows)));
        SceneUpdate u = params.update();
        EXPECT_EQ(u.shapes_created, 1u);
        EXPECT_EQ(u.geometries_built, *options ? 1u : 3u); // the instances and the light
        EXPECT_TRUE(same_pixels(render_image(*scene),
                                render_image(*load(xml(options, matrix_xml(kBoxRows))))));
    }
}
