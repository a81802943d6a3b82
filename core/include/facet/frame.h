#pragma once

#include <facet/assert.h>
#include <facet/vector.h>

namespace facet {

/// Build two unit vectors s, t that complete the unit normal n to an orthonormal basis
/// (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
inline void coordinate_system(const Vector3f &n, Vector3f &s, Vector3f &t) {
    float sgn = std::copysign(1.f, n.z);
    float a = -1.f / (sgn + n.z);
    float b = n.x * n.y * a;
    s = Vector3f(1.f + sgn * n.x * n.x * a, sgn * b, -sgn * n.x);
    t = Vector3f(b, sgn + n.y * n.y * a, -n.y);
}

/// Orthonormal shading frame. In local coordinates the normal is +Z, so cos θ = v.z.
struct Frame {
    Vector3f s{1, 0, 0}, t{0, 1, 0}, n{0, 0, 1};

    Frame() = default;
    Frame(const Vector3f &s_, const Vector3f &t_, const Vector3f &n_) : s(s_), t(t_), n(n_) {
        FACET_ASSERT(is_unit(s) && is_unit(t) && is_unit(n));
        FACET_ASSERT(std::abs(dot(s, n)) < 1e-3f && std::abs(dot(t, n)) < 1e-3f);
    }
    /// The normal must be a unit vector (the basis built from it is orthonormal only then).
    explicit Frame(const Vector3f &n_) : n(n_) {
        FACET_ASSERT(is_unit(n));
        coordinate_system(n, s, t);
    }

    Vector3f to_local(const Vector3f &v) const { return {dot(v, s), dot(v, t), dot(v, n)}; }
    Vector3f to_world(const Vector3f &v) const { return s * v.x + t * v.y + n * v.z; }

    /// |v| = 1 up to float rounding of normalised or interpolated vectors.
    static bool is_unit(const Vector3f &v) { return std::abs(dot(v, v) - 1.f) < 1e-3f; }

    static float cos_theta(const Vector3f &v) { return v.z; }
    static float cos_theta_2(const Vector3f &v) { return v.z * v.z; }
    static float sin_theta_2(const Vector3f &v) { return std::max(0.f, 1.f - v.z * v.z); }
    static float sin_theta(const Vector3f &v) { return safe_sqrt(sin_theta_2(v)); }
    static float tan_theta(const Vector3f &v) { return sin_theta(v) / v.z; }
    static float tan_theta_2(const Vector3f &v) { return sin_theta_2(v) / (v.z * v.z); }
    static float cos_phi(const Vector3f &v) {
        float st = sin_theta(v);
        return st == 0.f ? 1.f : clamp(v.x / st, -1.f, 1.f);
    }
    static float sin_phi(const Vector3f &v) {
        float st = sin_theta(v);
        return st == 0.f ? 0.f : clamp(v.y / st, -1.f, 1.f);
    }
    static float cos_phi_2(const Vector3f &v) { return sqr(cos_phi(v)); }
    static float sin_phi_2(const Vector3f &v) { return sqr(sin_phi(v)); }
};

} // namespace facet
