// What `facet bench` counts and replays: libfacet's statistics counters (per-thread counts,
// summed when read), the ray counts of Scene's queries, and the recording of the queries a
// scene sends to Embree, replayed as they were traced (core/apps/ray_recording.h).
#include "ray_recording.h"
#include "stats.h"

#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/scene.h>
#include <facet/transform.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <string>
#include <thread>
#include <vector>

using namespace facet;

namespace {

// A counter of the test's own, next to libfacet's.
const stats::Counter g_test_counter("test.events");

std::shared_ptr<Object> create(ObjectType kind, const std::string &type, Properties props = {}) {
    props.set_plugin_name(type);
    return PluginRegistry::instance().create(kind, props);
}

/// A 4 x 4 floor at z = 0 and a ball of radius 0.5 at z = 2.
Properties rect_and_sphere() {
    Properties rect;
    rect.set_transform("to_world", Transform::scale(Vector3f(2, 2, 1)));
    Properties sphere;
    sphere.set_vector("center", Vector3f(0, 0, 2));
    sphere.set_float("radius", 0.5);
    Properties props;
    props.set_object("floor", create(ObjectType::Shape, "rectangle", rect));
    props.set_object("ball", create(ObjectType::Shape, "sphere", sphere));
    return props;
}

/// Hits and misses of both kinds of query (5 ray_intersect() calls, 2 ray_test() calls), and a
/// NaN ray that never reaches Embree.
void trace(const Scene &scene) {
    SurfaceInteraction si;
    EXPECT_TRUE(scene.ray_intersect(Ray(Point3f(1, 0.5f, 3), Vector3f(0, 0, -1)), si));
    EXPECT_TRUE(scene.ray_intersect(Ray(Point3f(5, 0, 2), Vector3f(-1, 0, 0)), si));
    EXPECT_TRUE(scene.ray_intersect(Ray(Point3f(0, 0, 5), Vector3f(0, 0, -1), 3.f, 10.f), si));
    EXPECT_FALSE(scene.ray_intersect(Ray(Point3f(5, 5, 5), Vector3f(0, 0, 1)), si));
    EXPECT_TRUE(scene.ray_test(Ray(Point3f(0, 0, 5), Vector3f(0, 0, -1))));
    EXPECT_FALSE(scene.ray_test(Ray(Point3f(0, 0, 5), Vector3f(0, 0, -1), 0.f, 2.4f)));
    EXPECT_FALSE(scene.ray_intersect(
        Ray(Point3f(0, 0, 0), Vector3f(std::numeric_limits<float>::quiet_NaN(), 0, 0)), si));
}

} // namespace

TEST(Stats, CountsOfEveryThreadAreSummed) {
    const uint64_t before = g_test_counter.total();
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t)
        threads.emplace_back([t] {
            for (int i = 0; i < 1000; ++i) g_test_counter.add(uint64_t(t + 1));
        });
    for (std::thread &thread : threads) thread.join();
    // Counts of finished threads stay: 1000 · (1 + 2 + 3 + 4).
    EXPECT_EQ(g_test_counter.total() - before, 10000u);
    EXPECT_EQ(stats::total("test.events"), g_test_counter.total());
    EXPECT_EQ(stats::total("no such counter"), 0u);
    // Every counter is listed, libfacet's and this one.
    std::vector<std::string> names;
    for (const stats::CounterTotal &c : stats::totals()) names.push_back(c.name);
    for (const char *name : {"scene.ray_intersect", "scene.ray_test", "test.events"})
        EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
}

TEST(Stats, SceneCountsEveryQuery) {
    Scene scene(rect_and_sphere());
    const uint64_t intersect = stats::total("scene.ray_intersect");
    const uint64_t test = stats::total("scene.ray_test");
    trace(scene);
    // The NaN ray is counted although Embree never sees it.
    EXPECT_EQ(stats::total("scene.ray_intersect") - intersect, 5u);
    EXPECT_EQ(stats::total("scene.ray_test") - test, 2u);
    // Counted on another thread too.
    std::thread([&scene] { trace(scene); }).join();
    EXPECT_EQ(stats::total("scene.ray_intersect") - intersect, 10u);
    EXPECT_EQ(stats::total("scene.ray_test") - test, 4u);
}

TEST(RayRecording, ReplaysTheQueriesAsTraced) {
    Scene scene(rect_and_sphere());
    trace(scene); // not recorded
    // Room for two threads' claims on the budget (4096 queries each).
    RayRecording recording(10000);
    trace(scene);
    std::thread([&scene] { trace(scene); }).join(); // a second thread's log
    recording.stop();
    trace(scene); // not recorded
    RayRecording::Replay replay = recording.replay(scene);
    EXPECT_EQ(replay.rays, 12u);
    EXPECT_EQ(replay.differing, 0u);
    // A replay reproduces the queries, not just their number: through the floor alone, the ray
    // to the sphere's equator misses; the others reach the floor or miss as before.
    Properties floor_only;
    Properties rect;
    rect.set_transform("to_world", Transform::scale(Vector3f(2, 2, 1)));
    floor_only.set_object("floor", create(ObjectType::Shape, "rectangle", rect));
    Scene floor_scene(floor_only);
    replay = recording.replay(floor_scene);
    EXPECT_EQ(replay.rays, 12u);
    EXPECT_EQ(replay.differing, 2u);
}

TEST(RayRecording, BudgetBoundsWhatIsKept) {
    Scene scene(rect_and_sphere());
    {
        // Over every thread together; a new recording starts empty.
        RayRecording recording(4);
        trace(scene);
        std::thread([&scene] { trace(scene); }).join();
        recording.stop();
        EXPECT_EQ(recording.replay(scene).rays, 4u);
    }
    RayRecording recording(100);
    EXPECT_THROW(RayRecording(1), Error); // one at a time
    trace(scene);
    recording.stop();
    EXPECT_EQ(recording.replay(scene).rays, 6u);
    // Nothing is recorded once stopped.
    trace(scene);
    EXPECT_EQ(recording.replay(scene).rays, 6u);
}
