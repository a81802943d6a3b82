// Transforms, warps and erfinv.
#include "draws.h"

#include <facet/math.h>
#include <facet/random.h>
#include <facet/transform.h>
#include <facet/warp.h>

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

using namespace facet;

namespace {

void expect_near(const Vector3f &a, const Vector3f &b, float eps = 1e-5f) {
    EXPECT_NEAR(a.x, b.x, eps) << a << " vs " << b;
    EXPECT_NEAR(a.y, b.y, eps) << a << " vs " << b;
    EXPECT_NEAR(a.z, b.z, eps) << a << " vs " << b;
}

void expect_identity(const Matrix4f &m, float eps = 1e-5f) {
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            EXPECT_NEAR(m.m[i][j], i == j ? 1.f : 0.f, eps) << i << "," << j;
}

Vector3f column(const Transform &t, int j) {
    return {t.matrix.m[0][j], t.matrix.m[1][j], t.matrix.m[2][j]};
}

} // namespace

TEST(Transform, ComposeAppliesRightOperandFirst) {
    Transform t = Transform::translate({1, 2, 3}) * Transform::scale({2, 3, 4});
    // Scale first, then translate.
    expect_near(t.apply_point({1, 1, 1}), {3, 5, 7});
    Transform u = Transform::scale({2, 3, 4}) * Transform::translate({1, 2, 3});
    expect_near(u.apply_point({1, 1, 1}), {4, 9, 16});
    // Vectors ignore translation.
    expect_near(t.apply_vector({1, 1, 1}), {2, 3, 4});
}

TEST(Transform, InverseIsInverse) {
    Matrix4f m =
        Matrix4f::from_rows({2, 0.5f, 0, 1, 0.1f, 3, -1, 2, 0, 0.2f, 1.5f, -3, 0.3f, 0, 0.1f, 1});
    expect_identity(m * m.inverse());
    expect_identity(m.inverse() * m);
    Transform t = Transform::rotate({1, 2, 3}, 33.f) * Transform::translate({4, -5, 6}) *
                  Transform::scale({0.5f, 2, 3});
    expect_identity(t.matrix * t.inverse_matrix);
    Point3f p(0.3f, -0.7f, 2.f);
    expect_near(t.inverse().apply_point(t.apply_point(p)), p, 1e-4f);
    // A singular matrix gives NaNs.
    Matrix4f s = Matrix4f::from_rows({1, 2, 3, 4, 2, 4, 6, 8, 0, 1, 0, 0, 0, 0, 0, 1});
    EXPECT_TRUE(std::isnan(s.inverse().m[0][0]));
}

TEST(Transform, RotateIsCounterClockwiseInDegrees) {
    expect_near(Transform::rotate({0, 0, 1}, 90.f).apply_vector({1, 0, 0}), {0, 1, 0});
    expect_near(Transform::rotate({1, 0, 0}, 90.f).apply_vector({0, 1, 0}), {0, 0, 1});
    expect_near(Transform::rotate({0, 1, 0}, 90.f).apply_vector({0, 0, 1}), {1, 0, 0});
    // The axis need not be normalised.
    expect_near(Transform::rotate({0, 0, 5}, 180.f).apply_vector({1, 2, 0}), {-1, -2, 0});
}

TEST(Transform, NormalsUseInverseTranspose) {
    // The plane x + y = 0 under a non-uniform scale: the transformed normal must stay
    // perpendicular to the transformed tangent.
    Transform t = Transform::scale({2, 1, 1});
    Vector3f tangent = t.apply_vector({1, -1, 0});
    Normal3f n = t.apply_normal({1, 1, 0});
    EXPECT_NEAR(dot(tangent, n), 0.f, 1e-6f);
    expect_near(n, {0.5f, 1, 0});
    // Transforming the normal as a vector would be wrong.
    EXPECT_GT(std::abs(dot(tangent, t.apply_vector({1, 1, 0}))), 1.f);
}

TEST(Transform, PointsGetProjectiveDivide) {
    Matrix4f m;
    m.m[3][3] = 2.f;
    expect_near(Transform(m).apply_point({2, 4, 6}), {1, 2, 3});
}

TEST(Transform, LookAtColumnsAreLeftUpDirOrigin) {
    // Looking from +z towards the origin with +y up: dir = -z, left = up x dir = -x.
    Transform t = Transform::look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0});
    expect_near(column(t, 0), {-1, 0, 0});
    expect_near(column(t, 1), {0, 1, 0});
    expect_near(column(t, 2), {0, 0, -1});
    expect_near(column(t, 3), {0, 0, 5});
    expect_near(t.apply_point({0, 0, 1}), {0, 0, 4});
    expect_identity(t.matrix * t.inverse_matrix);

    // A general case: left = normalize(cross(up, dir)), up' = cross(dir, left).
    Point3f o(1, 2, 3), target(-2, 4, 0.5f);
    Vector3f up(0.1f, 0.2f, 1.f);
    Transform g = Transform::look_at(o, target, up);
    Vector3f dir = normalize(target - o), left = normalize(cross(up, dir));
    expect_near(column(g, 0), left);
    expect_near(column(g, 1), cross(dir, left));
    expect_near(column(g, 2), dir);
    expect_near(column(g, 3), o);
    // The up' column leans towards the given up.
    EXPECT_GT(dot(column(g, 1), up), 0.f);
}

TEST(Transform, LookAtWithDegenerateUpStillGivesAFrame) {
    for (Vector3f up : {Vector3f(0, 0, 0), Vector3f(0, 0, 2), Vector3f(0, 0, -1)}) {
        Transform t = Transform::look_at({0, 0, 0}, {0, 0, 3}, up);
        Vector3f l = column(t, 0), u = column(t, 1), d = column(t, 2);
        EXPECT_TRUE(is_finite(l) && is_finite(u)) << up;
        EXPECT_NEAR(norm(l), 1.f, 1e-5f);
        EXPECT_NEAR(norm(u), 1.f, 1e-5f);
        expect_near(d, {0, 0, 1});
        EXPECT_NEAR(dot(l, u), 0.f, 1e-5f);
        EXPECT_NEAR(dot(l, d), 0.f, 1e-5f);
        // Right-handed like the regular case: left x up' = dir.
        expect_near(cross(l, u), d);
    }
}

TEST(Transform, PerspectiveMapsFrustumToUnitRange) {
    float fov = 60.f, near = 0.1f, far = 100.f;
    Transform p = Transform::perspective(fov, near, far);
    float t = std::tan(deg_to_rad(fov / 2));
    // The frustum edge at x/z = tan(fov/2) maps to x = 1.
    expect_near(p.apply_point({t * 7, 0, 7}), {1, 0, (far * (7 - near)) / ((far - near) * 7)},
                1e-4f);
    expect_near(p.apply_point({0, -t * 3, 3}), {0, -1, (far * (3 - near)) / ((far - near) * 3)},
                1e-4f);
    EXPECT_NEAR(p.apply_point({0, 0, near}).z, 0.f, 1e-5f);
    EXPECT_NEAR(p.apply_point({0, 0, far}).z, 1.f, 1e-5f);
    expect_identity(p.matrix * p.inverse_matrix, 1e-4f);
}

TEST(Transform, ToStringShowsRows) {
    std::string s = Transform::translate({1, 2, 3}).to_string();
    EXPECT_NE(s.find("[1, 0, 0, 1]"), std::string::npos) << s;
    EXPECT_NE(s.find("[0, 0, 1, 3]"), std::string::npos) << s;
}

TEST(Math, ErfinvInvertsErf) {
    for (int i = -999; i <= 999; ++i) {
        float x = i / 1000.f;
        float y = erfinv(x);
        EXPECT_NEAR(std::erf(double(y)), x, 2e-7) << x;
    }
    EXPECT_EQ(erfinv(0.f), 0.f);
    EXPECT_NEAR(erfinv(0.5f), 0.4769362762f, 1e-6f);
    EXPECT_NEAR(erfinv(-0.999999f), -3.4589107f, 2e-3f);
}

TEST(Math, FastAtan2IsWithinTwoAndAQuarterUlpOfTheAngle) {
    // Random points in every quadrant, at every scale ratio (down to 1e-6, where the angle is
    // near an axis), against atan2 in double; then the signed zeros and the axes exactly.
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> uniform(-1.f, 1.f);
    double worst = 0.0;
    for (int i = 0; i < 1000000; ++i) {
        float y = uniform(rng), x = uniform(rng);
        if (i % 3 == 1) y *= std::pow(10.f, -float(i % 7));
        if (i % 3 == 2) x *= std::pow(10.f, -float(i % 7));
        const double want = std::atan2(double(y), double(x));
        const float got = fast_atan2(y, x);
        const float w = float(std::abs(want));
        const double ulp = double(std::nextafter(w, Infinity) - w);
        worst = std::max(worst, std::abs(double(got) - want) / ulp);
        ASSERT_LE(std::abs(double(got) - want), 2.25 * ulp) << "atan2(" << y << ", " << x << ")";
    }
    EXPECT_GT(worst, 0.5); // the comparison itself is not vacuous
    for (float y : {0.f, -0.f, 1.f, -1.f, 3e-30f})
        for (float x : {0.f, -0.f, 1.f, -1.f, 2e-30f}) {
            const float want = std::atan2(y, x), got = fast_atan2(y, x);
            EXPECT_NEAR(got, want, 2.5e-7f) << "atan2(" << y << ", " << x << ")";
            EXPECT_EQ(std::signbit(got), std::signbit(want)) << "atan2(" << y << ", " << x << ")";
        }
}

// -- Warps -------------------------------------------------------------------------------------

namespace {

/// A histogram test on a 2D domain [x0,x1]x[y0,y1]: the expected counts come from the density
/// integrated over each cell (midpoint rule on a sub-grid); Pearson's statistic is compared to
/// the chi-square quantile of significance 1e-4 (Wilson-Hilferty approximation), after pooling
/// cells expecting fewer than 5 samples. A sample in a cell of zero density fails outright.
struct HistogramTest {
    int nx, ny;
    double x0, x1, y0, y1;
    int subdiv = 8;

    /// density(x, y) in the cell's coordinates; sample(u) returns the sample's (x, y).
    void run(const std::function<double(double, double)> &density,
             const std::function<Vector2f(const Point2f &)> &sample, int n_samples = 200000,
             double pdf_integral_tolerance = 2e-3) const {
        std::vector<double> expected(nx * ny, 0.0);
        double dx = (x1 - x0) / nx, dy = (y1 - y0) / ny, total = 0.0;
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                double sum = 0.0;
                for (int b = 0; b < subdiv; ++b)
                    for (int a = 0; a < subdiv; ++a)
                        sum += density(x0 + (i + (a + 0.5) / subdiv) * dx,
                                       y0 + (j + (b + 0.5) / subdiv) * dy);
                expected[j * nx + i] = sum * dx * dy / (subdiv * subdiv);
                total += expected[j * nx + i];
            }
        // The density integrates to one.
        EXPECT_NEAR(total, 1.0, pdf_integral_tolerance);

        std::vector<double> observed(nx * ny, 0.0);
        PCG32 rng(42, 7);
        for (int k = 0; k < n_samples; ++k) {
            Vector2f s = sample(next_point2f(rng));
            ASSERT_TRUE(std::isfinite(s.x) && std::isfinite(s.y));
            int i = std::min(nx - 1, std::max(0, int((s.x - x0) / dx)));
            int j = std::min(ny - 1, std::max(0, int((s.y - y0) / dy)));
            observed[j * nx + i] += 1.0;
        }

        // Pool small cells, then Pearson's statistic.
        std::vector<std::pair<double, double>> cells; // (observed, expected)
        double pool_obs = 0, pool_exp = 0, chi2 = 0;
        for (size_t c = 0; c < expected.size(); ++c) {
            double e = expected[c] * n_samples;
            if (e == 0.0) {
                ASSERT_EQ(observed[c], 0.0)
                    << "samples in a cell of zero density (cell " << c << ")";
                continue;
            }
            if (e < 5.0) {
                pool_obs += observed[c];
                pool_exp += e;
            } else {
                cells.emplace_back(observed[c], e);
            }
        }
        if (pool_exp > 0) cells.emplace_back(pool_obs, pool_exp);
        for (auto &[o, e] : cells) chi2 += (o - e) * (o - e) / e;
        double dof = double(cells.size() - 1);
        double h = 2.0 / (9.0 * dof);
        double z = (std::cbrt(chi2 / dof) - (1.0 - h)) / std::sqrt(h);
        EXPECT_LT(z, 3.719) << "chi2 = " << chi2 << " with " << dof << " degrees of freedom";
    }
};

/// (phi, cos theta) parameterisation: equal-area cells, so the density per unit solid angle is
/// also the density in these coordinates.
Vector2f to_spherical(const Vector3f &v) {
    float phi = std::atan2(v.y, v.x);
    if (phi < 0) phi += 2 * Pi;
    return {phi, clamp(v.z, -1.f, 1.f)};
}

Vector3f from_spherical(double phi, double cos_theta) {
    double s = std::sqrt(std::max(0.0, 1 - cos_theta * cos_theta));
    return Vector3f(float(s * std::cos(phi)), float(s * std::sin(phi)), float(cos_theta));
}

HistogramTest sphere_test() { return HistogramTest{40, 40, 0.0, 2 * M_PI, -1.0, 1.0}; }

} // namespace

TEST(Warp, UniformDiskConcentric) {
    // Equal-area polar coordinates (phi, r²): dA = r dr dphi = ½ d(r²) dphi.
    HistogramTest{40, 40, 0.0, 2 * M_PI, 0.0, 1.0}.run(
        [](double phi, double r2) {
            double r = std::sqrt(r2);
            Point2f p(float(r * std::cos(phi)), float(r * std::sin(phi)));
            return 0.5 * double(warp::square_to_uniform_disk_concentric_pdf(p));
        },
        [](const Point2f &u) {
            Point2f p = warp::square_to_uniform_disk_concentric(u);
            float phi = std::atan2(p.y, p.x);
            return Vector2f(phi < 0 ? phi + 2 * Pi : phi, p.x * p.x + p.y * p.y);
        });
    EXPECT_EQ(warp::square_to_uniform_disk_concentric_pdf({0.9f, 0.9f}), 0.f);
    Point2f c = warp::square_to_uniform_disk_concentric({0.5f, 0.5f});
    EXPECT_EQ(c.x, 0.f);
    EXPECT_EQ(c.y, 0.f);
}

TEST(Warp, ConcentricMapIsTheExactMapToWithinFloatRounding) {
    // sin_cos_quarter_pi() against the double-precision functions over the whole range, and
    // the map against the double-precision map on a grid that includes the wedge boundaries
    // (|x| = |y|) and the corners: within 3e-7 (a few ulps of 1), and never outside the disk.
    double worst_trig = 0.0;
    for (int i = -1000; i <= 1000; ++i) {
        const float a = float(Pi / 4.0 * i / 1000.0);
        float s, c;
        warp::sin_cos_quarter_pi(a, s, c);
        worst_trig = std::max({worst_trig, std::abs(double(s) - std::sin(double(a))),
                               std::abs(double(c) - std::cos(double(a)))});
    }
    EXPECT_LT(worst_trig, 1.2e-7);
    double worst_map = 0.0;
    for (int i = 0; i <= 256; ++i)
        for (int j = 0; j <= 256; ++j) {
            const Point2f u(std::min(i / 256.f, OneMinusEpsilon),
                            std::min(j / 256.f, OneMinusEpsilon));
            const Point2f p = warp::square_to_uniform_disk_concentric(u);
            const double x = 2.0 * double(u.x) - 1.0, y = 2.0 * double(u.y) - 1.0;
            double ex = 0.0, ey = 0.0;
            if (std::abs(x) > std::abs(y)) {
                ex = x * std::cos(M_PI / 4 * (y / x));
                ey = x * std::sin(M_PI / 4 * (y / x));
            } else if (y != 0.0) {
                ex = y * std::cos(M_PI / 2 - M_PI / 4 * (x / y));
                ey = y * std::sin(M_PI / 2 - M_PI / 4 * (x / y));
            }
            worst_map = std::max({worst_map, std::abs(p.x - ex), std::abs(p.y - ey)});
            EXPECT_LE(p.x * p.x + p.y * p.y, 1.f + 2e-7f) << u.x << ", " << u.y;
        }
    EXPECT_LT(worst_map, 3e-7);
}

TEST(Warp, UniformTriangle) {
    // Exact cell integrals: the grid's diagonal cells are half inside.
    constexpr int n = 20;
    HistogramTest t{n, n, 0, 1, 0, 1, 1};
    t.run(
        [](double x, double y) {
            int i = int(x * n), j = int(y * n);
            return i + j < n - 1 ? 2.0 : (i + j == n - 1 ? 1.0 : 0.0);
        },
        [](const Point2f &u) { return warp::square_to_uniform_triangle(u); });
    Point2f b = warp::square_to_uniform_triangle({0.999f, 0.999f});
    EXPECT_LE(b.x + b.y, 1.f);
}

TEST(Warp, UniformSphere) {
    sphere_test().run(
        [](double phi, double c) {
            return double(warp::square_to_uniform_sphere_pdf(from_spherical(phi, c)));
        },
        [](const Point2f &u) { return to_spherical(warp::square_to_uniform_sphere(u)); });
}

TEST(Warp, UniformHemisphere) {
    sphere_test().run(
        [](double phi, double c) {
            return double(warp::square_to_uniform_hemisphere_pdf(from_spherical(phi, c)));
        },
        [](const Point2f &u) { return to_spherical(warp::square_to_uniform_hemisphere(u)); });
    EXPECT_EQ(warp::square_to_uniform_hemisphere_pdf({0, 0, -1}), 0.f);
}

TEST(Warp, CosineHemisphere) {
    sphere_test().run(
        [](double phi, double c) {
            return double(warp::square_to_cosine_hemisphere_pdf(from_spherical(phi, c)));
        },
        [](const Point2f &u) { return to_spherical(warp::square_to_cosine_hemisphere(u)); });
    EXPECT_NEAR(warp::square_to_cosine_hemisphere_pdf({0, 0, 1}), InvPi, 1e-7f);
}

TEST(Warp, UniformCone) {
    // cos_cutoff = 0.5 lies on a cell boundary of the 40-cell cos theta axis.
    const float cos_cutoff = 0.5f;
    sphere_test().run(
        [&](double phi, double c) {
            return double(warp::square_to_uniform_cone_pdf(from_spherical(phi, c), cos_cutoff));
        },
        [&](const Point2f &u) {
            return to_spherical(warp::square_to_uniform_cone(u, cos_cutoff));
        });
    EXPECT_EQ(warp::square_to_uniform_cone_pdf({1, 0, 0}, cos_cutoff), 0.f);
}

TEST(Warp, Tent) {
    // 1D: the second coordinate is uniform.
    HistogramTest{40, 1, -1, 1, 0, 1}.run(
        [](double x, double) { return 1.0 - std::abs(x); },
        [](const Point2f &u) { return Vector2f(warp::interval_to_tent(u.x), u.y); });
    EXPECT_NEAR(warp::interval_to_tent(0.5f), 0.f, 1e-6f);
    EXPECT_NEAR(warp::interval_to_tent(0.f), -1.f, 1e-6f);
}

TEST(Warp, IntervalToLinearInvertsTheLinearCdf) {
    // CDF of the density ∝ lerp(x, v0, v1) on [0, 1]: (v0 x + (v1 - v0) x²/2) / ((v0 + v1)/2).
    for (auto [v0, v1] : {std::pair{0.f, 1.f}, {1.f, 0.f}, {0.3f, 1.7f}, {2.f, 0.5f}, {1.f, 1.f}})
        for (float u : {0.f, 0.1f, 0.5f, 0.9f, OneMinusEpsilon}) {
            const float x = warp::interval_to_linear(v0, v1, u);
            const double cdf = (double(v0) * x + (double(v1) - v0) * x * x / 2) / ((v0 + v1) / 2.);
            EXPECT_NEAR(cdf, u, 2e-6) << "v0 " << v0 << " v1 " << v1 << " u " << u;
        }
}

TEST(Warp, IntervalToLinearIsUniformWhereTheDensityIsDegenerate) {
    // Both ends zero (a pole row of an environment map) was 0/0; not finite ends likewise.
    for (auto [v0, v1] : {std::pair{0.f, 0.f}, {-0.f, 0.f}, {Infinity, 1.f}, {NAN, 1.f}})
        for (float u : {0.f, 0.25f, OneMinusEpsilon})
            EXPECT_EQ(warp::interval_to_linear(v0, v1, u), u) << "v0 " << v0 << " v1 " << v1;
    // Whatever the ends, the point lies in [0, 1].
    for (auto [v0, v1] : {std::pair{0.f, 1e-30f}, {1e-30f, 0.f}, {3e38f, 1.f}})
        for (float u : {0.f, 0.5f, OneMinusEpsilon}) {
            const float x = warp::interval_to_linear(v0, v1, u);
            EXPECT_TRUE(x >= 0.f && x <= 1.f) << x;
        }
}

TEST(Warp, WrongDensityIsDetected) {
    // The test harness itself must be able to fail: a uniform density for cosine samples.
    HistogramTest t = sphere_test();
    EXPECT_NONFATAL_FAILURE(
        t.run([](double, double c) { return c >= 0 ? InvTwoPi : 0.0; },
              [](const Point2f &u) { return to_spherical(warp::square_to_cosine_hemisphere(u)); }),
        "chi2");
}
