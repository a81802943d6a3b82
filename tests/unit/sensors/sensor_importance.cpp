// Sensor importance sampling (light tracing): sample_direction() finds the film position that a
// camera ray through the point would have, and its importance We has the closed form of each
// camera and integrates to one over the film. The chi-square tests of the sensors' direction
// sampling (camera rays against the importance, the thin lens's aperture against pdf_direction)
// are lines of tests/chi2/configs.txt (`facet chi2 sensor`).

#include "draws.h"

#include <facet/plugin.h>
#include <facet/random.h>
#include <facet/sensor.h>
#include <facet/warp.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace facet;

namespace {

std::shared_ptr<Sensor> make_sensor(const std::string &type, const Transform &to_world,
                                    const std::vector<std::pair<std::string, double>> &floats,
                                    int w = 48, int h = 32) {
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

Interaction point(const Point3f &p) {
    Interaction it;
    it.p = p;
    it.t = 0.f;
    return it;
}

const Transform LOOK = Transform::look_at({1, 2, 3}, {0, 0.5f, -1}, {0, 1, 0});

/// Camera rays through random film positions; the point at distance t along each ray maps back
/// to the same film position.
void expect_round_trip(const Sensor &cam, bool aperture) {
    PCG32 rng;
    const Point2i size = cam.film().size();
    for (int i = 0; i < 200; ++i) {
        Point2f film = next_point2f(rng);
        Point2f ap = aperture ? next_point2f(rng) : Point2f(0.5f);
        auto [ray, w] = cam.sample_ray(0.f, film, ap);
        const float t = 0.5f + 5.f * rng.next_float();
        auto [ds, weight] = cam.sample_direction(point(ray.o + ray.d * t), ap);
        ASSERT_FALSE(weight.is_black()) << i;
        EXPECT_NEAR(ds.uv.x, film.x * float(size.x), 2e-3f) << i;
        EXPECT_NEAR(ds.uv.y, film.y * float(size.y), 2e-3f) << i;
        EXPECT_NEAR(ds.dist, t, 1e-3f * t) << i;
        EXPECT_NEAR(dot(ds.d, -ray.d), 1.f, 1e-5f) << i;
    }
}

/// ∫ We cos θ dω over all directions (points at unit distance, uniform on the sphere) is one:
/// the importance of the whole film is normalised. sample_direction returns We cos θ / dist².
/// The directions come from a jittered 632 x 632 grid on the square (square_to_uniform_sphere
/// keeps areas, so every stratum is the same solid angle), the two jitters drawn in a set order:
/// 400,000 independent directions scattered the estimate by about 0.005 from seed to seed, and
/// `next_point2f(rng)` drew x and y in a compiler's order.
double importance_integral(const Sensor &cam, const Point3f &centre) {
    PCG32 rng(7);
    const int n = 632;
    double sum = 0.0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const float ju = rng.next_float();
            const float jv = rng.next_float();
            const Point2f u((float(i) + ju) / float(n), (float(j) + jv) / float(n));
            Vector3f d = warp::square_to_uniform_sphere(u);
            sum += cam.sample_direction(point(centre + d), Point2f(0.5f)).second.g;
        }
    return sum * 4.0 * Pi / (double(n) * double(n));
}

/// A sensor that implements only sample_ray (as measurement sensors may).
class RayOnlySensor final : public Sensor {
public:
    RayOnlySensor() : Sensor(Properties("test")) {}
    std::pair<Ray, Color3f> sample_ray(float, const Point2f &, const Point2f &) const override {
        return {Ray(), Color3f(1.f)};
    }
    std::string to_string() const override { return "RayOnlySensor[]"; }
};

} // namespace

TEST(SensorImportance, PerspectiveRoundTrip) {
    auto cam = make_sensor("perspective", LOOK, {{"fov", 50.0}});
    ASSERT_TRUE(cam->supports_direction_sampling());
    expect_round_trip(*cam, false);
}

TEST(SensorImportance, PerspectiveClosedForm) {
    // fov 60 along x on a 48x32 film: tan_x = tan 30°, tan_y = tan_x * 32 / 48.
    auto cam = make_sensor("perspective", Transform(), {{"fov", 60.0}});
    const float tan_x = std::tan(deg_to_rad(30.f)), tan_y = tan_x * 32.f / 48.f;
    const float area = 4.f * tan_x * tan_y;
    // Off axis, away from the centre: local direction (0.3, -0.2, 1) at distance 2.5.
    const Vector3f dir = normalize(Vector3f(0.3f, -0.2f, 1.f));
    auto [ds, weight] = cam->sample_direction(point(Point3f(0.f) + dir * 2.5f), Point2f(0.5f));
    const float cos_t = dir.z;
    EXPECT_TRUE(ds.delta);
    EXPECT_NEAR(weight.r, 1.f / (area * cos_t * cos_t * cos_t * 2.5f * 2.5f), 1e-5f);
    // Local +x is the image's left: x = 0.3 lands left of centre, y = -0.2 below it.
    EXPECT_NEAR(ds.uv.x, 24.f * (1.f - 0.3f / tan_x), 1e-3f);
    EXPECT_NEAR(ds.uv.y, 16.f * (1.f + 0.2f / tan_y), 1e-3f);
    // Behind the camera, outside the field of view, closer than near_clip: nothing.
    EXPECT_TRUE(cam->sample_direction(point({0, 0, -1}), Point2f(0.5f)).second.is_black());
    EXPECT_TRUE(cam->sample_direction(point({5, 0, 1}), Point2f(0.5f)).second.is_black());
    EXPECT_TRUE(cam->sample_direction(point({0, 0, 0.001f}), Point2f(0.5f)).second.is_black());
    EXPECT_EQ(cam->pdf_direction(point({0, 0, 1}), ds), 0.f);
}

TEST(SensorImportance, PerspectiveIntegratesToOne) {
    auto cam = make_sensor("perspective", LOOK, {{"fov", 70.0}});
    EXPECT_NEAR(importance_integral(*cam, Point3f(1, 2, 3)), 1.0, 0.005);
}

TEST(SensorImportance, ThinLensRoundTripAndClosedForm) {
    auto cam = make_sensor("thinlens", LOOK,
                           {{"fov", 50.0}, {"aperture_radius", 0.2}, {"focus_distance", 2.5}});
    ASSERT_TRUE(cam->supports_direction_sampling());
    expect_round_trip(*cam, true);
    // We / pdf = 1 / (A cos^3 θ dist²) with θ and dist seen from the lens point.
    auto local = make_sensor("thinlens", Transform(),
                             {{"fov", 60.0}, {"aperture_radius", 0.3}, {"focus_distance", 2.0}});
    const Point3f p(0.4f, 0.1f, 3.f);
    auto [ds, weight] = local->sample_direction(point(p), Point2f(0.2f, 0.7f));
    const Vector3f w = p - ds.p;
    const float dist = norm(w), cos_t = w.z / dist;
    const float tan_x = std::tan(deg_to_rad(30.f)), tan_y = tan_x * 32.f / 48.f;
    EXPECT_NEAR(weight.g, 1.f / (4.f * tan_x * tan_y * cos_t * cos_t * cos_t * dist * dist), 1e-5f);
    EXPECT_NEAR(ds.pdf, dist * dist / (cos_t * Pi * 0.09f), 1e-3f * ds.pdf);
    EXPECT_NEAR(local->pdf_direction(point(p), ds), ds.pdf, 1e-3f * ds.pdf);
    EXPECT_FALSE(ds.delta);
}

TEST(SensorImportance, ThinLensIntegratesToOne) {
    // ∫_lens ∫ We cos θ dω dA = 1. With x uniform on a sphere of radius R around the lens and
    // dω = |cos_x| dA_x / dist², E[(We / pdf) |cos_x| 4 pi R²] = 1 for lens points drawn by
    // sample_direction.
    auto cam = make_sensor("thinlens", LOOK,
                           {{"fov", 60.0}, {"aperture_radius", 0.05}, {"focus_distance", 3.0}});
    PCG32 rng(3);
    const int n = 400000;
    const float R = 2.f;
    double sum = 0.0, sum2 = 0.0;
    for (int i = 0; i < n; ++i) {
        Vector3f d = warp::square_to_uniform_sphere(next_point2f(rng));
        Point2f u = next_point2f(rng);
        auto [ds, weight] = cam->sample_direction(point(Point3f(1, 2, 3) + d * R), u);
        const double v = weight.g * std::abs(dot(d, ds.d)) * 4.0 * Pi * R * R;
        sum += v;
        sum2 += v * v;
    }
    const double mean = sum / n, sigma = std::sqrt((sum2 / n - mean * mean) / n);
    EXPECT_NEAR(mean, 1.0, 4.0 * sigma);
    EXPECT_LT(sigma, 0.01);
}

TEST(SensorImportance, OrthographicRoundTripAndArea) {
    Transform xf = LOOK * Transform::scale({2, 2, 1});
    auto cam = make_sensor("orthographic", xf, {});
    ASSERT_TRUE(cam->supports_direction_sampling());
    expect_round_trip(*cam, false);
    // The film is 4 x (4 * 32/48) world units: importance 1 / area, no distance falloff.
    auto [ray, w] = cam->sample_ray(0.f, Point2f(0.3f, 0.6f), Point2f(0.5f));
    auto [ds, weight] = cam->sample_direction(point(ray.o + ray.d * 3.f), Point2f(0.5f));
    EXPECT_NEAR(weight.b, 1.f / (4.f * 4.f * 32.f / 48.f), 1e-6f);
    EXPECT_TRUE(ds.delta);
}

TEST(SensorImportance, DefaultSaysNotSupported) {
    RayOnlySensor s;
    EXPECT_FALSE(s.supports_direction_sampling());
    EXPECT_THROW(s.sample_direction(point({0, 0, 1}), Point2f(0.5f)), Error);
    EXPECT_THROW(s.pdf_direction(point({0, 0, 1}), DirectionSample()), Error);
}
