// Orthographic and thin-lens cameras: where their rays start and go, against the perspective
// camera they generalise.

#include <facet/plugin.h>
#include <facet/sensor.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace facet;

namespace {

std::shared_ptr<Sensor> make_sensor(const std::string &type, const Transform &to_world,
                                    const std::vector<std::pair<std::string, double>> &floats,
                                    int w = 64, int h = 32) {
    Properties film_props("hdrfilm");
    film_props.set_int("width", w);
    film_props.set_int("height", h);
    auto film = PluginRegistry::instance().create(ObjectType::Film, film_props);
    Properties props(type);
    props.set_transform("to_world", to_world);
    for (const auto &[k, v] : floats) props.set_float(k, v);
    props.set_object("film", film);
    return PluginRegistry::instance().create_as<Sensor>(ObjectType::Sensor, props);
}

void expect_vec_near(const Vector3f &a, const Vector3f &b, float tol) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

} // namespace

TEST(Orthographic, ParallelRaysOverTheScaledFilm) {
    Transform xf =
        Transform::look_at({0, 10, 0}, {0, 0, 0}, {0, 0, 1}) * Transform::scale({3, 3, 1});
    auto cam = make_sensor("orthographic", xf, {});
    auto [centre, w] = cam->sample_ray(0.f, Point2f(0.5f, 0.5f), Point2f(0.5f));
    EXPECT_EQ(w, Color3f(1.f));
    expect_vec_near(centre.o, {0, 10, 0}, 1e-5f);
    expect_vec_near(centre.d, {0, -1, 0}, 1e-6f);
    // Every ray has the same direction; the film spans 2·3 = 6 units across and 6/aspect = 3 down.
    auto [left, w2] = cam->sample_ray(0.f, Point2f(0.f, 0.5f), Point2f(0.5f));
    auto [right, w3] = cam->sample_ray(0.f, Point2f(1.f, 0.5f), Point2f(0.5f));
    auto [top, w4] = cam->sample_ray(0.f, Point2f(0.5f, 0.f), Point2f(0.5f));
    expect_vec_near(left.d, centre.d, 1e-6f);
    expect_vec_near(right.d, centre.d, 1e-6f);
    EXPECT_NEAR(norm(right.o - left.o), 6.f, 1e-4f);
    EXPECT_NEAR(norm(top.o - centre.o), 1.5f, 1e-4f);
    // Image right is the camera's -X (its left is +X): with up = +Z and looking down -Y,
    // camera +X = cross(up, dir) = (0,0,1) x (0,-1,0) = (1, 0, 0), so the image's right is -X.
    EXPECT_LT(right.o.x, left.o.x);
    // Image top is +up.
    EXPECT_GT(top.o.z, centre.o.z);
}

TEST(Orthographic, ClipDistancesScaleWithTheTransform) {
    Transform xf =
        Transform::look_at({0, 0, 0}, {0, 0, 1}, {0, 1, 0}) * Transform::scale({2, 2, 2});
    auto cam = make_sensor("orthographic", xf, {{"near_clip", 1.0}, {"far_clip", 5.0}});
    auto [ray, w] = cam->sample_ray(0.f, Point2f(0.3f, 0.6f), Point2f(0.5f));
    EXPECT_NEAR(ray.mint, 2.f, 1e-5f);
    EXPECT_NEAR(ray.maxt, 10.f, 1e-4f);
}

TEST(ThinLens, ZeroApertureIsThePinhole) {
    Transform xf = Transform::look_at({1, 2, 3}, {0, 0, 0}, {0, 1, 0});
    auto lens = make_sensor("thinlens", xf,
                            {{"fov", 50.0}, {"aperture_radius", 0.0}, {"focus_distance", 4.0}});
    auto pin = make_sensor("perspective", xf, {{"fov", 50.0}});
    for (Point2f p : {Point2f(0.1f, 0.2f), Point2f(0.5f, 0.5f), Point2f(0.9f, 0.7f)}) {
        auto [a, wa] = lens->sample_ray(0.f, p, Point2f(0.3f, 0.8f));
        auto [b, wb] = pin->sample_ray(0.f, p, Point2f(0.5f));
        expect_vec_near(a.o, b.o, 1e-5f);
        expect_vec_near(a.d, b.d, 1e-5f);
    }
}

TEST(ThinLens, RaysThroughOnePixelMeetOnTheFocusPlane) {
    Transform xf = Transform::look_at({0, 0, 0}, {0, 0, 1}, {0, 1, 0});
    const float focus = 7.f, radius = 0.5f;
    auto lens = make_sensor(
        "thinlens", xf, {{"fov", 40.0}, {"aperture_radius", radius}, {"focus_distance", focus}});
    Point2f film(0.3f, 0.65f);
    Point3f meet;
    bool first = true;
    float max_offset = 0.f;
    for (Point2f ap :
         {Point2f(0.1f, 0.1f), Point2f(0.9f, 0.2f), Point2f(0.5f, 0.95f), Point2f(0.3f, 0.6f)}) {
        auto [ray, w] = lens->sample_ray(0.f, film, ap);
        EXPECT_EQ(w, Color3f(1.f));
        EXPECT_LE(std::hypot(ray.o.x, ray.o.y), radius + 1e-5f); // starts on the aperture
        max_offset = std::max(max_offset, std::hypot(ray.o.x, ray.o.y));
        float t = focus / ray.d.z; // camera looks down +Z: the focus plane is z = focus
        Point3f p = ray(t);
        if (first) meet = p, first = false;
        expect_vec_near(p, meet, 1e-4f);
    }
    EXPECT_GT(max_offset, 0.2f); // the lens samples are really spread over the aperture
    EXPECT_TRUE(lens->needs_aperture_sample());
}

TEST(ThinLens, MissingParametersAreErrors) {
    EXPECT_THROW(make_sensor("thinlens", Transform(), {{"aperture_radius", 0.1}}), std::exception);
    EXPECT_THROW(make_sensor("thinlens", Transform(), {{"focus_distance", 3.0}}), std::exception);
    EXPECT_THROW(
        make_sensor("thinlens", Transform(), {{"aperture_radius", -1.0}, {"focus_distance", 3.0}}),
        std::exception);
}

TEST(ProjectiveCameras, ScaledToWorldIsRefusedAsInMitsuba) {
    // The pinhole's and the lens's importance and densities assume a rigid camera frame: a
    // scaled to_world would mix world and camera distances. Mitsuba refuses it; so does facet.
    const Transform look = Transform::look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0});
    const std::vector<std::pair<std::string, double>> lens = {{"aperture_radius", 0.1},
                                                              {"focus_distance", 3.0}};
    for (const auto &[type, params] :
         {std::pair{std::string("perspective"), std::vector<std::pair<std::string, double>>{}},
          std::pair{std::string("thinlens"), lens}}) {
        SCOPED_TRACE(type);
        for (const Vector3f &s : {Vector3f(2, 2, 2), Vector3f(1, 1, 0.5f), Vector3f(1.01f, 1, 1)}) {
            try {
                make_sensor(type, look * Transform::scale(s), params);
                ADD_FAILURE() << "a scaled to_world was accepted";
            } catch (const std::exception &e) {
                EXPECT_NE(std::string(e.what()).find("scale factors in the camera-to-world"),
                          std::string::npos)
                    << e.what();
            }
        }
        // Rigid frames, mirrored ones included (scale x = -1 flips the image, as in Mitsuba),
        // and rounding-level deviations are accepted.
        EXPECT_NO_THROW(make_sensor(type, look, params));
        EXPECT_NO_THROW(make_sensor(type, look * Transform::scale({-1, 1, 1}), params));
        EXPECT_NO_THROW(make_sensor(type, look * Transform::scale({1.0004f, 1, 1}), params));
    }
}
