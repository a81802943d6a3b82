// Emitters point, area and constant: sampling records and weights, pdf consistency, and the
// irradiance their direction sampling estimates against closed forms.

#include "draws.h"

#include <facet/emitter.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/random.h>
#include <facet/scene.h>
#include <facet/shape.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace facet;

namespace {

std::shared_ptr<Emitter> make_emitter(const Properties &props) {
    return PluginRegistry::instance().create_as<Emitter>(ObjectType::Emitter, props);
}

std::shared_ptr<Shape> make_shape(Properties props, std::shared_ptr<Emitter> emitter) {
    props.set_object("emitter", emitter);
    return PluginRegistry::instance().create_as<Shape>(ObjectType::Shape, props);
}

void expect_color_near(const Color3f &a, const Color3f &b, float rel) {
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(a[c], b[c], rel * std::max(1e-6f, std::abs(b[c]))) << "channel " << c;
}

Interaction reference(const Point3f &p, const Normal3f &n) {
    Interaction it;
    it.p = p;
    it.n = n;
    it.t = 0.f;
    return it;
}

/// Form factor from a point to a parallel rectangle a×b whose corner lies on the point's normal
/// at distance c (Howell's catalogue, configuration A-3).
double form_factor_corner(double a, double b, double c) {
    double x = a / c, y = b / c;
    double sx = std::sqrt(1 + x * x), sy = std::sqrt(1 + y * y);
    return (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy)) / (2 * M_PI);
}

struct Estimate {
    double mean[3] = {0, 0, 0};
    double sigma = 0; ///< standard error of the mean of channel 0
};

/// Monte Carlo estimate of the irradiance at `ref` from emitter direction sampling:
/// E = ∫ L cos θ dω ≈ mean(weight · max(0, n·d)). Also checks every sample's pdf.
Estimate irradiance(const Emitter &emitter, const Interaction &ref, int n, uint64_t seed) {
    PCG32 rng(seed);
    double sum[3] = {0, 0, 0}, sum2 = 0;
    int pdf_failures = 0;
    for (int i = 0; i < n; ++i) {
        auto [ds, weight] = emitter.sample_direction(ref, next_point2f(rng));
        float cos_theta = std::max(0.f, dot(ref.n, ds.d));
        if (!weight.is_black()) {
            EXPECT_EQ(ds.emitter, &emitter);
            float pdf = emitter.pdf_direction(ref, ds);
            if (!(std::abs(pdf - ds.pdf) <= 1e-4f * ds.pdf)) ++pdf_failures;
        }
        for (int c = 0; c < 3; ++c) sum[c] += double(weight[c]) * cos_theta;
        sum2 += sqr(double(weight[0]) * cos_theta);
    }
    EXPECT_EQ(pdf_failures, 0) << "pdf_direction disagrees with the sampled pdf";
    Estimate e;
    for (int c = 0; c < 3; ++c) e.mean[c] = sum[c] / n;
    e.sigma = std::sqrt(std::max(0.0, sum2 / n - sqr(e.mean[0])) / n);
    return e;
}

} // namespace

// ---- point ----------------------------------------------------------------------------------

TEST(EmitterPoint, Creation) {
    Properties props("point");
    auto e = make_emitter(props);
    EXPECT_EQ(e->flags(), EmitterFlags::DeltaPosition);
    EXPECT_TRUE(e->is_delta());
    EXPECT_FALSE(e->is_infinite());
    EXPECT_FALSE(e->to_string().empty());
}

TEST(EmitterPoint, WeightIsIntensityOverDistanceSquared) {
    Properties props("point");
    props.set_vector("position", Vector3f(1.f, 2.f, 3.f));
    props.set_color("intensity", Color3f(2.f, 4.f, 6.f));
    auto e = make_emitter(props);

    Interaction ref = reference(Point3f(1.f, 2.f, -1.f), Normal3f(0.f, 0.f, 1.f));
    auto [ds, weight] = e->sample_direction(ref, Point2f(0.3f, 0.7f));
    expect_color_near(weight, Color3f(2.f, 4.f, 6.f) / 16.f, 1e-6f);
    EXPECT_EQ(ds.p, Point3f(1.f, 2.f, 3.f));
    EXPECT_NEAR(ds.dist, 4.f, 1e-6f);
    EXPECT_NEAR(ds.d.z, 1.f, 1e-6f);
    EXPECT_TRUE(ds.delta);
    EXPECT_EQ(ds.pdf, 1.f);
    EXPECT_EQ(ds.emitter, e.get());
    EXPECT_EQ(e->pdf_direction(ref, ds), 0.f);
    SurfaceInteraction si;
    EXPECT_TRUE(e->eval(si).is_black());

    // Off axis: the weight does not include the receiver's cosine.
    Interaction side = reference(Point3f(4.f, 6.f, 3.f), Normal3f(0.f, 0.f, 1.f));
    auto [ds2, w2] = e->sample_direction(side, Point2f(0.5f, 0.5f));
    expect_color_near(w2, Color3f(2.f, 4.f, 6.f) / 25.f, 1e-6f);
    EXPECT_NEAR(ds2.d.x, -0.6f, 1e-6f);
    EXPECT_NEAR(ds2.d.y, -0.8f, 1e-6f);
}

TEST(EmitterPoint, SampleRay) {
    // Emitted rays start at the light and carry its total power 4π·I divided evenly.
    Properties props("point");
    props.set_vector("position", Vector3f(1.f, -2.f, 0.5f));
    props.set_color("intensity", Color3f(1.f, 2.f, 3.f));
    auto e = make_emitter(props);
    PCG32 rng(12);
    Vector3f mean_d(0.f);
    for (int i = 0; i < 10000; ++i) {
        const Point2f u_pos = next_point2f(rng);
        auto [ray, weight] = e->sample_ray(u_pos, next_point2f(rng), Wavelengths());
        EXPECT_EQ(ray.o, Point3f(1.f, -2.f, 0.5f));
        EXPECT_NEAR(norm(ray.d), 1.f, 1e-5f);
        EXPECT_NEAR(e->pdf_ray_direction(ray.d), InvFourPi, 1e-7f);
        expect_color_near(weight, Color3f(1.f, 2.f, 3.f) * (4.f * Pi), 1e-6f);
        mean_d += ray.d / 10000.f;
    }
    EXPECT_LT(norm(mean_d), 0.03f); // isotropic
}

TEST(EmitterPoint, ToWorld) {
    Properties props("point");
    props.set_transform("to_world", Transform::translate(Vector3f(0.f, 5.f, 0.f)));
    auto e = make_emitter(props);
    auto [ds, weight] =
        e->sample_direction(reference(Point3f(0.f), Normal3f(0.f, 1.f, 0.f)), Point2f(0.5f, 0.5f));
    EXPECT_EQ(ds.p, Point3f(0.f, 5.f, 0.f));
    expect_color_near(weight, Color3f(1.f / 25.f), 1e-6f); // default intensity 1
}

TEST(EmitterPoint, RejectsPositionAndToWorld) {
    Properties props("point");
    props.set_vector("position", Vector3f(1.f, 2.f, 3.f));
    props.set_transform("to_world", Transform::translate(Vector3f(0.f, 5.f, 0.f)));
    EXPECT_THROW(make_emitter(props), Error);
}

// ---- area -----------------------------------------------------------------------------------

TEST(EmitterArea, Creation) {
    Properties props("area");
    props.set_color("radiance", Color3f(3.f));
    auto e = make_emitter(props);
    EXPECT_EQ(e->flags(), EmitterFlags::Surface);
    EXPECT_FALSE(e->is_delta());
    EXPECT_FALSE(e->is_infinite());
    EXPECT_FALSE(e->to_string().empty());
}

TEST(EmitterArea, NeedsShape) {
    auto e = make_emitter(Properties("area"));
    Interaction ref = reference(Point3f(0.f), Normal3f(0.f, 0.f, 1.f));
    EXPECT_THROW(e->sample_direction(ref, Point2f(0.5f, 0.5f)), Error);
    DirectionSample ds;
    ds.d = Vector3f(0.f, 0.f, 1.f);
    ds.n = Normal3f(0.f, 0.f, -1.f);
    ds.dist = 1.f;
    EXPECT_THROW(e->pdf_direction(ref, ds), Error);
}

TEST(EmitterArea, RejectsToWorld) {
    Properties props("area");
    props.set_transform("to_world", Transform::translate(Vector3f(0.f, 5.f, 0.f)));
    EXPECT_THROW(make_emitter(props), Error);
}

TEST(EmitterArea, EvalFrontSideOnly) {
    Properties props("area");
    props.set_color("radiance", Color3f(1.f, 2.f, 3.f));
    auto e = make_emitter(props);
    SurfaceInteraction si;
    si.t = 1.f;
    si.wi = normalize(Vector3f(0.2f, 0.1f, 0.9f));
    expect_color_near(e->eval(si), Color3f(1.f, 2.f, 3.f), 1e-6f);
    si.wi = normalize(Vector3f(0.2f, 0.1f, -0.9f));
    EXPECT_TRUE(e->eval(si).is_black());
}

TEST(EmitterArea, RectangleIrradianceOnAxis) {
    // Unit-radiance square [-1, 1]² at z = 0 facing +z, seen from a point on its axis at height h
    // facing down: E = π L F with F = 4 · F_corner(1, 1, h).
    Properties props("area");
    props.set_color("radiance", Color3f(1.f, 2.f, 0.5f));
    auto e = make_emitter(props);
    auto shape = make_shape(Properties("rectangle"), e);
    ASSERT_EQ(e->shape(), shape.get());
    // Shape and emitter describe each other without recursing forever.
    EXPECT_FALSE(shape->to_string().empty());
    EXPECT_FALSE(e->to_string().empty());

    const double h = 1.5;
    Interaction ref = reference(Point3f(0.f, 0.f, float(h)), Normal3f(0.f, 0.f, -1.f));
    Estimate est = irradiance(*e, ref, 400000, 1);
    double expected = M_PI * 4.0 * form_factor_corner(1.0, 1.0, h);
    EXPECT_LT(est.sigma, 2e-3 * expected);
    EXPECT_NEAR(est.mean[0], expected, 4.0 * est.sigma);
    EXPECT_NEAR(est.mean[1], 2.0 * expected, 8.0 * est.sigma);
    EXPECT_NEAR(est.mean[2], 0.5 * expected, 2.0 * est.sigma);
}

TEST(EmitterArea, RectangleIrradianceOffAxisTilted) {
    // A receiver beside the light's axis, tilted: compare with a brute-force quadrature over the
    // light's surface, E = ∫ L cos θ_r cos θ_l / r² dA.
    Properties props("area");
    auto e = make_emitter(props);
    auto shape = make_shape(Properties("rectangle"), e);
    Point3f p(0.7f, -0.4f, 1.2f);
    Normal3f n = normalize(Vector3f(0.3f, 0.2f, -1.f));
    Interaction ref = reference(p, n);
    Estimate est = irradiance(*e, ref, 400000, 2);

    const int m = 800;
    double sum = 0;
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) {
            Vector3d q(-1.0 + (i + 0.5) * 2.0 / m, -1.0 + (j + 0.5) * 2.0 / m, 0.0);
            Vector3d d(q.x - p.x, q.y - p.y, q.z - p.z);
            double r2 = dot(d, d), r = std::sqrt(r2);
            double cos_r = std::max(0.0, (d.x * n.x + d.y * n.y + d.z * n.z) / r);
            double cos_l = std::max(0.0, -d.z / r);
            sum += cos_r * cos_l / r2;
        }
    double expected = sum * 4.0 / (double(m) * m);
    EXPECT_NEAR(est.mean[0], expected, 4.0 * est.sigma + 1e-5 * expected);
}

TEST(EmitterArea, SampleRayCarriesThePower) {
    // A 2×2 square of radiance L emits Φ = π·L·A from its front side; every ray carries Φ.
    Properties props("area");
    props.set_color("radiance", Color3f(2.f, 1.f, 0.5f));
    auto e = make_emitter(props);
    Properties rect("rectangle");
    rect.set_transform("to_world", Transform::translate(Vector3f(0.f, 0.f, 1.f)));
    auto shape = make_shape(rect, e);
    PCG32 rng(13);
    double mean_cos = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
        const Point2f u_pos = next_point2f(rng);
        auto [ray, weight] = e->sample_ray(u_pos, next_point2f(rng), Wavelengths());
        expect_color_near(weight, Color3f(2.f, 1.f, 0.5f) * (Pi * 4.f), 1e-5f);
        EXPECT_LE(std::abs(ray.o.x), 1.f + 1e-5f);
        EXPECT_LE(std::abs(ray.o.y), 1.f + 1e-5f);
        EXPECT_NEAR(ray.o.z, 1.f, 1e-3f);
        EXPECT_GT(ray.o.z, 1.f); // offset to the emitting side
        EXPECT_GT(ray.d.z, 0.f);
        mean_cos += ray.d.z / n;
    }
    // Cosine-weighted directions: E[cos θ] = 2/3.
    EXPECT_NEAR(mean_cos, 2.0 / 3.0, 7e-3); // 4 standard errors
}

namespace {
/// An area light whose radiance is a checkerboard of (1, 2, 3) (where u and v are on the same
/// side of 1/2) and 5.
std::shared_ptr<Emitter> checkerboard_light() {
    return std::dynamic_pointer_cast<Emitter>(load_string(R"(
        <emitter version="3.0.0" type="area">
            <texture type="checkerboard" name="radiance">
                <rgb name="color0" value="1, 2, 3"/>
                <rgb name="color1" value="5, 5, 5"/>
            </texture>
        </emitter>)"));
}

/// Which square of checkerboard_light() the point (u, v) lies in (0: u and v on the same side
/// of 1/2), counted in `seen`, and the radiance there.
Color3f checker_radiance(double u, double v, int (&seen)[2]) {
    const int square = (u > 0.5) == (v > 0.5) ? 0 : 1;
    ++seen[square];
    return square == 0 ? Color3f(1.f, 2.f, 3.f) : Color3f(5.f);
}
} // namespace

TEST(EmitterArea, TexturedRadiance) {
    // A checkerboard radiance: sampled points and hits see the value at their own uv.
    auto e = checkerboard_light();
    ASSERT_TRUE(e);
    EXPECT_TRUE(has_flag(e->flags(), EmitterFlags::SpatiallyVarying));
    auto shape = make_shape(Properties("rectangle"), e);
    Interaction ref = reference(Point3f(0.f, 0.f, 2.f), Normal3f(0.f, 0.f, -1.f));
    PCG32 rng(14);
    int seen[2] = {0, 0};
    for (int i = 0; i < 1000; ++i) {
        auto [ds, weight] = e->sample_direction(ref, next_point2f(rng));
        expect_color_near(weight * ds.pdf, checker_radiance(ds.uv.x, ds.uv.y, seen), 1e-5f);
    }
    EXPECT_GT(seen[0], 400);
    EXPECT_GT(seen[1], 400);
    SurfaceInteraction si;
    si.t = 1.f;
    si.wi = Vector3f(0.f, 0.f, 1.f);
    si.uv = Point2f(0.8f, 0.1f);
    expect_color_near(e->eval(si), Color3f(5.f), 1e-6f);
}

TEST(EmitterArea, TexturedRadianceOnASphere) {
    // A sphere light samples its cone of directions; with a textured radiance each sample sees
    // the value at its own point's spherical uv (a uniform one may skip the uv: see
    // Shape::sample_direction()).
    auto e = checkerboard_light();
    ASSERT_TRUE(e);
    auto shape = make_shape(Properties("sphere"), e);
    Interaction ref = reference(Point3f(0.f, 0.f, 2.f), Normal3f(0.f, 0.f, -1.f));
    PCG32 rng(15);
    int seen[2] = {0, 0};
    for (int i = 0; i < 1000; ++i) {
        auto [ds, weight] = e->sample_direction(ref, next_point2f(rng));
        ASSERT_GT(ds.pdf, 0.f);
        EXPECT_EQ(e->pdf_direction(ref, ds), ds.pdf);
        // u = φ/2π around +z, v = θ/π from +z, of the unit sphere's point.
        double u = std::atan2(double(ds.p.y), double(ds.p.x)) / (2.0 * M_PI);
        if (u < 0.0) u += 1.0;
        const double v = std::acos(std::clamp(double(ds.p.z), -1.0, 1.0)) / M_PI;
        if (std::abs(u - 0.5) < 1e-4 || u < 1e-4 || u > 1.0 - 1e-4) continue; // on an edge
        EXPECT_NEAR(ds.uv.y, v, 1e-5);
        EXPECT_NEAR(ds.uv.x, u, 1e-5);
        expect_color_near(weight * ds.pdf, checker_radiance(u, v, seen), 1e-5f);
    }
    EXPECT_GT(seen[0], 400);
    EXPECT_GT(seen[1], 400);
}

TEST(EmitterArea, BackSideGivesNothing) {
    auto e = make_emitter(Properties("area"));
    auto shape = make_shape(Properties("rectangle"), e);
    Interaction below = reference(Point3f(0.1f, 0.2f, -1.f), Normal3f(0.f, 0.f, 1.f));
    PCG32 rng(5);
    for (int i = 0; i < 1000; ++i) {
        auto [ds, weight] = e->sample_direction(below, next_point2f(rng));
        EXPECT_TRUE(weight.is_black());
        EXPECT_EQ(e->pdf_direction(below, ds), 0.f);
    }
}

TEST(EmitterArea, SphereIrradiance) {
    // A sphere of radius r at distance d above the receiver's normal: E = π L (r/d)².
    Properties props("area");
    props.set_color("radiance", Color3f(2.f));
    auto e = make_emitter(props);
    Properties sphere("sphere");
    sphere.set_vector("center", Vector3f(0.f, 0.f, 3.f));
    sphere.set_float("radius", 0.5);
    auto shape = make_shape(sphere, e);
    Interaction ref = reference(Point3f(0.f), Normal3f(0.f, 0.f, 1.f));
    Estimate est = irradiance(*e, ref, 200000, 3);
    double expected = M_PI * 2.0 * sqr(0.5 / 3.0);
    EXPECT_NEAR(est.mean[0], expected, 4.0 * est.sigma + 1e-4 * expected);
}

// ---- constant -------------------------------------------------------------------------------

TEST(EmitterConstant, SamplingRecord) {
    Properties props("constant");
    props.set_color("radiance", Color3f(0.5f, 1.f, 2.f));
    auto e = make_emitter(props);
    EXPECT_TRUE(e->is_infinite());
    EXPECT_FALSE(e->is_delta());
    EXPECT_FALSE(e->to_string().empty());

    SurfaceInteraction miss;
    miss.wi = normalize(Vector3f(0.3f, -0.5f, 0.2f));
    expect_color_near(e->eval(miss), Color3f(0.5f, 1.f, 2.f), 1e-6f);

    Interaction ref = reference(Point3f(0.2f, 0.3f, -0.1f), Normal3f(0.f, 1.f, 0.f));
    PCG32 rng(9);
    for (int i = 0; i < 1000; ++i) {
        auto [ds, weight] = e->sample_direction(ref, next_point2f(rng));
        EXPECT_NEAR(ds.pdf, InvFourPi, 1e-7f);
        EXPECT_EQ(e->pdf_direction(ref, ds), ds.pdf);
        EXPECT_FALSE(ds.delta);
        EXPECT_EQ(ds.emitter, e.get());
        EXPECT_NEAR(norm(ds.d), 1.f, 1e-5f);
        EXPECT_NEAR(norm(ds.p - ref.p), ds.dist, 1e-4f * ds.dist);
        expect_color_near(weight, Color3f(0.5f, 1.f, 2.f) * (4.f * Pi), 1e-5f);
    }
}

TEST(EmitterConstant, Irradiance) {
    // Unit radiance from every direction: E = π on any surface.
    auto e = make_emitter(Properties("constant"));
    Interaction ref = reference(Point3f(0.f), normalize(Normal3f(1.f, 1.f, 0.f)));
    Estimate est = irradiance(*e, ref, 200000, 4);
    EXPECT_NEAR(est.mean[0], M_PI, 4.0 * est.sigma);
    EXPECT_LT(est.sigma, 0.01);
}

TEST(EmitterConstant, SampledPointsLieOutsideTheScene) {
    Properties sphere("sphere");
    sphere.set_vector("center", Vector3f(10.f, 0.f, 0.f));
    sphere.set_float("radius", 2.0);
    auto shape = PluginRegistry::instance().create_as<Shape>(ObjectType::Shape, sphere);
    auto env = make_emitter(Properties("constant"));
    Properties scene_props("scene");
    scene_props.set_object("_arg_0", shape);
    scene_props.set_object("_arg_1", env);
    Scene scene(scene_props);
    ASSERT_EQ(scene.environment_emitters().size(), 1u);

    // From a point on the sphere, every sampled point is farther away than the scene's
    // diameter, so shadow rays towards it cross all geometry.
    Interaction ref = reference(Point3f(12.f, 0.f, 0.f), Normal3f(1.f, 0.f, 0.f));
    PCG32 rng(10);
    for (int i = 0; i < 1000; ++i) {
        auto [ds, weight] = env->sample_direction(ref, next_point2f(rng));
        EXPECT_GE(ds.dist, 4.f);
        EXPECT_GT(norm(ds.p - Point3f(10.f, 0.f, 0.f)), 2.f * std::sqrt(3.f));
    }
}

// ---- chi-square of direction sampling: the emitter lines of tests/chi2/configs.txt ----------
