#include <facet/warp.h>

namespace facet::warp {

float square_to_uniform_disk_concentric_pdf(const Point2f &p) {
    return p.x * p.x + p.y * p.y <= 1.f ? InvPi : 0.f;
}

Vector3f square_to_uniform_sphere(const Point2f &u) {
    float z = 1.f - 2.f * u.y;
    float r = safe_sqrt(1.f - z * z);
    float phi = 2.f * Pi * u.x;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

float square_to_uniform_sphere_pdf(const Vector3f &) { return InvFourPi; }

Vector3f square_to_uniform_hemisphere(const Point2f &u) {
    float z = u.y;
    float r = safe_sqrt(1.f - z * z);
    float phi = 2.f * Pi * u.x;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

float square_to_uniform_hemisphere_pdf(const Vector3f &v) { return v.z >= 0.f ? InvTwoPi : 0.f; }

Vector3f square_to_uniform_cone(const Point2f &u, float cos_cutoff) {
    float cos_theta = (1.f - u.y) + u.y * cos_cutoff;
    float sin_theta = safe_sqrt(1.f - cos_theta * cos_theta);
    float phi = 2.f * Pi * u.x;
    return {sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta};
}

float square_to_uniform_cone_pdf(const Vector3f &v, float cos_cutoff) {
    return v.z >= cos_cutoff ? InvTwoPi / (1.f - cos_cutoff) : 0.f;
}

float interval_to_tent(float u) {
    // Inverse CDF of the tent 1 - |x| on [-1, 1], one half at a time.
    if (u < 0.5f) return std::sqrt(2.f * u) - 1.f;
    return 1.f - std::sqrt(2.f - 2.f * u);
}

} // namespace facet::warp
