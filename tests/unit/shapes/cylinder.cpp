// The cylinder shape: area, bounds, hits from outside and inside (exact distance, uv, normal,
// dp/du, dp/dv), the open ends, flip_normals, to_world (rigid, scaled along the axis, and
// scaled unevenly across it as Mitsuba allows), position sampling, and the chi-square test of
// an area light on it.
#include "draws.h"

#include <facet/chi2.h>
#include <facet/interaction.h>
#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/random.h>
#include <facet/scene.h>
#include <facet/shape.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace facet;

namespace {

std::shared_ptr<Shape> make_cylinder(Properties props = Properties()) {
    props.set_plugin_name("cylinder");
    return PluginRegistry::instance().create_as<Shape>(ObjectType::Shape, props);
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

/// The shape alone in an Embree scene.
class SingleShape {
public:
    explicit SingleShape(std::shared_ptr<Shape> shape) : m_shape(std::move(shape)) {
        RTCDevice device = embree_device();
        m_scene = rtcNewScene(device);
        rtcSetSceneFlags(m_scene, RTC_SCENE_FLAG_ROBUST);
        RTCGeometry geom = m_shape->embree_geometry(device);
        rtcAttachGeometry(m_scene, geom);
        rtcReleaseGeometry(geom);
        rtcCommitScene(m_scene);
    }
    ~SingleShape() { rtcReleaseScene(m_scene); }
    SingleShape(const SingleShape &) = delete;
    SingleShape &operator=(const SingleShape &) = delete;

    bool intersect(const Ray &ray, SurfaceInteraction &si) const {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        RTCRayHit rh{};
        rh.ray.org_x = ray.o.x;
        rh.ray.org_y = ray.o.y;
        rh.ray.org_z = ray.o.z;
        rh.ray.dir_x = ray.d.x;
        rh.ray.dir_y = ray.d.y;
        rh.ray.dir_z = ray.d.z;
        rh.ray.tnear = ray.mint;
        rh.ray.tfar = ray.maxt;
        rh.ray.mask = 0xFFFFFFFFu;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(m_scene, &ctx, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
        m_shape->compute_surface_interaction(ray, rh.ray.tfar, rh.hit.primID,
                                             Point2f(rh.hit.u, rh.hit.v), si);
        return true;
    }

private:
    std::shared_ptr<Shape> m_shape;
    RTCScene m_scene;
};

void expect_near_vec(const Vector3f &a, const Vector3f &b, float tol) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

Properties axis_props(const Point3f &p0, const Point3f &p1, double radius) {
    Properties props;
    props.set_vector("p0", p0);
    props.set_vector("p1", p1);
    props.set_float("radius", radius);
    return props;
}

} // namespace

TEST(Cylinder, DefaultsAreaAndBounds) {
    auto cyl = make_cylinder();
    EXPECT_NEAR(cyl->surface_area(), 2.0 * M_PI, 1e-5); // radius 1, axis (0,0,0)-(0,0,1)
    BoundingBox3f b = cyl->bbox();
    expect_near_vec(b.min, Vector3f(-1.f, -1.f, 0.f), 1e-5f);
    expect_near_vec(b.max, Vector3f(1.f, 1.f, 1.f), 1e-5f);

    auto tube = make_cylinder(axis_props({1, 2, 3}, {1, 5, 3}, 0.25));
    EXPECT_NEAR(tube->surface_area(), 2.0 * M_PI * 0.25 * 3.0, 1e-5);
    b = tube->bbox();
    expect_near_vec(b.min, Vector3f(0.75f, 2.f, 2.75f), 1e-5f);
    expect_near_vec(b.max, Vector3f(1.25f, 5.f, 3.25f), 1e-5f);
}

TEST(Cylinder, HitFromOutsideHasExactDistanceUvAndFrame) {
    // Axis along +y from (0, -1, 0) to (0, 1, 0), radius 0.5.
    auto cyl = make_cylinder(axis_props({0, -1, 0}, {0, 1, 0}, 0.5));
    SingleShape scene(cyl);
    SurfaceInteraction si;
    ASSERT_TRUE(scene.intersect(Ray(Point3f(3.f, 0.5f, 0.f), Vector3f(-1, 0, 0)), si));
    EXPECT_NEAR(si.t, 2.5f, 1e-6f);
    expect_near_vec(si.p, Vector3f(0.5f, 0.5f, 0.f), 1e-6f);
    expect_near_vec(si.n, Vector3f(1, 0, 0), 1e-6f);
    EXPECT_GT(si.wi.z, 0.999f);
    EXPECT_NEAR(si.uv.y, 0.75f, 1e-6f); // three quarters of the way from p0 to p1
    // dp/dv is the axis p1 - p0; dp/du goes around it with length 2π·radius.
    expect_near_vec(si.dp_dv, Vector3f(0, 2, 0), 1e-5f);
    EXPECT_NEAR(norm(si.dp_du), 2.f * Pi * 0.5f, 1e-5f);
    EXPECT_NEAR(dot(si.dp_du, si.n), 0.f, 1e-5f);
    EXPECT_NEAR(dot(si.dp_du, si.dp_dv), 0.f, 1e-5f);
    // n = dp/du × dp/dv (normalised) for the outward normal.
    expect_near_vec(normalize(cross(si.dp_du, si.dp_dv)), si.n, 1e-5f);
    expect_near_vec(si.sh_frame.n, si.n, 1e-6f);
    EXPECT_NEAR(dot(si.sh_frame.s, normalize(si.dp_du)), 1.f, 1e-5f);

    // A grazing ray between the tube's end circles misses; mint/maxt are honoured.
    EXPECT_FALSE(scene.intersect(Ray(Point3f(3.f, 1.01f, 0.f), Vector3f(-1, 0, 0)), si));
    EXPECT_FALSE(scene.intersect(Ray(Point3f(3.f, 0.5f, 0.f), Vector3f(-1, 0, 0), 0.f, 2.4f), si));
    ASSERT_TRUE(scene.intersect(Ray(Point3f(3.f, 0.5f, 0.f), Vector3f(-1, 0, 0), 2.6f), si));
    EXPECT_NEAR(si.t, 3.5f, 1e-6f); // the far wall, seen from inside
    expect_near_vec(si.n, Vector3f(-1, 0, 0), 1e-6f);
    EXPECT_LT(si.wi.z, -0.999f);
}

TEST(Cylinder, UvGoesAroundTheAxis) {
    auto cyl = make_cylinder(); // axis +z: Mitsuba's frame around +z is the identity
    SingleShape scene(cyl);
    SurfaceInteraction si;
    for (int k = 0; k < 8; ++k) {
        const float phi = (float(k) + 0.25f) * Pi / 4.f;
        const Vector3f out(std::cos(phi), std::sin(phi), 0.f);
        ASSERT_TRUE(scene.intersect(Ray(Point3f(0, 0, 0.3f) + out * 3.f, -out), si)) << k;
        EXPECT_NEAR(si.uv.x, phi / (2.f * Pi), 1e-5f) << k;
        EXPECT_NEAR(si.uv.y, 0.3f, 1e-5f);
        expect_near_vec(si.n, out, 1e-5f);
        // dp/du = 2π·(-sin φ, cos φ, 0): u grows counter-clockwise around +z.
        expect_near_vec(si.dp_du, Vector3f(-out.y, out.x, 0.f) * (2.f * Pi), 1e-4f);
    }
}

TEST(Cylinder, OpenEndsAndHitsFromInside) {
    auto cyl = make_cylinder(axis_props({0, 0, 0}, {0, 0, 2}, 1.0));
    SingleShape scene(cyl);
    SurfaceInteraction si;
    // Along the axis through both open ends: nothing to hit.
    EXPECT_FALSE(scene.intersect(Ray(Point3f(0.2f, 0.1f, -5.f), Vector3f(0, 0, 1)), si));
    // From above the top opening at a slant: the ray enters the open end and meets the far wall
    // from inside.
    const Vector3f d = normalize(Vector3f(1.f, 0.f, -1.f));
    ASSERT_TRUE(scene.intersect(Ray(Point3f(-0.5f, 0.f, 3.f), d), si));
    // The ray meets x = 1 at z = 3 - 1.5 = 1.5, inside the tube's extent.
    EXPECT_NEAR(si.p.x, 1.f, 1e-5f);
    EXPECT_NEAR(si.p.z, 1.5f, 1e-5f);
    EXPECT_NEAR(si.t, 1.5f * std::sqrt(2.f), 1e-5f);
    expect_near_vec(si.n, Vector3f(1, 0, 0), 1e-5f);
    EXPECT_LT(si.wi.z, 0.f); // the inside is the back side
    // From a point inside, every direction off the axis hits the wall at distance 1 (radially).
    for (float a : {0.3f, 1.7f, 4.f}) {
        const Vector3f r(std::cos(a), std::sin(a), 0.f);
        ASSERT_TRUE(scene.intersect(Ray(Point3f(0.f, 0.f, 1.f), r), si));
        EXPECT_NEAR(si.t, 1.f, 1e-6f);
        EXPECT_NEAR(dot(si.n, r), 1.f, 1e-5f);
    }
}

TEST(Cylinder, FlipNormalsMakesTheInsideTheFront) {
    Properties props = axis_props({0, 0, 0}, {0, 0, 2}, 1.0);
    props.set_bool("flip_normals", true);
    auto cyl = make_cylinder(props);
    SingleShape scene(cyl);
    SurfaceInteraction si;
    ASSERT_TRUE(scene.intersect(Ray(Point3f(0.f, 0.f, 1.f), Vector3f(1, 0, 0)), si));
    expect_near_vec(si.n, Vector3f(-1, 0, 0), 1e-6f);
    EXPECT_GT(si.wi.z, 0.999f);
    ASSERT_TRUE(scene.intersect(Ray(Point3f(4.f, 0.f, 1.f), Vector3f(-1, 0, 0)), si));
    EXPECT_LT(si.wi.z, -0.999f); // seen from outside: the back
    // Sampled normals are flipped as well.
    PositionSample ps = cyl->sample_position(Point2f(0.3f, 0.6f));
    const Vector3f radial = normalize(Vector3f(ps.p.x, ps.p.y, 0.f));
    EXPECT_NEAR(dot(ps.n, radial), -1.f, 1e-5f);
}

TEST(Cylinder, ToWorldRigidAndAlongTheAxis) {
    // Default axis, scaled 3x along z, 0.5 across, rotated so that z becomes x, then moved.
    Properties props;
    Transform tw = Transform::translate(Vector3f(1, 2, 3)) *
                   Transform::rotate(Vector3f(0, 1, 0), 90.f) *
                   Transform::scale(Vector3f(0.5f, 0.5f, 3.f));
    props.set_transform("to_world", tw);
    size_t warnings = Logger::warning_count();
    auto cyl = make_cylinder(props);
    EXPECT_EQ(Logger::warning_count(), warnings); // a scale along the axis is fine
    EXPECT_NEAR(cyl->surface_area(), 2.0 * M_PI * 0.5 * 3.0, 1e-4);
    SingleShape scene(cyl);
    SurfaceInteraction si;
    // The axis runs from (1, 2, 3) to (4, 2, 3); hit the wall from above at x = 2.5.
    ASSERT_TRUE(scene.intersect(Ray(Point3f(2.5f, 5.f, 3.f), Vector3f(0, -1, 0)), si));
    EXPECT_NEAR(si.t, 2.5f, 1e-5f);
    expect_near_vec(si.n, Vector3f(0, 1, 0), 1e-5f);
    EXPECT_NEAR(si.uv.y, 0.5f, 1e-5f);
    expect_near_vec(si.dp_dv, Vector3f(3, 0, 0), 1e-4f);
}

TEST(Cylinder, NonUniformScaleAcrossTheAxisWarnsAndIntersectsTheEllipse) {
    // As in Mitsuba: a warning, the exactly transformed (elliptic) tube is intersected, and the
    // area uses the radius along the first cross-section axis.
    Properties props;
    props.set_transform("to_world", Transform::scale(Vector3f(2.f, 1.f, 1.f)));
    size_t warnings = Logger::warning_count();
    auto cyl = make_cylinder(props);
    EXPECT_EQ(Logger::warning_count(), warnings + 1);
    EXPECT_NEAR(cyl->surface_area(), 2.0 * M_PI * 2.0, 1e-4);
    SingleShape scene(cyl);
    SurfaceInteraction si;
    ASSERT_TRUE(scene.intersect(Ray(Point3f(5.f, 0.f, 0.5f), Vector3f(-1, 0, 0)), si));
    EXPECT_NEAR(si.t, 3.f, 1e-5f); // semi-axis 2 along x
    ASSERT_TRUE(scene.intersect(Ray(Point3f(0.f, 5.f, 0.5f), Vector3f(0, -1, 0)), si));
    EXPECT_NEAR(si.t, 4.f, 1e-5f); // semi-axis 1 along y
    // The normal of the ellipse x²/4 + y² = 1 at 45° in parameter space.
    const float c = std::sqrt(0.5f);
    const Point3f target(2.f * c, c, 0.5f);
    const Vector3f d = normalize(target - Point3f(3.f, 3.f, 0.5f));
    ASSERT_TRUE(scene.intersect(Ray(Point3f(3.f, 3.f, 0.5f), d), si));
    expect_near_vec(si.p, target, 1e-4f);
    expect_near_vec(si.n, normalize(Vector3f(c / 2.f, c, 0.f)), 1e-4f);

    Properties bad = axis_props({1, 1, 1}, {1, 1, 1}, 1.0);
    EXPECT_NE(error_of([&] { make_cylinder(bad); }).find("p0 and p1"), std::string::npos);
    Properties neg;
    neg.set_float("radius", -1.0);
    EXPECT_NE(error_of([&] { make_cylinder(neg); }).find("radius"), std::string::npos);
}

TEST(Cylinder, PositionSamplesLieOnTheSurfaceWithUniformPdf) {
    auto cyl = make_cylinder(axis_props({0, 0, 0}, {1, 1, 0}, 0.3));
    const Vector3f axis = normalize(Vector3f(1, 1, 0));
    PCG32 rng(7);
    double mean_along = 0.0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
        PositionSample ps = cyl->sample_position(next_point2f(rng));
        const float along = dot(ps.p, axis);
        const Vector3f radial = ps.p - axis * along;
        EXPECT_NEAR(norm(radial), 0.3f, 1e-5f);
        EXPECT_NEAR(dot(ps.n, normalize(radial)), 1.f, 1e-4f);
        EXPECT_NEAR(ps.pdf * cyl->surface_area(), 1.f, 1e-5f);
        EXPECT_NEAR(ps.uv.y * std::sqrt(2.f), along, 1e-4f);
        mean_along += along;
    }
    EXPECT_NEAR(mean_along / n, std::sqrt(2.0) / 2.0, 0.01); // uniform along the axis
}
