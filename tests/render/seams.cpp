// Light leaks at mesh seams. Rays from inside the shipped Cornell box aimed at points on the
// edges that two triangles share (the diagonal of each wall and the seams where walls meet) and
// at the corners surrounded by such edges, on the box as modelled (round coordinates) and under
// a rotation and scale that give every vertex non-round float coordinates: with the robust
// triangle test (`embree_use_robust_intersections`) none gets out. With the fast test (the
// default, as in Mitsuba 3) a few such exactly-aimed rays slip through, but no ray in a random
// direction gets out of a closed mesh.

#include <facet/math.h>
#include <facet/mesh.h>
#include <facet/random.h>
#include <facet/scene.h>
#include <facet/shapegroup.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <tuple>
#include <vector>

using namespace facet;

namespace {

std::string box_xml(bool robust, const std::string &transform) {
    const std::string dir = std::string(FACET_SOURCE_DIR) + "/scenes/cornell-box/meshes/";
    std::string xml = "<scene version=\"3.0.0\">\n";
    xml += std::string("<boolean name=\"embree_use_robust_intersections\" value=\"") +
           (robust ? "true" : "false") + "\"/>\n";
    for (const char *wall : {"floor", "ceiling", "back", "left", "right"})
        xml += std::string("<shape type=\"obj\"><string name=\"filename\" value=\"") + dir + wall +
               ".obj\"/><transform name=\"to_world\">" + transform + "</transform></shape>\n";
    return xml + "</scene>\n";
}

using Key = std::tuple<uint32_t, uint32_t, uint32_t>;
Key key_of(const Point3f &p) {
    uint32_t b[3];
    std::memcpy(&b[0], &p.x, 4);
    std::memcpy(&b[1], &p.y, 4);
    std::memcpy(&b[2], &p.z, 4);
    return {b[0], b[1], b[2]};
}

struct Seams {
    std::vector<std::pair<Point3f, Point3f>> edges; ///< edges of two triangles (any meshes)
    std::vector<Point3f> vertices;                  ///< vertices whose every edge is shared
    std::vector<Point3f> corners;                   ///< all vertices (their hull is the box)
};

Seams find_seams(const Scene &scene) {
    std::map<std::pair<Key, Key>, int> edge_count;
    std::map<std::pair<Key, Key>, std::pair<Point3f, Point3f>> edge_points;
    std::map<Key, Point3f> vertex_points;
    for (const auto &shape : scene.shapes()) {
        const auto *mesh = dynamic_cast<const Mesh *>(shape.get());
        if (!mesh) continue;
        const auto &faces = mesh->faces();
        for (size_t f = 0; f < faces.size(); f += 3) {
            for (int k = 0; k < 3; ++k) {
                Point3f a = mesh->vertex_position(faces[f + k]),
                        b = mesh->vertex_position(faces[f + (k + 1) % 3]);
                Key ka = key_of(a), kb = key_of(b);
                vertex_points[ka] = a;
                auto edge = ka < kb ? std::make_pair(ka, kb) : std::make_pair(kb, ka);
                ++edge_count[edge];
                edge_points[edge] = {a, b};
            }
        }
    }
    Seams seams;
    std::map<Key, bool> open_vertex;
    for (const auto &[edge, count] : edge_count) {
        if (count >= 2) {
            seams.edges.push_back(edge_points[edge]);
        } else {
            open_vertex[edge.first] = true;
            open_vertex[edge.second] = true;
        }
    }
    for (const auto &[key, p] : vertex_points) {
        seams.corners.push_back(p);
        if (!open_vertex.count(key)) seams.vertices.push_back(p);
    }
    return seams;
}

/// Number of rays that leave the box when aimed from interior points at the seams.
struct LeakCount {
    int rays = 0, escaped = 0;
};

LeakCount count_leaks(bool robust, const std::string &transform) {
    auto scene = std::static_pointer_cast<Scene>(load_string(box_xml(robust, transform)));
    EXPECT_EQ(scene->robust_intersections(), robust);
    Seams seams = find_seams(*scene);
    // The box: 5 walls of two triangles; seams are the 5 diagonals and the 8 closed wall joints,
    // and the 4 back corners are surrounded by seams.
    EXPECT_EQ(seams.edges.size(), 13u);
    EXPECT_EQ(seams.vertices.size(), 4u);

    std::vector<Point3f> targets = seams.vertices;
    for (const auto &[a, b] : seams.edges)
        for (int i = 1; i < 32; ++i) {
            float t = float(i) / 32.f;
            targets.push_back(a * (1.f - t) + b * t);
        }

    PCG32 rng(7, 11);
    LeakCount leaks;
    for (int o = 0; o < 48; ++o) {
        // A point well inside the box: a random convex combination of its corners.
        Point3f origin(0.f);
        float total = 0.f;
        std::vector<float> w(seams.corners.size());
        for (float &x : w) total += (x = 0.2f + rng.next_float());
        for (size_t i = 0; i < w.size(); ++i) origin += seams.corners[i] * (w[i] / total);
        for (const Point3f &target : targets) {
            Vector3f d = target - origin;
            float dist = norm(d);
            Ray ray(origin, d / dist, 0.f, Infinity);
            SurfaceInteraction si;
            ++leaks.rays;
            if (!scene->ray_intersect(ray, si)) {
                ++leaks.escaped;
                continue;
            }
            // The hit is the aimed point (a wall in front of it would be inside the box).
            EXPECT_NEAR(si.t, dist, 1e-4f * dist);
        }
    }
    return leaks;
}

const char *AS_MODELLED = "<scale value=\"1\"/>";
const char *ROTATED = "<scale value=\"137.3\"/><rotate x=\"0.3\" y=\"1\" z=\"0.2\" angle=\"33.7\"/>"
                      "<translate x=\"278.1\" y=\"-3.7\" z=\"29.9\"/>";

/// Rays from random points inside a closed `cube` mesh (12 triangles sharing their edges) in
/// random directions: the number that leave it.
int random_ray_leaks(bool robust, const std::string &transform, int count) {
    std::string xml = std::string("<scene version=\"3.0.0\"><boolean "
                                  "name=\"embree_use_robust_intersections\" value=\"") +
                      (robust ? "true" : "false") +
                      "\"/><shape type=\"cube\"><transform name=\"to_world\">" + transform +
                      "</transform></shape></scene>";
    auto scene = std::static_pointer_cast<Scene>(load_string(xml));
    const auto *mesh = dynamic_cast<const Mesh *>(scene->shapes().at(0).get());
    EXPECT_TRUE(mesh);
    std::vector<Point3f> corners;
    for (size_t i = 0; i < mesh->vertex_count(); ++i) corners.push_back(mesh->vertex_position(i));
    PCG32 rng(3, 5);
    int escaped = 0;
    for (int i = 0; i < count; ++i) {
        Point3f origin(0.f);
        float total = 0.f;
        std::vector<float> w(corners.size());
        for (float &x : w) total += (x = rng.next_float());
        for (size_t k = 0; k < w.size(); ++k) origin += corners[k] * (w[k] / total);
        float z = 1.f - 2.f * rng.next_float(), phi = 2.f * Pi * rng.next_float();
        float r = std::sqrt(std::max(0.f, 1.f - z * z));
        Ray ray(origin, Vector3f(r * std::cos(phi), r * std::sin(phi), z), 0.f, Infinity);
        SurfaceInteraction si;
        if (!scene->ray_intersect(ray, si)) ++escaped;
    }
    return escaped;
}

} // namespace

// The robust test is watertight: not one ray aimed exactly at a seam or a corner gets through.
TEST(Seams, RobustIntersectionDoesNotLeakAsModelled) {
    LeakCount leaks = count_leaks(true, AS_MODELLED);
    EXPECT_GT(leaks.rays, 10000);
    EXPECT_EQ(leaks.escaped, 0) << "of " << leaks.rays << " rays";
}

TEST(Seams, RobustIntersectionDoesNotLeakRotated) {
    LeakCount leaks = count_leaks(true, ROTATED);
    EXPECT_EQ(leaks.escaped, 0) << "of " << leaks.rays << " rays";
}

// Embree's fast test (the default, as in Mitsuba 3) is not watertight: a ray aimed exactly at a
// shared edge may pass between its two triangles (Mitsuba's own tests show the same). What a
// render sees are rays in random directions, which come that close to an edge with a
// probability of the order of the float rounding: none of a million gets out of a closed mesh.
TEST(Seams, FastIntersectionLetsNoRandomRayOut) {
    EXPECT_EQ(random_ray_leaks(false, AS_MODELLED, 500000), 0);
    EXPECT_EQ(random_ray_leaks(false, ROTATED, 500000), 0);
    EXPECT_EQ(random_ray_leaks(true, ROTATED, 100000), 0);
}

TEST(Seams, FastIntersectionOnlyMissesExactlyAimedRays) {
    // Rays aimed exactly at seams leak through the fast test at a small rate; recorded, and
    // bounded so that a regression (cracks in the geometry itself) shows up.
    for (const char *transform : {AS_MODELLED, ROTATED}) {
        LeakCount leaks = count_leaks(false, transform);
        std::printf("fast intersection: %d of %d rays aimed at seams escaped\n", leaks.escaped,
                    leaks.rays);
        EXPECT_LT(leaks.escaped, leaks.rays / 10);
    }
}

// A shape group's own Embree scene uses the triangle test of the scene that instances it, as
// the scene's own meshes do (it was always the robust one).
TEST(Seams, InstancedGroupsFollowTheSceneOption) {
    for (bool robust : {false, true}) {
        std::string xml = std::string("<scene version=\"3.0.0\"><boolean "
                                      "name=\"embree_use_robust_intersections\" value=\"") +
                          (robust ? "true" : "false") +
                          "\"/><shape type=\"shapegroup\" id=\"group\"><shape type=\"cube\"/>"
                          "</shape><shape type=\"instance\"><ref id=\"group\"/><transform "
                          "name=\"to_world\">" +
                          ROTATED + "</transform></shape></scene>";
        auto scene = std::static_pointer_cast<Scene>(load_string(xml));
        const ShapeGroup *group = nullptr;
        for (const auto &shape : scene->shapes())
            if (auto g = dynamic_cast<const ShapeGroup *>(shape.get())) group = g;
        ASSERT_TRUE(group);
        const RTCSceneFlags flags = rtcGetSceneFlags(group->group_scene(scene->embree_device()));
        EXPECT_EQ((flags & RTC_SCENE_FLAG_ROBUST) != 0, robust) << "robust = " << robust;
        // The instance is there: a ray at the centre of the placed cube hits it.
        const Point3f centre = 0.5f * (scene->bbox().min + scene->bbox().max);
        SurfaceInteraction si;
        EXPECT_TRUE(scene->ray_intersect(
            Ray(centre + Vector3f(0.f, 0.f, 1e3f), Vector3f(0.f, 0.f, -1.f), 0.f, Infinity), si));
    }
}
