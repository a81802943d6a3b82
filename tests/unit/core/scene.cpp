// The scene: collecting children, defaults, Embree queries, spawned rays that neither self-hit nor
// leak, and emitter sampling.
#include "draws.h"

#include <facet/bsdf.h>
#include <facet/emitter.h>
#include <facet/integrator.h>
#include <facet/mis.h>
#include <facet/plugin.h>
#include <facet/random.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/shape.h>
#include <facet/warp.h>

#include <gtest/gtest.h>

#include <algorithm>

using namespace facet;

namespace {

std::shared_ptr<Object> create(ObjectType kind, const std::string &type, Properties props = {}) {
    props.set_plugin_name(type);
    return PluginRegistry::instance().create(kind, props);
}

std::shared_ptr<Object> area_light(const Color3f &radiance) {
    Properties props;
    props.set_color("radiance", radiance);
    return create(ObjectType::Emitter, "area", props);
}

/// Rectangle scaled by 2 in the z = 0 plane and a sphere of radius 0.5 at (0, 0, 2).
Properties rect_and_sphere(std::shared_ptr<Object> sphere_emitter = nullptr) {
    Properties rect;
    rect.set_transform("to_world", Transform::scale(Vector3f(2, 2, 1)));
    Properties sphere;
    sphere.set_vector("center", Vector3f(0, 0, 2));
    sphere.set_float("radius", 0.5);
    if (sphere_emitter) sphere.set_object("light", sphere_emitter);
    Properties props;
    props.set_object("floor", create(ObjectType::Shape, "rectangle", rect));
    props.set_object("ball", create(ObjectType::Shape, "sphere", sphere));
    return props;
}

void expect_near_vec(const Vector3f &a, const Vector3f &b, float tol) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

template <typename F> std::string error_of(F &&f) {
    try {
        f();
    } catch (const Error &e) {
        return e.what();
    }
    ADD_FAILURE() << "expected a facet::Error";
    return "";
}

} // namespace

TEST(SceneBuild, DefaultsAreCreated) {
    Scene scene(rect_and_sphere());
    ASSERT_EQ(scene.shapes().size(), 2u);
    EXPECT_TRUE(scene.integrator());
    ASSERT_EQ(scene.sensors().size(), 1u);
    EXPECT_TRUE(scene.emitters().empty());
    for (const auto &shape : scene.shapes()) {
        ASSERT_TRUE(shape->bsdf());
        EXPECT_TRUE(has_flag(shape->bsdf()->flags(), BSDFFlags::DiffuseReflection));
    }
    expect_near_vec(scene.bbox().min, Vector3f(-2, -2, 0), 1e-6f);
    expect_near_vec(scene.bbox().max, Vector3f(2, 2, 2.5f), 1e-6f);
    EXPECT_NE(scene.to_string().find("Sphere"), std::string::npos);
}

TEST(SceneBuild, EmittingShapesGetABlackDefaultBSDF) {
    // As in Mitsuba: a shape without a BSDF reflects as a diffuse of albedo 0.5, unless it
    // emits; an emitter's default diffuse is black, so a light seen directly shows only its
    // emission.
    Scene scene(rect_and_sphere(area_light(Color3f(4.f))));
    ASSERT_EQ(scene.shapes().size(), 2u);
    SurfaceInteraction si;
    si.wi = normalize(Vector3f(0.3f, 0.f, 1.f));
    Vector3f wo = normalize(Vector3f(-0.2f, 0.4f, 1.f));
    for (const auto &shape : scene.shapes()) {
        ASSERT_TRUE(shape->bsdf());
        Color3f f = shape->bsdf()->eval(BSDFContext(), si, wo);
        if (shape->emitter())
            EXPECT_EQ(f, Color3f(0.f));
        else
            EXPECT_NEAR(f.g, 0.5f * InvPi * wo.z, 1e-6f);
    }
}

TEST(SceneBuild, ChildrenAreCheckedAndOrdered) {
    // Top-level BSDFs are references only; emitters keep declaration order, area emitters
    // coming with their shape.
    Properties props = rect_and_sphere(area_light(Color3f(1.f)));
    props.set_object("unused_bsdf", create(ObjectType::BSDF, "diffuse"));
    Properties point;
    point.set_vector("position", Vector3f(0, 0, 5));
    auto point_light = create(ObjectType::Emitter, "point", point);
    props.set_object("lamp", point_light);
    props.set_object("sky", create(ObjectType::Emitter, "constant"));
    props.set_object("integrator", create(ObjectType::Integrator, "path"));
    Scene scene(props);
    ASSERT_EQ(scene.emitters().size(), 3u);
    EXPECT_EQ(scene.emitters()[0].get(), scene.shapes()[1]->emitter());
    EXPECT_EQ(scene.emitters()[1], point_light);
    ASSERT_EQ(scene.environment_emitters().size(), 1u);
    EXPECT_EQ(scene.environment_emitters()[0], scene.emitters()[2]);
    EXPECT_TRUE(props.unqueried().empty());

    // Two integrators.
    Properties two = rect_and_sphere();
    two.set_object("a", create(ObjectType::Integrator, "path"));
    two.set_object("b", create(ObjectType::Integrator, "path"));
    std::string msg = error_of([&] { Scene s(two); });
    EXPECT_NE(msg.find("integrator"), std::string::npos) << msg;

    // An area emitter that no shape holds.
    Properties loose = rect_and_sphere();
    auto light = area_light(Color3f(1.f));
    light->set_id("lonely_light");
    loose.set_object("l", light);
    msg = error_of([&] { Scene s(loose); });
    EXPECT_NE(msg.find("lonely_light"), std::string::npos) << msg;

    // A shape with two BSDFs.
    Properties twice;
    twice.set_plugin_name("rectangle");
    twice.set_object("a", create(ObjectType::BSDF, "diffuse"));
    twice.set_object("b", create(ObjectType::BSDF, "diffuse"));
    msg = error_of([&] { PluginRegistry::instance().create(ObjectType::Shape, twice); });
    EXPECT_NE(msg.find("more than one bsdf"), std::string::npos) << msg;
}

TEST(SceneQuery, IntersectionRecords) {
    Scene scene(rect_and_sphere());
    SurfaceInteraction si;
    // The floor, from above.
    ASSERT_TRUE(scene.ray_intersect(Ray(Point3f(1, 0.5f, 3), Vector3f(0, 0, -1)), si));
    EXPECT_EQ(si.shape, scene.shapes()[0].get());
    EXPECT_NEAR(si.t, 3.f, 1e-6f);
    expect_near_vec(si.p, Vector3f(1, 0.5f, 0), 1e-6f);
    expect_near_vec(si.n, Vector3f(0, 0, 1), 1e-6f);
    expect_near_vec(si.wi, Vector3f(0, 0, 1), 1e-6f);
    EXPECT_NEAR(si.uv.x, 0.75f, 1e-6f);
    EXPECT_NEAR(si.uv.y, 0.625f, 1e-6f);
    EXPECT_EQ(si.bsdf(), scene.shapes()[0]->bsdf());
    EXPECT_EQ(si.emitter(), nullptr);

    // The sphere's equator, from +x.
    ASSERT_TRUE(scene.ray_intersect(Ray(Point3f(5, 0, 2), Vector3f(-1, 0, 0)), si));
    EXPECT_EQ(si.shape, scene.shapes()[1].get());
    EXPECT_NEAR(si.t, 4.5f, 1e-6f);
    expect_near_vec(si.n, Vector3f(1, 0, 0), 1e-6f);
    EXPECT_NEAR(si.wi.z, 1.f, 1e-6f);
    EXPECT_NEAR(si.uv.x, 0.f, 1e-6f);
    EXPECT_NEAR(si.uv.y, 0.5f, 1e-6f);

    // A miss leaves t at infinity.
    EXPECT_FALSE(scene.ray_intersect(Ray(Point3f(5, 5, 5), Vector3f(0, 0, 1)), si));
    EXPECT_EQ(si.t, Infinity);
    EXPECT_FALSE(si.is_valid());

    // Shadow queries honour [mint, maxt].
    EXPECT_TRUE(scene.ray_test(Ray(Point3f(0, 0, 5), Vector3f(0, 0, -1))));
    EXPECT_FALSE(scene.ray_test(Ray(Point3f(0, 0, 5), Vector3f(0, 0, -1), 0.f, 2.4f)));
    EXPECT_TRUE(scene.ray_test(Ray(Point3f(0, 0, 5), Vector3f(0, 0, -1), 0.f, 2.6f)));
    EXPECT_FALSE(scene.ray_test(Ray(Point3f(0, 0, 5), Vector3f(0, 0, -1), 3.6f, 4.9f)));
    // And so do closest-hit queries: the sphere's top at t = 2.5, its bottom at 3.5, the floor
    // at 5; along every axis (each component of the origin and direction reaches Embree).
    EXPECT_FALSE(scene.ray_intersect(Ray(Point3f(0, 0, 5), Vector3f(0, 0, -1), 0.f, 2.4f), si));
    ASSERT_TRUE(scene.ray_intersect(Ray(Point3f(0, 0, 5), Vector3f(0, 0, -1), 0.f, 2.6f), si));
    EXPECT_NEAR(si.t, 2.5f, 1e-5f);
    ASSERT_TRUE(scene.ray_intersect(Ray(Point3f(0, 0, 5), Vector3f(0, 0, -1), 3.f, 10.f), si));
    EXPECT_NEAR(si.t, 3.5f, 1e-5f);
    ASSERT_TRUE(scene.ray_intersect(Ray(Point3f(0, 0, 5), Vector3f(0, 0, -1), 4.f, 10.f), si));
    EXPECT_NEAR(si.t, 5.f, 1e-5f);
    EXPECT_EQ(si.shape, scene.shapes()[0].get());
    ASSERT_TRUE(scene.ray_intersect(Ray(Point3f(0, -3, 2), Vector3f(0, 1, 0), 0.f, 10.f), si));
    EXPECT_NEAR(si.t, 2.5f, 1e-5f);
    expect_near_vec(si.n, Vector3f(0, -1, 0), 1e-5f);
    ASSERT_TRUE(scene.ray_intersect(Ray(Point3f(-4, 0, 2), Vector3f(1, 0, 0), 0.f, 10.f), si));
    EXPECT_NEAR(si.t, 3.5f, 1e-5f);
    expect_near_vec(si.n, Vector3f(-1, 0, 0), 1e-5f);
}

namespace {

/// Hits a shape from random directions and checks that rays spawned from the hit point leave the
/// surface: no ray going back to the side it came from hits the same shape again, and rays going
/// into a closed shape travel through it rather than stopping at their own start.
void check_spawned_rays(const Transform &to_world, float radius_world, uint64_t seed) {
    Properties rect;
    rect.set_transform("to_world", to_world * Transform::scale(Vector3f(1, 1, 1)));
    Properties sphere;
    sphere.set_transform("to_world", to_world * Transform::translate(Vector3f(0, 0, 3)));
    Properties props;
    props.set_object("rect", create(ObjectType::Shape, "rectangle", rect));
    props.set_object("ball", create(ObjectType::Shape, "sphere", sphere));
    Scene scene(props);
    const Shape *rect_shape = scene.shapes()[0].get(), *ball = scene.shapes()[1].get();
    const Point3f center = to_world.apply_point(Point3f(0, 0, 3));
    const Point3f plane_center = to_world.apply_point(Point3f(0, 0, 0));

    PCG32 rng(seed);
    int self_hits = 0, short_chords = 0, hits = 0;
    for (int i = 0; i < 20000; ++i) {
        bool on_sphere = i % 2 == 1;
        Point3f target = on_sphere ? center : plane_center;
        // Camera rays from far away, aimed at the shape with a random offset.
        Vector3f from = warp::square_to_uniform_sphere(next_point2f(rng));
        if (!on_sphere) from.z = std::abs(from.z) + 0.05f;
        Point3f o = target + normalize(from) * (radius_world * 20.f);
        Vector3f jitter;
        jitter.x = rng.next_float() - 0.5f;
        jitter.y = rng.next_float() - 0.5f;
        jitter.z = on_sphere ? rng.next_float() - 0.5f : 0.f;
        Point3f aim = target + jitter * (1.6f * radius_world);
        SurfaceInteraction si;
        if (!scene.ray_intersect(Ray(o, normalize(aim - o)), si)) continue;
        if (si.shape != (on_sphere ? ball : rect_shape)) continue;
        ++hits;
        // A random direction back into the hemisphere the ray came from (including grazing).
        Vector3f n = si.n * sign(dot(si.n, o - si.p));
        Vector3f local = warp::square_to_uniform_hemisphere(next_point2f(rng));
        Frame frame(n);
        Vector3f d = frame.to_world(local);
        SurfaceInteraction si2;
        if (scene.ray_intersect(si.spawn_ray(d), si2) && si2.shape == si.shape) ++self_hits;
        // Into the sphere: the ray must cross it and leave on the far side.
        if (on_sphere) {
            Vector3f din = frame.to_world(Vector3f(local.x, local.y, -local.z));
            if (scene.ray_intersect(si.spawn_ray(din), si2) && si2.shape == ball) {
                float chord = 2.f * radius_world * std::abs(local.z);
                if (si2.t < 0.5f * chord) ++short_chords;
            } else {
                ++short_chords;
            }
        }
    }
    EXPECT_GT(hits, 10000);
    EXPECT_EQ(self_hits, 0);
    EXPECT_EQ(short_chords, 0);
}

} // namespace

TEST(SpawnRay, NoSelfIntersectionAtUnitScale) { check_spawned_rays(Transform(), 1.f, 1); }

TEST(SpawnRay, NoSelfIntersectionAtLargeCoordinates) {
    // The offset there is (1 + 2e4) · RayEpsilon = 1.8 (Mitsuba's): the shapes are sized above it.
    check_spawned_rays(Transform::translate(Vector3f(1e4f, -2e4f, 1e4f)) *
                           Transform::scale(Vector3f(10, 10, 10)),
                       10.f, 2);
    check_spawned_rays(Transform::translate(Vector3f(1e4f, 1e4f, 3e4f)) *
                           Transform::rotate(Vector3f(1, 2, 3), 37.f) *
                           Transform::scale(Vector3f(50, 50, 50)),
                       50.f, 3);
}

TEST(SpawnRay, NoSelfIntersectionAtSmallScale) {
    check_spawned_rays(Transform::translate(Vector3f(0.3f, 0.2f, -0.1f)) *
                           Transform::scale(Vector3f(1e-2f, 1e-2f, 1e-2f)),
                       1e-2f, 4);
}

TEST(SpawnRay, ShadowRaysReachSurfacePointsAndDoNotLeak) {
    // A floor (z = 0) and a wall (x = 0) crossing it.
    Properties floor;
    floor.set_transform("to_world", Transform::scale(Vector3f(2, 2, 1)));
    Properties wall;
    wall.set_transform("to_world", Transform::rotate(Vector3f(0, 1, 0), 90.f) *
                                       Transform::scale(Vector3f(2, 2, 1)));
    Properties props;
    props.set_object("floor", create(ObjectType::Shape, "rectangle", floor));
    props.set_object("wall", create(ObjectType::Shape, "rectangle", wall));
    Properties sphere;
    sphere.set_vector("center", Vector3f(1, 0, 1));
    sphere.set_float("radius", 0.25);
    props.set_object("ball", create(ObjectType::Shape, "sphere", sphere));
    Scene scene(props);

    PCG32 rng(5);
    const Shape &ball = *scene.shapes()[2];
    for (int i = 0; i < 2000; ++i) {
        // A point on the floor right of the wall, found by tracing down.
        const Point2f q = next_point2f(rng);
        Point3f start(0.05f + 1.9f * q.x, 3.8f * q.y - 1.9f, 1.f);
        SurfaceInteraction ref;
        ASSERT_TRUE(
            scene.ray_intersect(Ray(Point3f(start.x, start.y, 3.f), Vector3f(0, 0, -1)), ref));
        if (ref.shape != scene.shapes()[0].get()) continue; // under the ball
        // Points on the ball: those facing the reference point are visible, the others are not.
        PositionSample ps = ball.sample_position(next_point2f(rng));
        Vector3f to_ref = normalize(ref.p - ps.p);
        float facing = dot(ps.n, to_ref);
        if (std::abs(facing) < 0.05f) continue; // the silhouette, where both answers are right
        bool blocked = scene.ray_test(ref.spawn_ray_to(ps.p));
        EXPECT_EQ(blocked, facing < 0.f) << "floor point " << ref.p << ", ball point " << ps.p;
    }
    // Through the wall: from the floor just left of it to points on its right.
    for (float x : {-1e-3f, -1e-4f}) {
        SurfaceInteraction ref;
        ASSERT_TRUE(scene.ray_intersect(Ray(Point3f(x, 0.3f, 3.f), Vector3f(0, 0, -1)), ref));
        for (Point3f target :
             {Point3f(0.5f, 0.3f, 0.5f), Point3f(1.f, -1.f, 1e-3f), Point3f(0.01f, 0.3f, 1.f)})
            EXPECT_TRUE(scene.ray_test(ref.spawn_ray_to(target))) << x << " -> " << target;
        // The same points are reachable from the right side.
        SurfaceInteraction right;
        ASSERT_TRUE(scene.ray_intersect(Ray(Point3f(-x, 0.3f, 3.f), Vector3f(0, 0, -1)), right));
        EXPECT_FALSE(scene.ray_test(right.spawn_ray_to(Point3f(0.5f, 0.3f, 0.5f))));
    }
}

TEST(SpawnRay, OffsetsAreMitsubas) {
    // Mitsuba 3: origin + n · ±(1 + max |p_i|) · RayEpsilon with RayEpsilon = 1500 · 2^-24, on
    // the side the direction points to; a ray towards a point stops ShadowEpsilon = 10 ·
    // RayEpsilon of its length short.
    EXPECT_EQ(RayEpsilon, 1500.f / 16777216.f);
    EXPECT_EQ(ShadowEpsilon, 10.f * RayEpsilon);
    Interaction it;
    it.p = Point3f(0.5f, -3.f, 2.f);
    it.n = Normal3f(0.f, 0.f, 1.f);
    it.t = 1.f;
    const float offset = 4.f * RayEpsilon;
    Ray up = it.spawn_ray(normalize(Vector3f(1.f, 0.f, 1.f)));
    EXPECT_FLOAT_EQ(up.o.z, 2.f + offset);
    EXPECT_EQ(up.o.x, 0.5f);
    Ray down = it.spawn_ray(normalize(Vector3f(1.f, 0.f, -1.f)));
    EXPECT_FLOAT_EQ(down.o.z, 2.f - offset);
    Ray to = it.spawn_ray_to(Point3f(0.5f, -3.f, 7.f));
    EXPECT_FLOAT_EQ(to.o.z, 2.f + offset);
    EXPECT_FLOAT_EQ(to.maxt, (5.f - offset) * (1.f - ShadowEpsilon));
}

TEST(SpawnRay, SmallGeometryWithinTheOffsetsIsSteppedOver) {
    // What the offsets mean for small geometry, as in Mitsuba: a sheet 4e-5 above a floor is
    // below the origin of rays spawned upwards from the floor, and a bulb of radius 3e-4 around
    // a point 1 away lies within the part of the shadow ray towards that point left out.
    Properties floor;
    floor.set_transform("to_world", Transform::scale(Vector3f(2, 2, 1)));
    Properties sheet;
    sheet.set_transform("to_world", Transform::translate(Vector3f(0.f, 0.f, 4e-5f)) *
                                        Transform::scale(Vector3f(0.5f, 0.5f, 1)));
    Properties bulb;
    bulb.set_vector("center", Vector3f(1.2f, 0.f, 1.f));
    bulb.set_float("radius", 3e-4);
    Properties props;
    props.set_object("floor", create(ObjectType::Shape, "rectangle", floor));
    props.set_object("sheet", create(ObjectType::Shape, "rectangle", sheet));
    props.set_object("bulb", create(ObjectType::Shape, "sphere", bulb));
    Scene scene(props);

    // A floor point under the sheet, reached from below.
    SurfaceInteraction si;
    ASSERT_TRUE(scene.ray_intersect(Ray(Point3f(0.1f, 0.2f, -1.f), Vector3f(0, 0, 1)), si));
    ASSERT_EQ(si.shape, scene.shapes()[0].get());
    SurfaceInteraction hit;
    EXPECT_FALSE(scene.ray_intersect(si.spawn_ray(normalize(Vector3f(0.f, 0.3f, 1.f))), hit))
        << "hit shape " << (hit.shape == scene.shapes()[1].get() ? "sheet" : "other");
    // The bulb's centre is visible from a floor point 1.2 away from it.
    EXPECT_FALSE(scene.ray_test(si.spawn_ray_to(Point3f(1.2f, 0.f, 1.f))));
}

TEST(SceneEmitters, SampleAndPdfAgree) {
    const Color3f radiance(2.f, 3.f, 4.f);
    Properties props = rect_and_sphere(area_light(radiance));
    Properties point;
    point.set_vector("position", Vector3f(1, 1, 4));
    props.set_object("lamp", create(ObjectType::Emitter, "point", point));
    Scene scene(props);
    ASSERT_EQ(scene.emitters().size(), 2u);
    const Emitter *sphere_light = scene.shapes()[1]->emitter();

    SurfaceInteraction ref;
    ASSERT_TRUE(scene.ray_intersect(Ray(Point3f(0.7f, -0.4f, 3.f), Vector3f(0, 0, -1)), ref));
    PCG32 rng(8);
    int area_samples = 0, point_samples = 0;
    const float sphere_pmf = scene.emitter_pmf(ref, *sphere_light);
    for (int i = 0; i < 1000; ++i) {
        Point2f u = next_point2f(rng);
        auto [ds, weight] = scene.sample_emitter_direction(ref, u, true, LightSampling::Alone);
        float picked_u = u.x;
        if (scene.sample_emitter(ref, picked_u).first == sphere_light) {
            ASSERT_EQ(ds.emitter, sphere_light);
            ASSERT_GT(ds.pdf, 0.f);
            ++area_samples;
            EXPECT_NEAR(scene.pdf_emitter_direction(ref, ds, LightSampling::Alone), ds.pdf,
                        1e-5f * ds.pdf);
            // The point on the ball seen from the floor is visible: the weight is L / pdf.
            EXPECT_NEAR(weight.r * ds.pdf, radiance.r, 1e-4f);
            EXPECT_NEAR(weight.b * ds.pdf, radiance.b, 1e-4f);
            // Part of the pdf is the probability of picking this emitter.
            EXPECT_NEAR(ds.pdf, sphere_pmf * sphere_light->pdf_direction(ref, ds), 1e-5f * ds.pdf);
        } else {
            ASSERT_NE(ds.emitter, sphere_light);
            EXPECT_TRUE(ds.delta);
            ++point_samples;
            EXPECT_EQ(scene.pdf_emitter_direction(ref, ds, LightSampling::Alone), 0.f);
            // The ball sits between the floor point and the lamp only for some points.
            Ray shadow = ref.spawn_ray_to(ds.p);
            EXPECT_EQ(weight.is_black(), scene.ray_test(shadow));
        }
    }
    // Both kinds are checked often (the light hierarchy gives the near ball most samples).
    EXPECT_GT(area_samples, 50);
    EXPECT_GT(point_samples, 50);

    // Occluded: from (-1, -1, 0) the line to the lamp passes through the centre of the ball.
    SurfaceInteraction under;
    ASSERT_TRUE(scene.ray_intersect(Ray(Point3f(-1.f, -1.f, 1.f), Vector3f(0, 0, -1)), under));
    auto [ds, weight] =
        scene.sample_emitter_direction(under, Point2f(0.999f, 0.5f), true, LightSampling::Alone);
    ASSERT_NE(ds.emitter, sphere_light);
    EXPECT_TRUE(weight.is_black());
    auto [ds2, weight2] =
        scene.sample_emitter_direction(under, Point2f(0.999f, 0.5f), false, LightSampling::Alone);
    EXPECT_FALSE(weight2.is_black());
}

TEST(SceneEmitters, EmitterVisibleIsTheSamplesOwnShadowTest) {
    // The path tracer samples emitters without the visibility test and asks emitter_visible()
    // once the BSDF has weighted the sample: that must be exactly the test that
    // sample_emitter_direction(..., true, LightSampling::Alone) applies. Floor points around and
    // under the ball, lit by the ball itself, a point lamp and a slanted directional light (a
    // sample at infinity).
    Properties props = rect_and_sphere(area_light(Color3f(1.f)));
    Properties point;
    point.set_vector("position", Vector3f(0.3f, -0.2f, 4.f));
    props.set_object("lamp", create(ObjectType::Emitter, "point", point));
    Properties sun;
    sun.set_vector("direction", Vector3f(0.2f, 0.1f, -1.f));
    props.set_object("sun", create(ObjectType::Emitter, "directional", sun));
    Scene scene(props);
    ASSERT_EQ(scene.emitters().size(), 3u);
    PCG32 rng(5);
    int blocked[3] = {0, 0, 0}, clear[3] = {0, 0, 0};
    for (int i = 0; i < 3000; ++i) {
        const Point3f o(1.6f * rng.next_float() - 0.8f, 1.6f * rng.next_float() - 0.8f, 1.f);
        SurfaceInteraction ref;
        ASSERT_TRUE(scene.ray_intersect(Ray(o, Vector3f(0, 0, -1)), ref));
        const Point2f u = next_point2f(rng);
        auto [ds, weight] = scene.sample_emitter_direction(ref, u, false, LightSampling::Alone);
        auto [tested, tested_weight] =
            scene.sample_emitter_direction(ref, u, true, LightSampling::Alone);
        if (weight.is_black()) {
            EXPECT_TRUE(tested_weight.is_black());
            continue;
        }
        const bool visible = scene.emitter_visible(ref, ds);
        EXPECT_EQ(tested_weight.is_black(), !visible) << o.x << ", " << o.y << "; " << u.x;
        int kind = 0; // the ball
        if (ds.emitter != scene.shapes()[1]->emitter()) kind = std::isfinite(ds.dist) ? 1 : 2;
        (visible ? clear : blocked)[kind]++;
    }
    // The ball is only ever hidden by itself (how often depends on how it samples its surface);
    // the lamp and the sun are hidden by the ball from the points in its shadow.
    for (int kind = 0; kind < 3; ++kind) EXPECT_GT(clear[kind], 50) << kind;
    EXPECT_GT(blocked[1], 10);
    EXPECT_GT(blocked[2], 10);
}

TEST(SceneEmitters, TriangleLightsMatchTheirEmitter) {
    // A constant area light on a mesh (a tilted rectangle of two triangles) is sampled by the
    // scene's own non-virtual path: the same points, pdfs and weights as the emitter's virtual
    // methods (up to float rounding), and pdf_emitter_direction() gives exactly the pdf that
    // the sample reported. A textured area light on a cube keeps the virtual path.
    const Color3f radiance(5.f, 2.f, 1.f);
    Properties rect;
    rect.set_transform("to_world", Transform::translate(Vector3f(0.3f, 0.2f, 3.f)) *
                                       Transform::rotate(Vector3f(1, 0.4f, 0), 160.f) *
                                       Transform::scale(Vector3f(0.7f, 1.3f, 1.f)));
    rect.set_object("light", area_light(radiance));
    Properties props = rect_and_sphere();
    props.set_object("panel", create(ObjectType::Shape, "rectangle", rect));
    Properties checker;
    checker.set_color("color0", Color3f(1.f, 2.f, 3.f));
    Properties textured;
    textured.set_object("radiance", create(ObjectType::Texture, "checkerboard", checker));
    Properties cube;
    cube.set_transform("to_world", Transform::translate(Vector3f(-3.f, 0.f, 1.f)) *
                                       Transform::scale(Vector3f(0.4f)));
    cube.set_object("light", create(ObjectType::Emitter, "area", textured));
    props.set_object("cube", create(ObjectType::Shape, "cube", cube));
    Scene scene(props);
    ASSERT_EQ(scene.emitters().size(), 2u);

    SurfaceInteraction ref;
    ASSERT_TRUE(scene.ray_intersect(Ray(Point3f(-0.6f, 0.9f, 1.f), Vector3f(0, 0, -1)), ref));
    ASSERT_EQ(ref.shape, scene.shapes()[0].get()); // the floor
    PCG32 rng(21);
    int panel = 0, box = 0;
    for (int i = 0; i < 2000; ++i) {
        Point2f u = next_point2f(rng);
        auto [ds, weight] = scene.sample_emitter_direction(ref, u, false, LightSampling::Alone);
        if (!(ds.pdf > 0.f)) continue;
        ASSERT_TRUE(ds.emitter);
        EXPECT_EQ(scene.pdf_emitter_direction(ref, ds, LightSampling::Alone), ds.pdf);
        // The emitter's own answer for the same sample (stretched back as the scene does).
        Point2f v = u;
        const auto [picked, pmf] = scene.sample_emitter(ref, v.x);
        ASSERT_EQ(picked, ds.emitter);
        auto [own, own_weight] = ds.emitter->sample_direction(ref, v);
        expect_near_vec(Vector3f(ds.p), Vector3f(own.p), 1e-5f);
        EXPECT_NEAR(ds.pdf, pmf * own.pdf, 1e-5f * ds.pdf);
        EXPECT_NEAR(ds.pdf, pmf * ds.emitter->pdf_direction(ref, ds), 1e-5f * ds.pdf);
        EXPECT_NEAR(weight.r, own_weight.r / pmf, 1e-4f * weight.r);
        EXPECT_NEAR(weight.g, own_weight.g / pmf, 1e-4f * weight.g);
        (ds.emitter->shape() == scene.shapes()[2].get() ? panel : box)++;
    }
    EXPECT_GT(panel, 100);
    EXPECT_GT(box, 100);
}

TEST(SceneEmitters, ShapeLightsMatchTheirEmitter) {
    // A constant area light on a sphere and one on a disk (not meshes) are sampled by the scene
    // through their shapes' own sample_direction(), without the emitter's call: the same
    // points, pdfs and weights as the emitter's virtual methods to the last bit, nothing from
    // behind the disk, and pdf_emitter_direction() gives exactly the pdf the sample reported.
    Properties props = rect_and_sphere(area_light(Color3f(3.f, 2.f, 1.f)));
    Properties disk;
    disk.set_transform("to_world", Transform::translate(Vector3f(1.2f, -0.4f, 1.1f)) *
                                       Transform::rotate(Vector3f(1, 0.3f, 0), 170.f) *
                                       Transform::scale(Vector3f(0.6f)));
    disk.set_object("light", area_light(Color3f(1.f, 4.f, 2.f)));
    props.set_object("lamp", create(ObjectType::Shape, "disk", disk));
    Scene scene(props);
    ASSERT_EQ(scene.emitters().size(), 2u);

    PCG32 rng(33);
    int ball = 0, lamp = 0, behind = 0;
    for (const Point3f &o : {Point3f(-0.6f, 0.9f, 0.f), Point3f(1.5f, -0.2f, 2.2f)}) {
        Interaction ref;
        ref.p = o;
        ref.n = Normal3f(0.f, 0.f, 1.f);
        for (int i = 0; i < 2000; ++i) {
            const Point2f u = next_point2f(rng);
            auto [ds, weight] = scene.sample_emitter_direction(ref, u, false, LightSampling::Alone);
            Point2f v = u;
            const auto [picked, pmf] = scene.sample_emitter(ref, v.x);
            ASSERT_TRUE(picked);
            auto [own, own_weight] = picked->sample_direction(ref, v);
            if (!(own.pdf > 0.f) || own_weight.is_black()) {
                // The emitter sends nothing this way (the disk's back): nor does the scene.
                EXPECT_TRUE(weight.is_black());
                ++behind;
                continue;
            }
            ASSERT_EQ(ds.emitter, picked);
            EXPECT_EQ(ds.p, own.p);
            EXPECT_EQ(ds.d, own.d);
            EXPECT_EQ(ds.pdf, own.pdf * pmf);
            EXPECT_EQ(weight, own_weight / pmf);
            EXPECT_EQ(scene.pdf_emitter_direction(ref, ds, LightSampling::Alone), ds.pdf);
            EXPECT_EQ(scene.pdf_emitter_direction(ref, ds, LightSampling::Alone),
                      picked->pdf_direction(ref, ds) * pmf);
            (picked->shape() == scene.shapes()[1].get() ? ball : lamp)++;
        }
    }
    EXPECT_GT(ball, 500);
    EXPECT_GT(lamp, 500);
    EXPECT_GT(behind, 100);
}

TEST(SceneEmitters, EnvironmentIsSeenThroughTheMissRecord) {
    Properties props = rect_and_sphere();
    Properties sky;
    sky.set_color("radiance", Color3f(0.5f, 0.25f, 0.125f));
    props.set_object("sky", create(ObjectType::Emitter, "constant", sky));
    Scene scene(props);
    ASSERT_EQ(scene.environment_emitters().size(), 1u);

    // The miss fills the record of the escaped ray: wi local (identity frame), pointing back.
    const Vector3f d = normalize(Vector3f(0.3f, -0.2f, 0.9f));
    const Ray ray(Point3f(0, 0, 5), d);
    SurfaceInteraction escaped;
    escaped.shape = scene.shapes().front().get(); // stale fields of an earlier hit are reset
    escaped.t = 1.f;
    ASSERT_FALSE(scene.ray_intersect(ray, escaped));
    EXPECT_FALSE(escaped.is_valid());
    EXPECT_EQ(escaped.shape, nullptr);
    Vector3f back = escaped.to_world(escaped.wi);
    EXPECT_NEAR(back.x, -d.x, 1e-6f);
    EXPECT_NEAR(back.y, -d.y, 1e-6f);
    EXPECT_NEAR(back.z, -d.z, 1e-6f);

    // Unweighted (camera ray or delta bounce): the sky radiance.
    Color3f env = environment_mis(scene, escaped, escaped, 0.f, true);
    EXPECT_NEAR(env.r, 0.5f, 1e-6f);
    EXPECT_NEAR(env.g, 0.25f, 1e-6f);
    EXPECT_NEAR(env.b, 0.125f, 1e-6f);
    // After a BSDF sample: weighted against emitter sampling (the sky is the only emitter, its
    // directions have density 1/4π); equal densities weigh 1/2.
    Interaction ref;
    ref.p = ray.o;
    float em_pdf = InvFourPi / float(scene.emitters().size());
    Color3f half = environment_mis(scene, escaped, ref, em_pdf, false);
    EXPECT_NEAR(half.r, 0.25f, 1e-6f);
    Color3f third = environment_mis(scene, escaped, ref, em_pdf, false, 0.5f);
    EXPECT_NEAR(third.r, 0.5f * 0.8f, 1e-6f); // (1)² / ((1)² + (1/2)²) = 0.8

    Scene empty_env(rect_and_sphere());
    ASSERT_FALSE(empty_env.ray_intersect(ray, escaped));
    EXPECT_TRUE(environment_mis(empty_env, escaped, escaped, 0.f, true).is_black());
}

TEST(SceneQuery, InstancesDispatchToTheGroupMembers) {
    Properties ball;
    ball.set_float("radius", 0.5);
    Properties group("shapegroup");
    group.set_object("ball", create(ObjectType::Shape, "sphere", ball));
    auto group_obj = PluginRegistry::instance().create(ObjectType::Shape, group);
    Properties props;
    for (float x : {-2.f, 2.f}) {
        Properties inst;
        inst.set_object("group", group_obj);
        inst.set_transform("to_world", Transform::translate(Vector3f(x, 0, 0)));
        props.set_object(fmt::format("inst{}", x), create(ObjectType::Shape, "instance", inst));
    }
    props.set_object("group", group_obj);
    Scene scene(props);
    SurfaceInteraction si;
    ASSERT_TRUE(scene.ray_intersect(Ray(Point3f(2, 0, 5), Vector3f(0, 0, -1)), si));
    EXPECT_NEAR(si.t, 4.5f, 1e-5f);
    expect_near_vec(si.p, Vector3f(2, 0, 0.5f), 1e-5f);
    expect_near_vec(si.n, Vector3f(0, 0, 1), 1e-5f);
    ASSERT_NE(si.shape, nullptr);
    EXPECT_NE(si.bsdf(), nullptr); // members of groups get the default BSDF too
    EXPECT_FALSE(scene.ray_intersect(Ray(Point3f(0, 0, 5), Vector3f(0, 0, -1)), si));
    EXPECT_TRUE(scene.ray_test(Ray(Point3f(-2, 0, 5), Vector3f(0, 0, -1))));
    // The group itself is not visible and does not extend the bounds twice.
    expect_near_vec(scene.bbox().min, Vector3f(-2.5f, -0.5f, -0.5f), 1e-5f);
    expect_near_vec(scene.bbox().max, Vector3f(2.5f, 0.5f, 0.5f), 1e-5f);
}

namespace {
/// Every field of si that a hit fills in, compared exactly.
void expect_same_record(const SurfaceInteraction &a, const SurfaceInteraction &b) {
    EXPECT_EQ(a.t, b.t);
    EXPECT_EQ(a.shape, b.shape);
    EXPECT_EQ(a.prim_index, b.prim_index);
    EXPECT_EQ(a.instance_index, b.instance_index);
    for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(a.p[k], b.p[k]);
        EXPECT_EQ(a.n[k], b.n[k]);
        EXPECT_EQ(a.sh_frame.n[k], b.sh_frame.n[k]);
        EXPECT_EQ(a.wi[k], b.wi[k]);
    }
    EXPECT_EQ(a.uv.x, b.uv.x);
    EXPECT_EQ(a.uv.y, b.uv.y);
}

/// Rays from `eye` towards a jittered grid of points of the square [-3, 3]² at z = 0, with
/// some ranges [mint, maxt] cut short and a few directions that are not finite.
std::vector<Ray> packet_test_rays(const Point3f &eye, uint64_t seed) {
    PCG32 rng(seed);
    std::vector<Ray> rays;
    for (int j = 0; j < 12; ++j)
        for (int i = 0; i < 12; ++i) {
            const Point3f target(-3.f + 0.5f * (float(i) + rng.next_float()),
                                 -3.f + 0.5f * (float(j) + rng.next_float()), 0.f);
            Ray ray(eye, normalize(target - eye));
            const float r = rng.next_float();
            // Ranges that end before the ball or the floor, or start past them (the eyes are 6
            // to 8 away from the floor).
            if (r < 0.25f) ray.maxt = 2.f + 7.f * rng.next_float();
            if (r > 0.75f) ray.mint = 2.f + 7.f * rng.next_float();
            if ((i * 7 + j) % 29 == 0) ray.d = Vector3f(NAN, 0.f, -1.f);
            rays.push_back(ray);
        }
    return rays;
}

/// Each ray of `rays` in packets of every size from 1 to 8: the same answers as its own query.
void expect_packets_match_single_queries(const Scene &scene, const std::vector<Ray> &rays) {
    size_t hits_seen = 0, misses_seen = 0;
    for (int count = 1; count <= Scene::PacketSize; ++count)
        for (size_t first = 0; first + size_t(count) <= rays.size(); first += size_t(count)) {
            SurfaceInteraction sis[Scene::PacketSize];
            bool hits[Scene::PacketSize];
            scene.ray_intersect_packet(rays.data() + first, count, sis, hits);
            for (int k = 0; k < count; ++k) {
                SCOPED_TRACE(fmt::format("packet of {}, ray {}", count, first + size_t(k)));
                SurfaceInteraction si;
                const bool hit = scene.ray_intersect(rays[first + size_t(k)], si);
                ASSERT_EQ(hits[k], hit);
                (hit ? hits_seen : misses_seen) += 1;
                if (hit) {
                    expect_same_record(sis[k], si);
                } else {
                    EXPECT_EQ(sis[k].t, Infinity);
                    EXPECT_EQ(sis[k].shape, nullptr);
                    // wi = -d in the escaped record: NaN for a direction that is not finite.
                    for (int c = 0; c < 3; ++c)
                        EXPECT_TRUE(sis[k].wi[c] == si.wi[c] ||
                                    (std::isnan(sis[k].wi[c]) && std::isnan(si.wi[c])));
                }
            }
        }
    EXPECT_GT(hits_seen, 100u);
    EXPECT_GT(misses_seen, 20u);
}
} // namespace

TEST(SceneQuery, PacketsGiveTheAnswersOfSingleQueries) {
    // A mesh and a sphere (Embree's triangles and a shape of facet's own, asked through
    // callbacks for up to eight rays at once), seen from above and from an angle.
    Scene scene(rect_and_sphere());
    expect_packets_match_single_queries(scene, packet_test_rays(Point3f(0.3f, -0.2f, 6.f), 1));
    expect_packets_match_single_queries(scene, packet_test_rays(Point3f(-5.f, 4.f, 3.f), 2));
    // Instances of a group: hits inside the group dispatch to its members.
    Properties ball;
    ball.set_float("radius", 0.7);
    Properties group("shapegroup");
    group.set_object("ball", create(ObjectType::Shape, "sphere", ball));
    group.set_object("tile", create(ObjectType::Shape, "rectangle"));
    auto group_obj = PluginRegistry::instance().create(ObjectType::Shape, group);
    Properties props;
    for (float x : {-1.5f, 1.5f}) {
        Properties inst;
        inst.set_object("group", group_obj);
        inst.set_transform("to_world", Transform::translate(Vector3f(x, 0.5f * x, 0)));
        props.set_object(fmt::format("inst{}", x), create(ObjectType::Shape, "instance", inst));
    }
    props.set_object("group", group_obj);
    Scene instanced(props);
    expect_packets_match_single_queries(instanced, packet_test_rays(Point3f(0.3f, -0.2f, 6.f), 3));
}
