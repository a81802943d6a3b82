// The envmap emitter: the direction mapping (+Y is the top row, u turns around +Y), its pdf
// integrating to one, and chi-square tests of its importance sampling on the maps Mitsuba uses
// for the same purpose (a single bright pixel, a constant map, a tiny 3×2 map) and on a rotated
// HDR sky.

#include <facet/chi2.h>
#include <facet/emitter.h>
#include <facet/image.h>
#include <facet/scene.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>

using namespace facet;
namespace fs = std::filesystem;

namespace {

std::string write_map(const std::string &name, int w, int h,
                      const std::function<Color3f(int, int)> &f) {
    fs::path dir = fs::temp_directory_path() / "facet-envmap-unit";
    fs::create_directories(dir);
    Image img(w, h, 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            Color3f c = f(x, y);
            for (int ch = 0; ch < 3; ++ch) img.at(x, y, ch) = c[ch];
        }
    std::string path = (dir / name).string();
    write_image(path, img);
    return path;
}

std::string scene_with(const std::string &map, const std::string &extra = "") {
    return R"(<scene version="3.0.0">
        <emitter type="envmap"><string name="filename" value=")" +
           map + R"("/>)" + extra + R"(</emitter>
        <shape type="sphere"><float name="radius" value="0.1"/></shape>
    </scene>)";
}

void expect_chi2_passes(const std::string &xml, const Point3f &ref, int res = 32) {
    EmitterAdapter adapter(xml, ref);
    Chi2Options opts;
    opts.res = res;
    opts.samples = 400000;
    Chi2Result r = run_chi2(adapter, opts);
    EXPECT_TRUE(r.passed) << r.summary();
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-2) << r.summary();
}

std::shared_ptr<Scene> load(const std::string &xml) {
    return std::dynamic_pointer_cast<Scene>(load_string(xml));
}

} // namespace

TEST(EnvironmentMap, TopRowIsUpAndUTurnsAroundY) {
    // Left half red, right half green, top rows blue.
    std::string map = write_map("quadrants.exr", 8, 4, [](int x, int y) {
        if (y == 0) return Color3f(0, 0, 1);
        return x < 4 ? Color3f(1, 0, 0) : Color3f(0, 1, 0);
    });
    auto scene = load(scene_with(map, R"(<string name="filter_type" value="nearest"/>)"));
    const Emitter &env = *scene->environment_emitters().at(0);
    auto look = [&](const Vector3f &d) {
        SurfaceInteraction si;
        si.wi = -normalize(d);
        return env.eval(si);
    };
    EXPECT_EQ(look({0, 1, 0}), Color3f(0, 0, 1));
    // u = atan2(x, -z) / 2π: -Z is u = 0 (left edge), +X is u = 1/4 (left half), -X is u = 3/4.
    EXPECT_EQ(look({1, -0.2f, 0}), Color3f(1, 0, 0));
    EXPECT_EQ(look({-1, -0.2f, 0}), Color3f(0, 1, 0));
}

TEST(EnvironmentMap, ScaleAndEvalMatchSampleWeight) {
    std::string map =
        write_map("flat.exr", 16, 8, [](int, int) { return Color3f(0.5f, 1.f, 2.f); });
    auto scene = load(scene_with(map, R"(<float name="scale" value="3"/>)"));
    const Emitter &env = *scene->environment_emitters().at(0);
    Interaction ref;
    ref.p = Point3f(0, 0, 0.5f);
    auto [ds, w] = env.sample_direction(ref, Point2f(0.3f, 0.6f));
    ASSERT_GT(ds.pdf, 0.f);
    SurfaceInteraction si;
    si.wi = -ds.d;
    Color3f L = env.eval(si);
    EXPECT_NEAR(L.r, 1.5f, 1e-5f);
    EXPECT_NEAR(L.b, 6.0f, 1e-5f);
    EXPECT_NEAR(w.g * ds.pdf, L.g, 1e-4f * L.g);
    EXPECT_NEAR(env.pdf_direction(ref, ds), ds.pdf, 1e-4f * ds.pdf);
}

TEST(EnvironmentMapChi2, SingleBrightPixel) {
    std::string map = write_map("one-pixel.exr", 100, 10, [](int x, int y) {
        return (x == 37 && y == 4) ? Color3f(1.f) : Color3f(0.f);
    });
    expect_chi2_passes(scene_with(map), Point3f(0.f, 0.f, 0.f));
}

TEST(EnvironmentMapChi2, ConstantMap) {
    std::string map = write_map("constant.exr", 100, 100, [](int, int) { return Color3f(1.f); });
    expect_chi2_passes(scene_with(map), Point3f(0.f, 0.f, 0.f));
}

TEST(EnvironmentMapChi2, TinyMap) {
    std::string map =
        write_map("tiny.exr", 3, 2, [](int x, int y) { return Color3f(float(1 + x + 3 * y)); });
    expect_chi2_passes(scene_with(map), Point3f(0.f, 0.f, 0.f));
}

TEST(EnvironmentMapChi2, RotatedSkyWithSun) {
    std::string map = write_map("sky.exr", 64, 32, [](int x, int y) {
        if (x >= 40 && x < 43 && y >= 8 && y < 10) return Color3f(400.f, 300.f, 200.f);
        float t = float(y) / 31.f;
        return Color3f(0.3f + t, 0.5f + t, 1.f);
    });
    expect_chi2_passes(
        scene_with(map,
                   R"(<transform name="to_world"><rotate x="1" y="1" angle="30"/></transform>)"),
        Point3f(0.05f, 0.0f, 0.02f));
}

TEST(EnvironmentMapChi2, UniformSamplingOption) {
    std::string map =
        write_map("grad.exr", 32, 16, [](int x, int) { return Color3f(0.1f + float(x)); });
    expect_chi2_passes(scene_with(map, R"(<boolean name="importance_sampling" value="false"/>)"),
                       Point3f(0.f, 0.f, 0.f));
}
