// The sdfgrid shape: the .vol reader (layout, x-fastest order, the file's bounding box ignored as
// in Mitsuba 3, and every malformed header refused), exact hits of the trilinear interpolant
// (a planar field hit to float precision, Mitsuba's own diagonal-plane case, rays starting
// inside, grazing, and running along voxel faces and edges), a sphere's sampled SDF against the
// analytic sphere (silhouette, distance, both normal modes), the bounding box and the parameters
// Mitsuba refuses.
#include "draws.h"

#include <facet/interaction.h>
#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/random.h>
#include <facet/scene.h>
#include <facet/shape.h>
#include <facet/xml.h>

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <string>
#include <unistd.h>
#include <vector>

using namespace facet;

namespace {

std::string temp_dir() {
    static std::string dir = [] {
        std::string d =
            std::string(::testing::TempDir()) + "facet_sdfgrid_" + std::to_string(::getpid());
        ::mkdir(d.c_str(), 0755);
        return d;
    }();
    return dir;
}

struct VolHeader {
    std::string magic = "VOL";
    int version = 3;
    int32_t encoding = 1;
    int32_t res[3] = {2, 2, 2};
    int32_t channels = 1;
    float bbox[6] = {0, 0, 0, 1, 1, 1};
};

void put_i32(std::string &s, int32_t v) { s.append(reinterpret_cast<const char *>(&v), 4); }
void put_f32(std::string &s, float v) { s.append(reinterpret_cast<const char *>(&v), 4); }

std::string write_vol(const std::string &name, const VolHeader &h,
                      const std::vector<float> &values) {
    std::string bytes = h.magic;
    bytes.push_back(char(h.version));
    put_i32(bytes, h.encoding);
    for (int32_t r : h.res) put_i32(bytes, r);
    put_i32(bytes, h.channels);
    for (float b : h.bbox) put_f32(bytes, b);
    for (float v : values) put_f32(bytes, v);
    std::string path = temp_dir() + "/" + name;
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
}

/// A grid of nx·ny·nz samples of `f` at the object-space sample positions (i/(nx-1), ...),
/// written x fastest.
std::string write_field(const std::string &name, int nx, int ny, int nz,
                        const std::function<double(double, double, double)> &f,
                        const float bbox[6] = nullptr) {
    VolHeader h;
    h.res[0] = nx;
    h.res[1] = ny;
    h.res[2] = nz;
    if (bbox) std::memcpy(h.bbox, bbox, sizeof h.bbox);
    std::vector<float> v;
    for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y)
            for (int x = 0; x < nx; ++x)
                v.push_back(
                    float(f(double(x) / (nx - 1), double(y) / (ny - 1), double(z) / (nz - 1))));
    return write_vol(name, h, v);
}

std::shared_ptr<Scene> grid_scene(const std::string &path, const std::string &extra = "") {
    std::string xml = "<scene version=\"3.0.0\"><shape type=\"sdfgrid\" id=\"grid\">"
                      "<string name=\"filename\" value=\"" +
                      path + "\"/>" + extra + "</shape></scene>";
    return std::dynamic_pointer_cast<Scene>(load_string(xml));
}

std::string error_of(const std::function<void()> &f) {
    try {
        f();
    } catch (const Error &e) {
        return e.what();
    }
    ADD_FAILURE() << "expected a facet::Error";
    return "";
}

void expect_vec_near(const Vector3f &a, const Vector3f &b, float tol, const char *what) {
    EXPECT_NEAR(a.x, b.x, tol) << what;
    EXPECT_NEAR(a.y, b.y, tol) << what;
    EXPECT_NEAR(a.z, b.z, tol) << what;
}

// A plane n·x + d in object space, sampled exactly (the trilinear interpolant of a linear
// function is the function itself).
const Vector3d PLANE_N = normalize(Vector3d(0.3, -0.5, 0.8));
const double PLANE_D = -0.1;
double plane_field(double x, double y, double z) {
    return PLANE_N.x * x + PLANE_N.y * y + PLANE_N.z * z + PLANE_D;
}

} // namespace

TEST(SDFGrid, MitsubaDiagonalPlane) {
    // Mitsuba 3's own test case: a 2×2×2 grid whose zero set is the plane y + z = 1.
    VolHeader h;
    const float s = float(std::sqrt(2.0) / 2.0);
    std::string path = write_vol("diagonal.vol", h, {-s, -s, 0, 0, 0, 0, s, s});
    for (const char *translate : {"0, 0, 0", "-0.5, 0.5, 0.2"}) {
        SCOPED_TRACE(translate);
        auto scene = grid_scene(path, std::string("<transform name=\"to_world\"><translate "
                                                  "value=\"") +
                                          translate + "\"/></transform>");
        float tx, ty, tz;
        std::sscanf(translate, "%f, %f, %f", &tx, &ty, &tz);
        for (int i = 0; i < 10; ++i)
            for (int j = 0; j < 10; ++j) {
                float x = -2.f + 4.f * float(i) / 9.f, y = -2.f + 4.f * float(j) / 9.f;
                Ray ray(Point3f(tx + x, ty + y, tz + 3.f), Vector3f(0, 0, -1));
                bool expected = x >= 0.f && x <= 1.f && y >= 0.f && y <= 1.f;
                EXPECT_EQ(scene->ray_test(ray), expected) << x << ", " << y;
                SurfaceInteraction si;
                ASSERT_EQ(scene->ray_intersect(ray, si), expected) << x << ", " << y;
                if (!expected) continue;
                EXPECT_NEAR(si.t, 2.f + y, 1e-5f);
                expect_vec_near(si.n, Vector3f(0, s, s), 1e-5f, "normal");
                expect_vec_near(si.p, ray.o - Vector3f(0, 0, 2.f + y), 1e-5f, "position");
            }
    }
}

TEST(SDFGrid, PlanarFieldIsHitExactly) {
    // Rotated, unevenly scaled and moved: the world-space plane is known in closed form.
    std::string path = write_field("plane.vol", 9, 7, 11, plane_field);
    const char *xform = R"(<transform name="to_world"><scale x="2" y="1.5" z="3"/>
        <rotate x="1" y="1" z="0" angle="25"/><translate x="0.3" y="-1" z="2"/></transform>)";
    for (const char *normals : {"analytic", "smooth"}) {
        SCOPED_TRACE(normals);
        auto scene = grid_scene(path, std::string(xform) + "<string name=\"normals\" value=\"" +
                                          normals + "\"/>");
        const Shape &shape = *scene->shapes().at(0);
        Transform to_world = Transform::translate(Vector3f(0.3f, -1.f, 2.f)) *
                             Transform::rotate(Vector3f(1, 1, 0), 25.f) *
                             Transform::scale(Vector3f(2.f, 1.5f, 3.f));
        // World plane: n·(M⁻¹(p − c)) + d = 0, normal ∝ M⁻ᵀ n.
        Transform to_object = to_world.inverse();
        Normal3f world_n = normalize(to_world.apply_normal(Normal3f(PLANE_N)));
        PCG32 rng(7);
        int hits = 0, smooth_checked = 0;
        for (int k = 0; k < 400; ++k) {
            // A point on the plane inside the grid, approached from a random direction.
            const Point2f q = next_point2f(rng);
            Vector3d x(q.x, q.y, 0.0);
            x.z = -(PLANE_N.x * x.x + PLANE_N.y * x.y + PLANE_D) / PLANE_N.z;
            if (x.z < 0.02 || x.z > 0.98) continue;
            Point3f target = to_world.apply_point(Point3f(x));
            Vector3f d = normalize(next_vector3f(rng) - Vector3f(0.5f));
            if (std::abs(dot(d, world_n)) < 0.2f) continue;
            float dist = 4.f + 3.f * rng.next_float();
            Ray ray(target - d * dist, d);
            // The exact hit distance of the world-space plane, in double.
            Vector3d xo(to_object.apply_point(ray.o)), xd(to_object.apply_vector(ray.d));
            double t_exact = -(dot(PLANE_N, xo) + PLANE_D) / dot(PLANE_N, xd);
            SurfaceInteraction si;
            ASSERT_TRUE(scene->ray_intersect(ray, si)) << "ray " << k;
            ++hits;
            EXPECT_NEAR(si.t, t_exact, 1e-5 * t_exact) << "ray " << k;
            expect_vec_near(si.n, world_n, 1e-5f, "geometric normal");
            // The smooth normal of a linear field equals its gradient away from the upper
            // grid faces, where Mitsuba's clamped differences vanish.
            bool interior = x.x < 0.8 && x.y < 0.8 && x.z < 0.85;
            if (std::string(normals) == "analytic" || interior) {
                expect_vec_near(si.sh_frame.n, world_n, 1e-5f, "shading normal");
                smooth_checked += std::string(normals) == "smooth";
            }
            EXPECT_EQ(si.shape, &shape);
        }
        EXPECT_GT(hits, 150);
        if (std::string(normals) == "smooth") {
            EXPECT_GT(smooth_checked, 30);
        }
    }
}

TEST(SDFGrid, RaysAlongVoxelFacesAndEdges) {
    // 9 samples per axis: the voxel faces lie at multiples of 1/8, exact in binary.
    std::string path = write_field("plane_faces.vol", 9, 9, 9, plane_field);
    auto scene = grid_scene(path, "<string name=\"normals\" value=\"analytic\"/>");
    Normal3f n = Normal3f(PLANE_N);
    for (double fx : {0.25, 0.5, 0.625})
        for (double fy : {0.375, 0.5, 0.4321}) {
            // Straight down along x = fx (a face) and, for fy on a grid line, along an edge.
            Ray ray(Point3f(float(fx), float(fy), 2.f), Vector3f(0, 0, -1));
            double z = -(PLANE_N.x * fx + PLANE_N.y * fy + PLANE_D) / PLANE_N.z;
            SurfaceInteraction si;
            ASSERT_TRUE(scene->ray_intersect(ray, si)) << fx << ", " << fy;
            EXPECT_NEAR(si.t, 2.0 - z, 1e-5) << fx << ", " << fy;
            expect_vec_near(si.n, n, 1e-5f, "normal");
            EXPECT_TRUE(scene->ray_test(ray));
        }
    // Within the face y = 0.5, slanted: crosses voxel edges and faces on the way.
    for (int k = 0; k < 20; ++k) {
        Vector3f d = normalize(Vector3f(0.1f * float(k) - 1.f, 0.f, -1.f));
        Ray ray(Point3f(0.5f, 0.5f, 1.5f), d);
        double t = -(dot(PLANE_N, Vector3d(ray.o)) + PLANE_D) / dot(PLANE_N, Vector3d(d));
        Point3f p = ray(float(t));
        bool inside_grid = p.x >= 0.f && p.x <= 1.f;
        SurfaceInteraction si;
        EXPECT_EQ(scene->ray_intersect(ray, si), inside_grid) << k;
        if (inside_grid) {
            EXPECT_NEAR(si.t, t, 1e-5 * t) << k;
        }
    }
}

TEST(SDFGrid, AsymmetricGridKeepsXFastestOrderAndIgnoresFileBounds) {
    // One negative sample at (2, 1, 3) of a 5 × 4 × 6 grid: the surface surrounds the object
    // point (2/4, 1/3, 3/5), and nowhere else. The file's bounding box is nonsense on purpose:
    // as in Mitsuba, the grid always fills [0, 1]³ before to_world.
    const int nx = 5, ny = 4, nz = 6;
    VolHeader h;
    h.res[0] = nx;
    h.res[1] = ny;
    h.res[2] = nz;
    const float bogus[6] = {-5, -6, -7, 8, 9, 10};
    std::memcpy(h.bbox, bogus, sizeof bogus);
    std::vector<float> v(nx * ny * nz, 1.f);
    v[(3 * ny + 1) * nx + 2] = -1.f;
    std::string path = write_vol("asymmetric.vol", h, v);
    auto scene = grid_scene(path, R"(<transform name="to_world"><scale x="4" y="3" z="5"/>
        <translate x="1" y="2" z="3"/></transform>)");
    const BoundingBox3f box = scene->shapes().at(0)->bbox();
    expect_vec_near(box.min, Vector3f(1, 2, 3), 1e-6f, "bbox min");
    expect_vec_near(box.max, Vector3f(5, 5, 8), 1e-6f, "bbox max");

    // The sample sits at world (1 + 4·2/4, 2 + 3·1/3, 3 + 5·3/5) = (3, 3, 6).
    const Point3f c(3.f, 3.f, 6.f);
    SurfaceInteraction si;
    ASSERT_TRUE(scene->ray_intersect(Ray(Point3f(3.f, 3.f, 20.f), Vector3f(0, 0, -1)), si));
    // Along z the value goes 1 → -1 over one voxel (5/5 = 1 world unit): zero half-way.
    EXPECT_NEAR(si.t, 20.f - 6.5f, 1e-5f);
    // On the voxel edge through the sample the analytic normal depends on the voxel, but it
    // points away from the sample.
    EXPECT_GT(si.n.z, 0.5f);
    ASSERT_TRUE(scene->ray_intersect(Ray(Point3f(-10.f, 3.f, 6.f), Vector3f(1, 0, 0)), si));
    EXPECT_NEAR(si.t, 10.f + 2.5f, 1e-5f); // voxels of 1 world unit along x
    ASSERT_TRUE(scene->ray_intersect(Ray(Point3f(3.f, -10.f, 6.f), Vector3f(0, 1, 0)), si));
    EXPECT_NEAR(si.t, 13.f - 0.5f, 1e-5f); // voxels of 1 world unit along y
    // The transposed orders put the sample elsewhere: nothing there.
    EXPECT_FALSE(
        scene->ray_test(Ray(Point3f(1.f + 4.f * 3.f / 4.f, 3.f, 20.f), Vector3f(0, 0, -1))));
    EXPECT_FALSE(
        scene->ray_test(Ray(Point3f(3.f, 2.f + 3.f * 2.f / 3.f, 20.f), Vector3f(0, 0, -1))));
    EXPECT_FALSE(scene->ray_test(Ray(c + Vector3f(1.5f, 0, 0), Vector3f(0, 0, -1))));
}

TEST(SDFGrid, SphereFieldMatchesAnalyticSphere) {
    // The SDF of a sphere of radius 0.3 at the cube's centre on 33³ samples, scaled by 2.
    const double r = 0.3;
    auto sdf = [&](double x, double y, double z) {
        return std::sqrt((x - 0.5) * (x - 0.5) + (y - 0.5) * (y - 0.5) + (z - 0.5) * (z - 0.5)) - r;
    };
    std::string path = write_field("sphere.vol", 33, 33, 33, sdf);
    const char *xform = R"(<transform name="to_world"><scale value="2"/></transform>)";
    const Point3f center(1.f, 1.f, 1.f);
    const float radius = 0.6f, voxel = 2.f / 32.f;
    double analytic_angle = 0;
    for (const char *normals : {"analytic", "smooth"}) {
        SCOPED_TRACE(normals);
        auto scene = grid_scene(path, std::string(xform) + "<string name=\"normals\" value=\"" +
                                          normals + "\"/>");
        double max_t_err = 0, max_angle = 0;
        int agree = 0, tested = 0;
        for (int i = 0; i < 64; ++i)
            for (int j = 0; j < 64; ++j) {
                float x = 0.2f + 1.6f * (float(i) + 0.5f) / 64.f,
                      y = 0.2f + 1.6f * (float(j) + 0.5f) / 64.f;
                float rho = std::hypot(x - center.x, y - center.y);
                // Rays within a tenth of a voxel of the silhouette may go either way.
                if (std::abs(rho - radius) < 0.1f * voxel) continue;
                ++tested;
                Ray ray(Point3f(x, y, 5.f), Vector3f(0, 0, -1));
                SurfaceInteraction si;
                bool hit = scene->ray_intersect(ray, si);
                agree += hit == (rho < radius);
                if (!hit || !(rho < radius)) continue;
                float t_exact = 5.f - center.z - std::sqrt(radius * radius - rho * rho);
                float cos_theta = std::sqrt(1.f - (rho / radius) * (rho / radius));
                if (cos_theta < 0.5f) continue;
                max_t_err = std::max(max_t_err, double(std::abs(si.t - t_exact)));
                Vector3f n_exact = normalize(ray(t_exact) - center);
                max_angle = std::max(max_angle,
                                     double(std::acos(std::min(1.f, dot(si.sh_frame.n, n_exact)))));
            }
        EXPECT_EQ(agree, tested) << "silhouette";
        // The trilinear interpolant of |x| - r errs by about h²/8 · (2/r) (h the voxel): 8e-4
        // in object units here, at most twice that along rays with cos θ >= 0.5, and twice
        // again for the scale of 2: 3.3e-3, with some slack.
        EXPECT_LT(max_t_err, 5e-3) << "distance";
        // The gradient of the interpolant turns by about h/r within a voxel (0.1 rad); the
        // smooth normals blend it away.
        if (std::string(normals) == "analytic") {
            EXPECT_LT(max_angle, 0.1) << "analytic normal (radians)";
            analytic_angle = max_angle;
        } else {
            EXPECT_LT(max_angle, 0.02) << "smooth normal (radians)";
            EXPECT_LT(max_angle, 0.5 * analytic_angle);
        }
        std::printf("%s normals: max distance error %.2e, max normal error %.4f rad\n", normals,
                    max_t_err, max_angle);
    }
}

TEST(SDFGrid, StartsInsideAndGrazes) {
    const double r = 0.3;
    auto sdf = [&](double x, double y, double z) {
        return std::sqrt((x - 0.5) * (x - 0.5) + (y - 0.5) * (y - 0.5) + (z - 0.5) * (z - 0.5)) - r;
    };
    std::string path = write_field("sphere_inside.vol", 33, 33, 33, sdf);
    auto scene = grid_scene(path, "<string name=\"normals\" value=\"analytic\"/>");
    // From the centre outwards: the first hit is the sphere at distance r, normal outwards.
    PCG32 rng(3);
    for (int k = 0; k < 50; ++k) {
        Vector3f d = normalize(next_vector3f(rng) - Vector3f(0.5f));
        SurfaceInteraction si;
        ASSERT_TRUE(scene->ray_intersect(Ray(Point3f(0.5f), d), si));
        EXPECT_NEAR(si.t, 0.3f, 1e-3f);
        EXPECT_GT(dot(si.n, d), 0.99f);
    }
    // A ray from the centre that ends before the surface hits nothing.
    EXPECT_FALSE(scene->ray_test(Ray(Point3f(0.5f), Vector3f(1, 0, 0), 0.f, 0.29f)));
    // A ray starting beyond the first crossing (mint) finds the far side.
    SurfaceInteraction si;
    ASSERT_TRUE(scene->ray_intersect(Ray(Point3f(0.5f, 0.5f, 2.f), Vector3f(0, 0, -1), 1.5f), si));
    EXPECT_NEAR(si.t, 1.8f, 1e-3f);
    // Grazing: passing just outside misses, just inside hits near the tangent point.
    EXPECT_FALSE(scene->ray_test(Ray(Point3f(0.5f + 0.31f, 0.5f, 2.f), Vector3f(0, 0, -1))));
    ASSERT_TRUE(
        scene->ray_intersect(Ray(Point3f(0.5f + 0.29f, 0.5f, 2.f), Vector3f(0, 0, -1)), si));
    EXPECT_NEAR(si.t, 1.5f - std::sqrt(0.3f * 0.3f - 0.29f * 0.29f), 5e-3f);
    // Nearly parallel to a planar field: still the exact hit.
    std::string plane =
        write_field("plane_graze.vol", 9, 9, 9, [](double, double, double z) { return z - 0.5; });
    auto flat = grid_scene(plane);
    Vector3f d = normalize(Vector3f(1.f, 0.f, -1e-3f));
    Ray ray(Point3f(-0.2f, 0.3f, 0.5005f), d);
    ASSERT_TRUE(flat->ray_intersect(ray, si));
    EXPECT_NEAR(ray(si.t).z, 0.5f, 1e-6f);
    EXPECT_NEAR(ray(si.t).x, 0.3f, 1e-3f);
    EXPECT_FALSE(flat->ray_test(Ray(Point3f(-0.2f, 0.3f, 0.5005f), Vector3f(1, 0, 0))));
}

TEST(SDFGrid, Parameters) {
    std::string path =
        write_field("params.vol", 3, 3, 3, [](double x, double, double) { return x - 0.5; });
    // Defaults: smooth normals; bbox = to_world([0,1]³) (Mitsuba's bbox test).
    auto scene = grid_scene(path, R"(<transform name="to_world"><scale x="2" y="2.5" z="1"/>
        <translate x="1.3" y="-3" z="5"/></transform>)");
    const Shape &shape = *scene->shapes().at(0);
    EXPECT_NE(shape.to_string().find("normals=smooth"), std::string::npos);
    expect_vec_near(shape.bbox().min, Vector3f(1.3f, -3.f, 5.f), 1e-5f, "bbox min");
    expect_vec_near(shape.bbox().max, Vector3f(3.3f, -0.5f, 6.f), 1e-5f, "bbox max");
    EXPECT_EQ(shape.surface_area(), 0.f);

    std::string e = error_of([&] { grid_scene(path, R"(<string name="normals" value="flat"/>)"); });
    EXPECT_NE(e.find("\"smooth\" or \"analytic\""), std::string::npos) << e;
    e = error_of([&] { load_string(R"(<scene version="3.0.0"><shape type="sdfgrid"/></scene>)"); });
    EXPECT_NE(e.find("filename"), std::string::npos) << e;
    e = error_of([&] { grid_scene(path, R"(<emitter type="area"/>)"); });
    EXPECT_NE(e.find("area emitter"), std::string::npos) << e;
    e = error_of([&] {
        grid_scene(path, R"(<transform name="to_world"><scale x="0" y="1" z="1"/></transform>)");
    });
    EXPECT_NE(e.find("singular"), std::string::npos) << e;
}

TEST(SDFGrid, HostileFilesAreRefused) {
    std::vector<float> eight = {-1, 1, -1, 1, -1, 1, -1, 1};
    auto refuse = [&](const std::string &path, const std::string &expected) {
        std::string e = error_of([&] { grid_scene(path); });
        EXPECT_NE(e.find(expected), std::string::npos) << e;
    };
    VolHeader h;
    h.magic = "VOX";
    refuse(write_vol("magic.vol", h, eight), "does not start with \"VOL\"");
    h = VolHeader();
    h.version = 2;
    refuse(write_vol("version.vol", h, eight), "version 2, expected version 3");
    h = VolHeader();
    h.encoding = 2;
    refuse(write_vol("encoding.vol", h, eight), "encoding 2");
    h = VolHeader();
    h.channels = 3;
    std::vector<float> rgb(24, 1.f);
    refuse(write_vol("channels.vol", h, rgb), "3 channels, expected 1");
    h = VolHeader();
    refuse(write_vol("short.vol", h, {1, 2, 3}), "bytes follow its header");
    refuse(write_vol("long.vol", h, std::vector<float>(9, 1.f)), "bytes follow its header");
    h.res[0] = h.res[1] = h.res[2] = 0x7fffffff; // 2^93 bytes: the product overflows
    refuse(write_vol("overflow.vol", h, eight), "more than 2^64");
    h.res[0] = 65536;
    h.res[1] = 65536;
    h.res[2] = 2;
    refuse(write_vol("huge.vol", h, eight), "bytes follow its header");
    h = VolHeader();
    h.res[1] = 1;
    refuse(write_vol("flat.vol", h, {1, 2, 3, 4}), "at least 2 samples");
    h.res[1] = -4;
    refuse(write_vol("negative.vol", h, eight), "yres = -4");
    h = VolHeader();
    std::vector<float> nan = eight;
    nan[5] = std::nanf("");
    refuse(write_vol("nan.vol", h, nan), "non-finite value at sample (1, 0, 1)");
    refuse(write_vol("empty.vol", h, std::vector<float>(8, 1.f)), "no surface");
    refuse(write_vol("truncated.vol", h, {}), "bytes follow its header");
    {
        std::string p = temp_dir() + "/header_only.vol";
        std::ofstream(p, std::ios::binary) << "VOL";
        refuse(p, "less than the 48-byte");
    }
    refuse(temp_dir(), "is not a regular file");
    refuse(temp_dir() + "/missing.vol", "cannot open");
}

TEST(SDFGrid, ClosedSurfaceHasNoPinholes) {
    // Rays aimed at the inside of a closed surface must all hit it, also those that run exactly
    // along the grid's sample planes and lines, where neighbouring voxels share faces and edges.
    const int n = 17;
    auto sdf = [](double x, double y, double z) {
        return std::sqrt((x - 0.5) * (x - 0.5) + (y - 0.5) * (y - 0.5) + (z - 0.5) * (z - 0.5)) -
               0.375;
    };
    std::string path = write_field("pinholes.vol", n, n, n, sdf);
    auto scene = grid_scene(path);
    int missed = 0, rays = 0;
    // Axis-aligned rays through every sample line (and half-way between them).
    for (int i = 4; i <= 12; ++i)
        for (int j = 4; j <= 12; ++j)
            for (int axis = 0; axis < 3; ++axis)
                for (float sign : {-1.f, 1.f}) {
                    float a = float(i) / 16.f, b = float(j) / 16.f;
                    if ((a - 0.5f) * (a - 0.5f) + (b - 0.5f) * (b - 0.5f) > 0.3f * 0.3f) continue;
                    Point3f o;
                    Vector3f d(0.f);
                    o[axis] = sign > 0 ? -1.f : 2.f;
                    o[(axis + 1) % 3] = a;
                    o[(axis + 2) % 3] = b;
                    d[axis] = sign;
                    ++rays;
                    missed += !scene->ray_test(Ray(o, d));
                }
    // Random rays from outside towards the inner half of the ball.
    PCG32 rng(11);
    for (int k = 0; k < 20000; ++k) {
        Vector3f target = next_vector3f(rng) - Vector3f(0.5f);
        Vector3f dir = normalize(next_vector3f(rng) - Vector3f(0.5f));
        Point3f t = Point3f(0.5f) + target * 0.3f;
        ++rays;
        missed += !scene->ray_test(Ray(t - dir * 2.f, dir));
    }
    EXPECT_EQ(missed, 0) << "of " << rays << " rays";

    // A zero set lying exactly on a sample plane: every crossing is on a face shared by two
    // voxels, each of which sees a value of zero up to rounding there.
    std::string flat_path =
        write_field("zero_plane.vol", 9, 9, 9, [](double x, double y, double z) {
            return (z - 0.5) * (1.0 + 0.3 * x + 0.2 * y);
        });
    auto flat = grid_scene(flat_path);
    missed = 0;
    for (int k = 0; k < 20000; ++k) {
        const Point2f q = next_point2f(rng);
        Point3f target(0.05f + 0.9f * q.x, 0.05f + 0.9f * q.y, 0.5f);
        const Vector3f r = next_vector3f(rng);
        Vector3f dir = normalize(Vector3f(r.x - 0.5f, r.y - 0.5f, -0.05f - r.z));
        missed += !flat->ray_test(Ray(target - dir * (1.5f / std::abs(dir.z)), dir));
    }
    EXPECT_EQ(missed, 0) << "rays through the zero sample plane that missed";
}

TEST(SDFGrid, InstancedLikeMitsuba) {
    // Mitsuba's instancing case: the diagonal plane in a shapegroup placed twice.
    VolHeader h;
    const float s = float(std::sqrt(2.0) / 2.0);
    std::string path = write_vol("diagonal_instanced.vol", h, {-s, -s, 0, 0, 0, 0, s, s});
    auto scene = std::dynamic_pointer_cast<Scene>(
        load_string("<scene version=\"3.0.0\"><shape type=\"shapegroup\" id=\"g\"><shape "
                    "type=\"sdfgrid\"><string name=\"filename\" value=\"" +
                    path +
                    "\"/></shape></shape><shape type=\"instance\"><ref id=\"g\"/></shape><shape "
                    "type=\"instance\"><ref id=\"g\"/><transform name=\"to_world\"><translate "
                    "x=\"8\"/></transform></shape></scene>"));
    for (float tx : {0.f, 8.f})
        for (float x : {-0.5f, 0.25f, 0.75f, 1.5f})
            for (float y : {-0.5f, 0.3f, 0.9f, 1.5f}) {
                Ray ray(Point3f(tx + x, y, 3.f), Vector3f(0, 0, -1));
                bool expected = x >= 0.f && x <= 1.f && y >= 0.f && y <= 1.f;
                SurfaceInteraction si;
                ASSERT_EQ(scene->ray_intersect(ray, si), expected) << tx << " " << x << " " << y;
                if (!expected) continue;
                EXPECT_NEAR(si.t, 2.f + y, 1e-5f);
                expect_vec_near(si.n, Vector3f(0, s, s), 1e-5f, "normal");
            }
}
