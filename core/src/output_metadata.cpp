#include <facet/output_metadata.h>
#include <facet/render.h>
#include <facet/sensor.h>

#include <fmt/format.h>

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

void add_metadata(ImageWriteOptions &opts, const FileMetadata &metadata) {
    for (const auto &[key, value] : metadata.strings) opts.metadata[key] = value;
    for (const auto &[key, value] : metadata.ints) opts.int_metadata[key] = value;
    for (const auto &[key, value] : metadata.floats) opts.float_metadata[key] = value;
    for (const auto &[key, value] : metadata.matrices) opts.matrix_metadata[key] = value;
}

RenderFileInfo render_file_info(const RenderResult &result, const Sensor &sensor,
                                const std::string &scene_hash, const std::string &scene_path,
                                uint64_t seed, const std::string &mode) {
    RenderFileInfo info;
    info.spp = result.spp;
    info.spp_target = result.spp_target;
    info.sample_offset = result.sample_offset;
    info.spp_total = result.spp_total;
    info.pass_index = result.pass_index;
    info.pass_count = result.pass_count;
    info.crop = result.crop;
    info.film_width = result.film_width;
    info.film_height = result.film_height;
    info.seconds = result.seconds;
    if (result.cancelled) info.blocks = {result.blocks_done, result.blocks_total};
    info.scene_hash = scene_hash;
    info.scene_path = scene_path;
    info.seed = seed;
    info.mode = mode;
    info.world_to_camera = sensor.to_world().inverse_matrix;
    info.world_to_ndc = sensor_world_to_ndc(sensor);
    return info;
}

FileMetadata render_file_metadata(const RenderFileInfo &info) {
    FileMetadata m;
    std::map<std::string, std::string> &s = m.strings;
    s[attr::spp] = std::to_string(info.spp);
    if (info.spp != info.spp_target) s[attr::spp_target] = std::to_string(info.spp_target);
    s[attr::spp_total] = std::to_string(info.spp_total);
    s[attr::sample_offset] = std::to_string(info.sample_offset);
    s[attr::pass] = std::to_string(info.pass_index);
    s[attr::passes] = std::to_string(info.pass_count);
    const std::array<int, 4> &c = info.crop;
    s[attr::crop] = fmt::format("{} {} {} {}", c[0], c[1], c[2], c[3]);
    s[attr::film_size] = fmt::format("{} {}", info.film_width, info.film_height);
    if (!info.scene_hash.empty()) s[attr::scene_hash] = info.scene_hash;
    if (!info.scene_path.empty()) s[attr::scene] = info.scene_path;
    if (info.seed) s[attr::seed] = std::to_string(*info.seed);
    if (!info.mode.empty()) s[attr::mode] = info.mode;
    if (info.seconds) s[attr::render_time] = fmt::format("{:.3f}", *info.seconds);
    if (info.blocks)
        s[attr::blocks] = fmt::format("{}/{}", info.blocks->first, info.blocks->second);

    m.ints[attr::samples_per_pixel] = int(info.spp);
    if (info.seconds) m.floats[attr::render_time_seconds] = float(*info.seconds);
    if (info.world_to_camera) m.matrices[attr::world_to_camera] = *info.world_to_camera;
    if (info.world_to_ndc) m.matrices[attr::world_to_ndc] = *info.world_to_ndc;
    return m;
}

std::string scene_identity(const std::string &scene_text,
                           const std::map<std::string, std::string> &params, int film_width,
                           int film_height) {
    uint64_t h = 0xcbf29ce484222325ull; // FNV-1a, 64 bits
    auto add = [&h](const std::string &bytes) {
        for (unsigned char ch : bytes) {
            h ^= ch;
            h *= 0x100000001b3ull;
        }
        h ^= 0xff; // separator: ("ab", "c") and ("a", "bc") differ
        h *= 0x100000001b3ull;
    };
    add(scene_text);
    for (const auto &[key, value] : params) add(key + "=" + value);
    add(fmt::format("{}x{}", film_width, film_height));
    return fmt::format("{:016x}", h);
}

} // namespace facet
