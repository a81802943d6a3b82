#include <facet/output_metadata.h>
#include <facet/sensor.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace facet {

namespace {

/// Solves f = A q + b for the 2×2 matrix A and offset b from three correspondences.
bool fit_affine_2d(const Point2f (&q)[3], const Point2f (&f)[3], float (&a)[2][2], float (&b)[2]) {
    const double q1x = q[1].x - q[0].x, q1y = q[1].y - q[0].y;
    const double q2x = q[2].x - q[0].x, q2y = q[2].y - q[0].y;
    const double det = q1x * q2y - q2x * q1y;
    if (!(std::abs(det) > 1e-12)) return false;
    const double f1x = f[1].x - f[0].x, f1y = f[1].y - f[0].y;
    const double f2x = f[2].x - f[0].x, f2y = f[2].y - f[0].y;
    // A = F Q^-1 with F = [f1 - f0, f2 - f0], Q = [q1 - q0, q2 - q0] (columns).
    const double i00 = q2y / det, i01 = -q2x / det, i10 = -q1y / det, i11 = q1x / det;
    a[0][0] = float(f1x * i00 + f2x * i10);
    a[0][1] = float(f1x * i01 + f2x * i11);
    a[1][0] = float(f1y * i00 + f2y * i10);
    a[1][1] = float(f1y * i01 + f2y * i11);
    b[0] = float(f[0].x - (a[0][0] * q[0].x + a[0][1] * q[0].y));
    b[1] = float(f[0].y - (a[1][0] * q[0].x + a[1][1] * q[0].y));
    return true;
}

} // namespace

std::optional<Matrix4f> sensor_world_to_ndc(const Sensor &sensor) {
    const Transform world_to_camera = sensor.to_world().inverse();
    // Film positions to fit with, and one more to check the fit.
    const Point2f film[4] = {{0.25f, 0.25f}, {0.75f, 0.25f}, {0.25f, 0.75f}, {0.6f, 0.4f}};
    Point3f origin[4], start[4];
    Vector3f dir[4];
    float far_z = 0.f;
    for (int i = 0; i < 4; ++i) {
        auto [ray, weight] = sensor.sample_ray(0.f, film[i], Point2f(0.5f, 0.5f));
        (void)weight;
        origin[i] = world_to_camera.apply_point(ray.o);
        start[i] = world_to_camera.apply_point(ray(ray.mint));
        dir[i] = normalize(world_to_camera.apply_vector(ray.d));
        far_z = std::isfinite(ray.maxt) ? world_to_camera.apply_point(ray(ray.maxt)).z
                                        : std::numeric_limits<float>::infinity();
        if (!(dir[i].z > 0.f)) return std::nullopt;
    }
    const float near_z = start[0].z;
    const float scale = std::max(1.f, std::abs(near_z));
    bool pinhole = true, parallel = true;
    for (int i = 0; i < 4; ++i) {
        pinhole &= norm(origin[i]) < 1e-4f * scale;
        parallel &= std::abs(dir[i].x) < 1e-6f && std::abs(dir[i].y) < 1e-6f;
    }
    if (pinhole == parallel) return std::nullopt;

    Point2f q[4];
    for (int i = 0; i < 4; ++i)
        q[i] = pinhole ? Point2f(dir[i].x / dir[i].z, dir[i].y / dir[i].z)
                       : Point2f(origin[i].x, origin[i].y);
    float a[2][2], b[2];
    if (!fit_affine_2d({q[0], q[1], q[2]}, {film[0], film[1], film[2]}, a, b)) return std::nullopt;
    // The fourth ray must land where the fit says (a fisheye lens would not).
    const float px = a[0][0] * q[3].x + a[0][1] * q[3].y + b[0];
    const float py = a[1][0] * q[3].x + a[1][1] * q[3].y + b[1];
    if (std::abs(px - film[3].x) > 1e-4f || std::abs(py - film[3].y) > 1e-4f) return std::nullopt;

    Matrix4f p;
    const bool finite_far = std::isfinite(far_z) && far_z > near_z;
    if (pinhole) {
        // x' w = a (x, y) + b z with w = z; z' = far (z - near) / (z (far - near)).
        const float m[16] = {a[0][0],
                             a[0][1],
                             b[0],
                             0.f,
                             a[1][0],
                             a[1][1],
                             b[1],
                             0.f,
                             0.f,
                             0.f,
                             finite_far ? far_z / (far_z - near_z) : 1.f,
                             finite_far ? -far_z * near_z / (far_z - near_z) : -near_z,
                             0.f,
                             0.f,
                             1.f,
                             0.f};
        p = Matrix4f::from_rows(m);
    } else {
        if (!finite_far) return std::nullopt;
        const float m[16] = {a[0][0],
                             a[0][1],
                             0.f,
                             b[0],
                             a[1][0],
                             a[1][1],
                             0.f,
                             b[1],
                             0.f,
                             0.f,
                             1.f / (far_z - near_z),
                             -near_z / (far_z - near_z),
                             0.f,
                             0.f,
                             0.f,
                             1.f};
        p = Matrix4f::from_rows(m);
    }
    return p * world_to_camera.matrix;
}

void add_render_metadata(ImageWriteOptions &opts, const Sensor &sensor, int spp, double seconds) {
    opts.int_metadata["samplesPerPixel"] = spp;
    opts.float_metadata["renderTimeSeconds"] = float(seconds);
    opts.matrix_metadata["worldToCamera"] = sensor.to_world().inverse_matrix;
    if (auto ndc = sensor_world_to_ndc(sensor)) opts.matrix_metadata["worldToNDC"] = *ndc;
}

} // namespace facet
