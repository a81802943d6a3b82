// Perspective camera: field of view rules, camera frame conventions, clipping planes.
#include <facet/plugin.h>
#include <facet/sensor.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace facet;

namespace {

constexpr double RadToDeg = 180.0 / 3.14159265358979323846;

std::shared_ptr<Film> film_of(int w, int h) {
    Properties p("hdrfilm");
    p.set_int("width", w);
    p.set_int("height", h);
    return PluginRegistry::instance().create_as<Film>(ObjectType::Film, p);
}

std::shared_ptr<Sensor> camera(int w, int h, Properties p = {}) {
    p.set_plugin_name("perspective");
    p.set_object("film", film_of(w, h));
    return PluginRegistry::instance().create_as<Sensor>(ObjectType::Sensor, p);
}

Vector3f dir(const Sensor &s, float u, float v) {
    return s.sample_ray(0.f, {u, v}, {0.5f, 0.5f}).first.d;
}

/// Full horizontal field of view in degrees, measured from the rays through the film edges.
double measured_x_fov(const Sensor &s) {
    Vector3f d = dir(s, 0.f, 0.5f); // identity to_world: camera space
    return 2.0 * std::atan2(std::abs(double(d.x)), double(d.z)) * RadToDeg;
}
double measured_y_fov(const Sensor &s) {
    Vector3f d = dir(s, 0.5f, 0.f);
    return 2.0 * std::atan2(std::abs(double(d.y)), double(d.z)) * RadToDeg;
}

std::string error_of(const std::function<void()> &f) {
    try {
        f();
    } catch (const Error &e) {
        return e.what();
    }
    return "(no error)";
}

} // namespace

TEST(Perspective, Default50mmLens) {
    // 50 mm on 36x24 mm measured along the diagonal (Mitsuba's focal_length convention).
    EXPECT_NEAR(measured_x_fov(*camera(64, 64)), 34.022, 1e-3);
    EXPECT_NEAR(measured_x_fov(*camera(200, 120)), 40.711, 1e-3);
    Properties p;
    p.set_string("focal_length", "50mm");
    EXPECT_NEAR(measured_x_fov(*camera(64, 64, p)), 34.022, 1e-3);
    Properties q;
    q.set_string("focal_length", "28mm"); // diagonal 2·atan(43.267/56) = 75.38°
    auto cam = camera(100, 100, q);
    double diag = 2.0 * std::atan(std::sqrt(36.0 * 36 + 24 * 24) / 56.0);
    EXPECT_NEAR(measured_x_fov(*cam),
                2.0 * std::atan(std::tan(diag / 2) / std::sqrt(2.0)) * RadToDeg, 1e-3);
}

TEST(Perspective, FovAxes) {
    auto with = [](double fov, const char *axis) {
        Properties p;
        p.set_float("fov", fov);
        if (axis) p.set_string("fov_axis", axis);
        return p;
    };
    // 200x100: aspect 2.
    EXPECT_NEAR(measured_x_fov(*camera(200, 100, with(60, nullptr))), 60.0, 1e-3);
    EXPECT_NEAR(measured_x_fov(*camera(200, 100, with(60, "x"))), 60.0, 1e-3);
    EXPECT_NEAR(measured_y_fov(*camera(200, 100, with(30, "y"))), 30.0, 1e-3);
    EXPECT_NEAR(measured_y_fov(*camera(200, 100, with(30, "smaller"))), 30.0, 1e-3);
    EXPECT_NEAR(measured_x_fov(*camera(200, 100, with(50, "larger"))), 50.0, 1e-3);
    // Portrait: the smaller axis is x, the larger y.
    EXPECT_NEAR(measured_x_fov(*camera(100, 200, with(30, "smaller"))), 30.0, 1e-3);
    EXPECT_NEAR(measured_y_fov(*camera(100, 200, with(50, "larger"))), 50.0, 1e-3);
    // Diagonal: the corner ray makes half the angle with the axis.
    auto cam = camera(200, 100, with(70, "diagonal"));
    Vector3f c = dir(*cam, 0.f, 0.f);
    EXPECT_NEAR(2.0 * std::acos(double(c.z)) * RadToDeg, 70.0, 1e-3);
    // y fov relates to x fov through the aspect ratio.
    auto y = camera(200, 100, with(30, "y"));
    EXPECT_NEAR(std::tan(measured_x_fov(*y) / 2 / RadToDeg), 2.0 * std::tan(15.0 / RadToDeg), 1e-5);

    EXPECT_NE(error_of([&] { camera(10, 10, with(30, "z")); }).find("fov_axis"), std::string::npos);
    EXPECT_NE(error_of([&] { camera(10, 10, with(180, "x")); }).find("fov"), std::string::npos);
    Properties both = with(30, nullptr);
    both.set_string("focal_length", "35mm");
    EXPECT_NE(error_of([&] { camera(10, 10, both); }).find("not both"), std::string::npos);
    Properties bad;
    bad.set_string("focal_length", "long");
    EXPECT_NE(error_of([&] { camera(10, 10, bad); }).find("focal_length"), std::string::npos);
}

TEST(Perspective, LookAtFrameAndImageOrientation) {
    const Point3f origin(1.f, 2.f, 3.f), target(4.f, 2.f, -1.f);
    Properties p;
    p.set_float("fov", 45.0);
    p.set_transform("to_world", Transform::look_at(origin, target, Vector3f(0.f, 1.f, 0.f)));
    auto cam = camera(32, 32, p);

    auto [ray, weight] = cam->sample_ray(0.f, {0.5f, 0.5f}, {0.5f, 0.5f});
    EXPECT_EQ(weight, Color3f(1.f));
    EXPECT_NEAR(norm(ray.o - origin), 0.f, 1e-5f);
    Vector3f view = normalize(target - origin);
    EXPECT_NEAR(dot(ray.d, view), 1.f, 1e-6f);
    EXPECT_NEAR(norm(ray.d), 1.f, 1e-6f);

    // The camera's left (+X of its frame, cross(up, dir)) is where the image's left edge looks.
    const Vector3f up(0.f, 1.f, 0.f);
    const Vector3f left = normalize(cross(up, view));
    Vector3f d_left = dir(*cam, 0.f, 0.5f), d_right = dir(*cam, 1.f, 0.5f);
    EXPECT_GT(dot(d_left, left), 0.f);
    EXPECT_LT(dot(d_right, left), 0.f);
    EXPECT_NEAR(dot(d_left, left), -dot(d_right, left), 1e-5f);
    // The top of the image (film y = 0) looks up.
    EXPECT_GT(dot(dir(*cam, 0.5f, 0.f), up), 0.f);
    EXPECT_LT(dot(dir(*cam, 0.5f, 1.f), up), 0.f);
}

TEST(Perspective, ClipPlanesAlongTheRay) {
    Properties p;
    p.set_float("fov", 90.0);
    p.set_float("near_clip", 0.5);
    p.set_float("far_clip", 100.0);
    auto cam = camera(10, 10, p);
    auto centre = cam->sample_ray(0.f, {0.5f, 0.5f}, {0.5f, 0.5f}).first;
    EXPECT_NEAR(centre.mint, 0.5f, 1e-6f);
    EXPECT_NEAR(centre.maxt, 100.f, 1e-4f);
    // At the left edge of a 90° camera the ray is 45° off axis: the planes are √2 further away.
    auto edge = cam->sample_ray(0.f, {0.f, 0.5f}, {0.5f, 0.5f}).first;
    EXPECT_NEAR(edge.mint, 0.5f * std::sqrt(2.f), 1e-5f);
    EXPECT_NEAR(edge.maxt, 100.f * std::sqrt(2.f), 1e-3f);
    // The clip planes are planes: mint·d.z is the near distance for every ray.
    auto corner = cam->sample_ray(0.f, {0.9f, 0.1f}, {0.5f, 0.5f}).first;
    EXPECT_NEAR(corner.mint * corner.d.z, 0.5f, 1e-6f);

    auto defaults = camera(10, 10);
    auto r = defaults->sample_ray(0.f, {0.5f, 0.5f}, {0.5f, 0.5f}).first;
    EXPECT_NEAR(r.mint, 1e-2f, 1e-8f);
    EXPECT_NEAR(r.maxt, 1e4f, 1e-1f);

    Properties bad;
    bad.set_float("near_clip", 10.0);
    bad.set_float("far_clip", 1.0);
    EXPECT_NE(error_of([&] { camera(10, 10, bad); }).find("near_clip"), std::string::npos);
}

TEST(Perspective, PrincipalPointAndFocusDistance) {
    Properties p;
    p.set_float("fov", 60.0);
    p.set_float("principal_point_offset_x", 0.25);
    p.set_float("focus_distance", 7.0); // accepted, no effect on a pinhole
    auto cam = camera(20, 20, p);
    // The film centre now looks where film x = 0.75 looked before.
    Properties q;
    q.set_float("fov", 60.0);
    auto ref = camera(20, 20, q);
    Vector3f a = dir(*cam, 0.5f, 0.5f), b = dir(*ref, 0.75f, 0.5f);
    EXPECT_NEAR(norm(a - b), 0.f, 1e-6f);
}

TEST(Sensor, DefaultFilmAndSampler) {
    auto cam =
        PluginRegistry::instance().create_as<Sensor>(ObjectType::Sensor, Properties("perspective"));
    EXPECT_EQ(cam->film().size(), Point2i(768, 576));
    EXPECT_EQ(cam->sampler().sample_count(), 4u);
    EXPECT_FALSE(cam->needs_aperture_sample());
    EXPECT_TRUE(cam->to_world().is_identity());
    EXPECT_NE(cam->to_string().find("Perspective"), std::string::npos);
}
