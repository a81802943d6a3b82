// The envmap emitter: the direction mapping (+Y is the top row, u turns around +Y) and its pdf
// integrating to one. Chi-square tests of its importance sampling on the maps Mitsuba uses for
// the same purpose: tests/chi2/configs.txt.

#include "draws.h"

#include <facet/emitter.h>
#include <facet/image.h>
#include <facet/scene.h>
#include <facet/xml.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <vector>

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

std::shared_ptr<Scene> load(const std::string &xml) {
    return std::dynamic_pointer_cast<Scene>(load_string(xml));
}

/// Radiance the emitter shows towards direction d (seen from the scene).
Color3f look(const Emitter &env, const Vector3f &d) {
    SurfaceInteraction si;
    si.wi = -normalize(d);
    return env.eval(si);
}

/// The direction of (u, v) in the map's frame: θ = πv, φ = 2πu, d = (sin φ sin θ, cos θ,
/// -cos φ sin θ).
Vector3f direction(double u, double v) {
    double phi = 2 * M_PI * u, theta = M_PI * v;
    return Vector3f(float(std::sin(phi) * std::sin(theta)), float(std::cos(theta)),
                    float(-std::cos(phi) * std::sin(theta)));
}

void expect_color_near(const Color3f &a, const Color3f &b, float tol) {
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(a[ch], b[ch], tol) << "channel " << ch;
}

} // namespace

TEST(EnvironmentMap, TopRowIsUpAndUTurnsAroundY) {
    // Left half red, right half green, top row blue.
    std::string map = write_map("quadrants.exr", 8, 4, [](int x, int y) {
        if (y == 0) return Color3f(0, 0, 1);
        return x < 4 ? Color3f(1, 0, 0) : Color3f(0, 1, 0);
    });
    auto scene = load(scene_with(map, R"(<string name="filter_type" value="nearest"/>)"));
    const Emitter &env = *scene->environment_emitters().at(0);
    EXPECT_EQ(look(env, {0, 1, 0}), Color3f(0, 0, 1));
    // u = atan2(x, -z) / 2π: -Z is u = 0 (left edge), +X is u = 1/4 (left half), -X is u = 3/4.
    EXPECT_EQ(look(env, {1, -0.2f, 0}), Color3f(1, 0, 0));
    EXPECT_EQ(look(env, {-1, -0.2f, 0}), Color3f(0, 1, 0));
}

TEST(EnvironmentMap, FirstAndLastRowsLieOnThePoles) {
    // Every row its own colour: the first row is seen exactly at +Y and the last exactly at
    // -Y, from any azimuth; row j is seen exactly at v = j / (H - 1).
    const int H = 5;
    std::string map = write_map("rows.exr", 6, H, [](int, int y) {
        return Color3f(float(y), float(y * y), 1.f + 0.5f * float(y));
    });
    auto scene = load(scene_with(map));
    const Emitter &env = *scene->environment_emitters().at(0);
    auto row = [](int y) { return Color3f(float(y), float(y * y), 1.f + 0.5f * float(y)); };
    EXPECT_EQ(look(env, {0, 1, 0}), row(0));
    EXPECT_EQ(look(env, {0, -1, 0}), row(H - 1));
    for (double u : {0.0, 0.13, 0.5, 0.77})
        for (int j = 0; j < H; ++j)
            expect_color_near(look(env, direction(u, double(j) / (H - 1))), row(j), 2e-4f);
    // Half-way between rows 1 and 2 (v = 3/8): their mean. Pixel centres in latitude
    // ((j + ½)/H) would give 5/8 of row 1 and 3/8 of row 2 here.
    expect_color_near(look(env, direction(0.3, 1.5 / (H - 1))), (row(1) + row(2)) * 0.5f, 2e-4f);
}

TEST(EnvironmentMap, ColumnsAreTexelCentredAndWrapAcrossTheSeam) {
    const int W = 8;
    auto column = [](int x) { return Color3f(float(x), 10.f - float(x), 0.5f); };
    std::string map = write_map("columns.exr", W, 3, [&](int x, int) { return column(x); });
    auto scene = load(scene_with(map));
    const Emitter &env = *scene->environment_emitters().at(0);
    // Column i is seen exactly at u = (i + ½) / W.
    for (int i = 0; i < W; ++i)
        expect_color_near(look(env, direction((i + 0.5) / W, 0.5)), column(i), 2e-4f);
    // On the u = 0 seam (towards -Z) the first and last columns blend half and half, and the
    // radiance is continuous across it.
    Color3f seam = (column(0) + column(W - 1)) * 0.5f;
    expect_color_near(look(env, {0, 0, -1}), seam, 2e-4f);
    expect_color_near(look(env, direction(1e-4, 0.5)), seam, 1e-2f);
    expect_color_near(look(env, direction(1 - 1e-4, 0.5)), seam, 1e-2f);
    // A quarter texel either side: 3/4 of the nearer column.
    expect_color_near(look(env, direction(0.25 / W, 0.5)),
                      column(0) * 0.75f + column(W - 1) * 0.25f, 2e-4f);
    expect_color_near(look(env, direction(1 - 0.25 / W, 0.5)),
                      column(W - 1) * 0.75f + column(0) * 0.25f, 2e-4f);
}

TEST(EnvironmentMap, RefusesMapsSmallerThanTwoByThree) {
    for (auto [w, h] : {std::pair{2, 2}, std::pair{1, 5}, std::pair{16, 2}}) {
        std::string map = write_map("small.exr", w, h, [](int, int) { return Color3f(1.f); });
        try {
            load(scene_with(map));
            ADD_FAILURE() << w << "x" << h << " map accepted";
        } catch (const std::exception &e) {
            EXPECT_NE(std::string(e.what()).find("at least 2x3"), std::string::npos) << e.what();
        }
    }
    std::string map = write_map("smallest.exr", 2, 3, [](int, int) { return Color3f(1.f); });
    EXPECT_NO_THROW(load(scene_with(map)));
}

TEST(EnvironmentMap, KeepsNegativeTexels) {
    std::string map = write_map("negative.exr", 4, 3, [](int x, int y) {
        return (x == 1 && y == 1) ? Color3f(-2.f, 0.5f, 1.f) : Color3f(1.f);
    });
    auto scene = load(scene_with(map));
    const Emitter &env = *scene->environment_emitters().at(0);
    expect_color_near(look(env, direction(1.5 / 4, 0.5)), Color3f(-2.f, 0.5f, 1.f), 1e-5f);
}

TEST(EnvironmentMap, ConstantMapDensityFollowsTheRowGrid) {
    // A constant map's table is sin θ_j on the rows θ_j = πj/(H-1), interpolated linearly in v.
    // On a row the density is then (H - 1) / (2π² Σ_j ½(sin θ_j + sin θ_j+1)), the trapezoid
    // rule's normalisation; for H = 3 (rows at 0, π/2, π) that is 1/π² on the equator, not the
    // 1/4π of a uniform sphere.
    std::string map = write_map("flat3.exr", 4, 3, [](int, int) { return Color3f(2.f); });
    auto scene = load(scene_with(map));
    const Emitter &env = *scene->environment_emitters().at(0);
    Interaction ref;
    DirectionSample ds;
    ds.d = direction(0.3, 0.5);
    EXPECT_NEAR(env.pdf_direction(ref, ds), 1.0 / (M_PI * M_PI), 1e-6);
    // Half-way to the pole the table is ½ (linear in v) while sin θ = sin(π/4).
    ds.d = direction(0.6, 0.25);
    EXPECT_NEAR(env.pdf_direction(ref, ds), 0.5 / (M_PI * M_PI * std::sin(M_PI / 4)), 1e-6);
}

TEST(EnvironmentMap, MisCompensationSamplesOnlyAboveTheMean) {
    // Left half 1, right half 3 (luminance): the mean is 2, so with compensation only the
    // bright half (and the bilinear band along its edges) is sampled.
    std::string map = write_map("halves.exr", 16, 9,
                                [](int x, int) { return x < 8 ? Color3f(1.f) : Color3f(3.f); });
    auto plain = load(scene_with(map));
    auto comp = load(scene_with(map, R"(<boolean name="mis_compensation" value="true"/>)"));
    const Emitter &e0 = *plain->environment_emitters().at(0);
    const Emitter &e1 = *comp->environment_emitters().at(0);
    Interaction ref;
    DirectionSample ds;
    ds.d = direction(4.5 / 16, 0.5); // well inside the dark half
    EXPECT_GT(e0.pdf_direction(ref, ds), 0.f);
    EXPECT_EQ(e1.pdf_direction(ref, ds), 0.f);
    ds.d = direction(12.5 / 16, 0.5); // the bright half
    EXPECT_GT(e1.pdf_direction(ref, ds), e0.pdf_direction(ref, ds));
    // Radiance itself is untouched.
    EXPECT_EQ(look(e0, ds.d), look(e1, ds.d));
    for (float a : {0.1f, 0.4f, 0.8f}) {
        auto [s, w] = e1.sample_direction(ref, Point2f(a, 0.3f + 0.5f * a));
        ASSERT_GT(s.pdf, 0.f);
        // Only cells touching the bright half are sampled (radiance above the dark half's 1).
        EXPECT_GT(look(e1, s.d).r, 1.f) << "sampled a direction in the dark half";
    }
}

TEST(EnvironmentMap, UnsetCompensationMixesMisSamplesOnly) {
    // mis_compensation unset: the light samples weighted by MIS (sample_direction_mis()) follow
    // 90% the compensated table and 10% the plain one, so that their density is that mix of the
    // two emitters' densities; everything else (light samples alone, emitted rays) is the plain
    // table's, bit for bit. Set either way, both samplings are the one table (Mitsuba's).
    std::string map = write_map("halves-mix.exr", 16, 9,
                                [](int x, int) { return x < 8 ? Color3f(1.f) : Color3f(3.f); });
    auto plain = load(scene_with(map, R"(<boolean name="mis_compensation" value="false"/>)"));
    auto comp = load(scene_with(map, R"(<boolean name="mis_compensation" value="true"/>)"));
    auto mix = load(scene_with(map));
    const Emitter &ep = *plain->environment_emitters().at(0);
    const Emitter &ec = *comp->environment_emitters().at(0);
    const Emitter &em = *mix->environment_emitters().at(0);
    Interaction ref;
    for (float ux : {0.02f, 0.2f, 0.45f, 0.7f, 0.93f, 0.999f})
        for (float uy : {0.05f, 0.3f, 0.6f, 0.95f}) {
            SCOPED_TRACE(testing::Message() << "u = (" << ux << ", " << uy << ")");
            const Point2f u(ux, uy);
            auto [dp, wp] = ep.sample_direction(ref, u);
            auto [da, wa] = em.sample_direction(ref, u);
            EXPECT_EQ(da.d, dp.d);
            EXPECT_EQ(da.pdf, dp.pdf);
            EXPECT_EQ(wa, wp);
            EXPECT_EQ(ep.sample_direction_mis(ref, u, Vector3f(0.f)).first.d, dp.d);
            auto [rp, pp] = ep.sample_ray(Point2f(0.3f, 0.6f), u, Wavelengths());
            auto [ra, pa] = em.sample_ray(Point2f(0.3f, 0.6f), u, Wavelengths());
            EXPECT_EQ(ra.d, rp.d);
            EXPECT_EQ(pa, pp);
            auto [dc, wc] = ec.sample_direction(ref, u);
            EXPECT_EQ(ec.sample_direction_mis(ref, u, Vector3f(0.f)).first.d, dc.d);
            EXPECT_EQ(ec.pdf_direction_mis(ref, dc, Vector3f(0.f)), dc.pdf);

            auto [dm, wm] = em.sample_direction_mis(ref, u, Vector3f(0.f));
            ASSERT_GT(dm.pdf, 0.f);
            EXPECT_EQ(em.pdf_direction_mis(ref, dm, Vector3f(0.f)), dm.pdf);
            const float expected =
                0.9f * ec.pdf_direction(ref, dm) + 0.1f * ep.pdf_direction(ref, dm);
            EXPECT_NEAR(dm.pdf, expected, 1e-4f * expected);
            EXPECT_NEAR(wm.r * dm.pdf, look(em, dm.d).r, 1e-5f);
        }
    // The directions compensation never samples get a tenth of the plain table's share of the
    // MIS samples (counted over a fine grid of the variate that picks the cell).
    const int n = 4000;
    int dark_plain = 0, dark_mix = 0;
    for (int k = 0; k < n; ++k) {
        const Point2f u((float(k) + 0.5f) / float(n), 0.5f);
        if (ec.pdf_direction(ref, ep.sample_direction(ref, u).first) == 0.f) ++dark_plain;
        if (ec.pdf_direction(ref, em.sample_direction_mis(ref, u, Vector3f(0.f)).first) == 0.f)
            ++dark_mix;
    }
    EXPECT_GT(dark_plain, n / 10);
    EXPECT_NEAR(double(dark_mix) / n, 0.1 * dark_plain / n, 0.005);
}

namespace {
/// Sides to test: the axes, the cube's edges and corners (where the bins of sides meet) and
/// random ones.
std::vector<Vector3f> test_sides() {
    std::vector<Vector3f> sides;
    for (int x = -1; x <= 1; ++x)
        for (int y = -1; y <= 1; ++y)
            for (int z = -1; z <= 1; ++z)
                if (x || y || z) sides.push_back(normalize(Vector3f(float(x), float(y), float(z))));
    PCG32 rng(5);
    for (int k = 0; k < 40; ++k) {
        Vector3f v = next_vector3f(rng) * 2.f - Vector3f(1.f);
        if (dot(v, v) > 1e-2f) sides.push_back(normalize(v));
    }
    return sides;
}
} // namespace

TEST(EnvironmentMap, MisSamplesWithASideCoverWhatItSees) {
    // Told a side (no light counts from directions d with dot(d, side) <= 0), the MIS light
    // samples leave out the map's parts wholly behind it. What they must keep: every direction
    // in front of the side that has light has a density; a sample's density is
    // pdf_direction_mis()'s with the same side and its weight the radiance over it; the density
    // integrates to one over the sphere; and fewer samples fall behind the side than without it.
    // A map with structure at several sizes (a 2-pixel-wide map: blocks of half a turn), and
    // one turned by to_world.
    auto sky = [](int x, int y) {
        return Color3f(0.2f + 0.05f * float(y % 7) + (x % 13 == 3 ? 5.f : 0.f), 0.5f, 1.f);
    };
    const std::string rotated =
        R"(<transform name="to_world"><rotate x="1" y="0.5" z="0.2" angle="50"/></transform>)";
    struct Case {
        std::string map, extra;
        bool narrow_blocks; ///< blocks small enough that many lie wholly behind a side
    };
    const std::vector<Case> cases = {{write_map("side-2x3.exr", 2, 3, sky), "", false},
                                     {write_map("side-5x4.exr", 5, 4, sky), "", false},
                                     {write_map("side-64x32.exr", 64, 32, sky), "", true},
                                     {write_map("side-64x32r.exr", 64, 32, sky), rotated, true},
                                     {write_map("side-200x90.exr", 200, 90, sky), "", true}};
    PCG32 rng(17);
    for (const Case &c : cases) {
        SCOPED_TRACE(c.map + " " + c.extra);
        auto scene = load(scene_with(c.map, c.extra));
        const Emitter &env = *scene->environment_emitters().at(0);
        Interaction ref;
        double behind_with = 0.0, behind_without = 0.0;
        int samples = 0;
        for (const Vector3f &side : test_sides()) {
            SCOPED_TRACE(testing::Message() << "side " << side);
            for (int k = 0; k < 64; ++k) {
                const Point2f u = next_point2f(rng);
                auto [ds, w] = env.sample_direction_mis(ref, u, side);
                if (ds.pdf > 0.f) {
                    EXPECT_EQ(env.pdf_direction_mis(ref, ds, side), ds.pdf);
                    SurfaceInteraction seen; // the sample's own direction, not renormalised
                    seen.wi = -ds.d;
                    const float radiance = env.eval(seen).r;
                    EXPECT_NEAR(w.r * ds.pdf, radiance, 1e-6f * radiance);
                    behind_with += dot(ds.d, side) <= 0.f ? 1.0 : 0.0;
                }
                auto [d0, w0] = env.sample_direction_mis(ref, u, Vector3f(0.f));
                behind_without += d0.pdf > 0.f && dot(d0.d, side) <= 0.f ? 1.0 : 0.0;
                ++samples;
                // A direction in front of the side with light has a density.
                DirectionSample probe;
                probe.d = normalize(next_vector3f(rng) * 2.f - Vector3f(1.f));
                if (dot(probe.d, side) > 1e-4f &&
                    env.pdf_direction_mis(ref, probe, Vector3f(0.f)) > 0.f) {
                    EXPECT_GT(env.pdf_direction_mis(ref, probe, side), 0.f) << probe.d;
                }
            }
        }
        // Blocks of a map a few pixels wide span a large part of the sphere: few lie wholly
        // behind a side.
        if (c.narrow_blocks)
            EXPECT_LT(behind_with, 0.6 * behind_without) << samples << " samples";
        else
            EXPECT_LE(behind_with, 1.05 * behind_without) << samples << " samples";
        // The density over the sphere, on a grid of (cos θ, φ) cells (midpoints), for a few sides.
        for (const Vector3f &side : {Vector3f(0.f, 1.f, 0.f), normalize(Vector3f(1.f, -2.f, 0.5f)),
                                     normalize(Vector3f(-1.f, 1.f, 1.f))}) {
            const int n = 400;
            double integral = 0.0;
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < 2 * n; ++j) {
                    const double z = -1.0 + 2.0 * (i + 0.5) / n, phi = M_PI * (j + 0.5) / n;
                    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
                    DirectionSample ds;
                    ds.d = Vector3f(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z));
                    integral += env.pdf_direction_mis(ref, ds, side);
                }
            integral *= 4.0 * M_PI / (2.0 * n * n);
            EXPECT_NEAR(integral, 1.0, 0.01) << "side " << side;
        }
    }
}

TEST(EnvironmentMap, MisCompensationIsSkippedForNearConstantMaps) {
    // mean - min = 0.5 % of the mean: compensation would leave almost nothing, so it is off.
    std::string map = write_map("nearly-flat.exr", 8, 5, [](int x, int y) {
        return (x == 3 && y == 2) ? Color3f(1.f + 0.005f * 40.f) : Color3f(1.f);
    });
    auto plain = load(scene_with(map));
    auto comp = load(scene_with(map, R"(<boolean name="mis_compensation" value="true"/>)"));
    Interaction ref;
    DirectionSample ds;
    for (double u : {0.1, 0.45, 0.9}) {
        ds.d = direction(u, 0.6);
        EXPECT_EQ(plain->environment_emitters().at(0)->pdf_direction(ref, ds),
                  comp->environment_emitters().at(0)->pdf_direction(ref, ds));
    }
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

// Chi-square tests of its importance sampling (a single bright pixel, a constant map, a tiny 3x2
// map, a rotated HDR sky, uniform sampling): the envmap lines of tests/chi2/configs.txt.

namespace {
/// A sky whose light is at the zenith: the cells next to the +Y pole carry most of the weight.
Color3f bright_zenith(int, int y) { return y < 2 ? Color3f(50.f, 60.f, 70.f) : Color3f(0.1f); }

/// Variates on the edges of the unit square and inside it: 0 exactly (which a sampler returns
/// with probability 2^-24 per dimension), the smallest steps above it, the middle, 1 - ε.
const std::vector<float> &edge_variates() {
    static const std::vector<float> v = {0.f,   0x1p-149f, 0x1p-24f, 1e-7f,  0.001f,
                                         0.25f, 0.5f,      0.75f,    0.999f, OneMinusEpsilon};
    return v;
}

void expect_valid_direction_sample(const DirectionSample &ds, const Color3f &w, float ux,
                                   float uy) {
    SCOPED_TRACE(::testing::Message() << "u = (" << ux << ", " << uy << ")");
    ASSERT_TRUE(std::isfinite(ds.d.x) && std::isfinite(ds.d.y) && std::isfinite(ds.d.z));
    EXPECT_NEAR(norm(ds.d), 1.f, 1e-5f);
    EXPECT_TRUE(std::isfinite(ds.pdf) && ds.pdf >= 0.f) << "pdf " << ds.pdf;
    EXPECT_TRUE(w.is_finite()) << w.r << " " << w.g << " " << w.b;
    // The pole itself has density zero (sin θ = 0 on the first row): a sample that lands on it
    // is a failed one, with weight zero.
    if (ds.pdf == 0.f) {
        EXPECT_EQ(w, Color3f(0.f));
    }
}
} // namespace

TEST(EnvironmentMap, SamplesOnTheEdgesOfTheSquareAreValid) {
    // u.y = 0 puts the sample on the first row of its cell; in a cell next to the pole that row
    // has zero density, and the inverse CDF along it was 0/0 (a NaN direction, then a read
    // outside the map). Every edge variate must give a unit direction, a finite positive pdf
    // and a finite weight, for sample_direction() and sample_ray() alike.
    for (bool bilinear : {true, false}) {
        std::string map = write_map("zenith.exr", 16, 8, bright_zenith);
        auto scene = load(
            scene_with(map, bilinear ? "" : R"(<string name="filter_type" value="nearest"/>)"));
        const Emitter &env = *scene->environment_emitters().at(0);
        Interaction ref;
        for (float ux : edge_variates())
            for (float uy : edge_variates()) {
                auto [ds, w] = env.sample_direction(ref, Point2f(ux, uy));
                expect_valid_direction_sample(ds, w, ux, uy);
                EXPECT_EQ(env.pdf_direction(ref, ds), ds.pdf);
                auto [dm, wm] = env.sample_direction_mis(ref, Point2f(ux, uy), Vector3f(0.f));
                expect_valid_direction_sample(dm, wm, ux, uy);
                EXPECT_EQ(env.pdf_direction_mis(ref, dm, Vector3f(0.f)), dm.pdf);
                auto [ray, power] =
                    env.sample_ray(Point2f(0.5f, 0.5f), Point2f(ux, uy), Wavelengths());
                EXPECT_TRUE(std::isfinite(ray.d.x) && std::isfinite(ray.o.x));
                EXPECT_TRUE(power.is_finite());
            }
    }
}

TEST(EnvironmentMap, VeryDarkAndVeryBrightMapsSampleLikeTheirUnitTwin) {
    // Sampling depends on the map only up to a constant factor: a map scaled by 2^-84 (whose
    // table values squared underflow) or by 2^84 (whose squares overflow) must pick the same
    // directions with the same densities as the unscaled one, bit for bit (powers of two, so
    // that the scaled pixels are exact).
    std::string map = write_map("zenith-scaled.exr", 16, 8, bright_zenith);
    auto unit = load(scene_with(map));
    const Emitter &e1 = *unit->environment_emitters().at(0);
    for (const char *scale :
         {"5.1698788284564229679463043254372e-26", "19342813113834066795298816"}) {
        SCOPED_TRACE(scale);
        auto scaled =
            load(scene_with(map, std::string(R"(<float name="scale" value=")") + scale + "\"/>"));
        const Emitter &es = *scaled->environment_emitters().at(0);
        Interaction ref;
        for (float ux : edge_variates())
            for (float uy : edge_variates()) {
                auto [d1, w1] = e1.sample_direction(ref, Point2f(ux, uy));
                auto [ds, ws] = es.sample_direction(ref, Point2f(ux, uy));
                expect_valid_direction_sample(ds, ws, ux, uy);
                EXPECT_EQ(ds.d, d1.d) << "u = (" << ux << ", " << uy << ")";
                EXPECT_EQ(ds.pdf, d1.pdf) << "u = (" << ux << ", " << uy << ")";
                auto [m1, v1] = e1.sample_direction_mis(ref, Point2f(ux, uy), Vector3f(0.f));
                auto [ms, vs] = es.sample_direction_mis(ref, Point2f(ux, uy), Vector3f(0.f));
                expect_valid_direction_sample(ms, vs, ux, uy);
                EXPECT_EQ(ms.d, m1.d) << "MIS, u = (" << ux << ", " << uy << ")";
                EXPECT_EQ(ms.pdf, m1.pdf) << "MIS, u = (" << ux << ", " << uy << ")";
            }
    }
}
