#pragma once

#include <facet/vector.h>

#include <cstdint>
#include <cstring>

/// Warps from the unit square to other domains, each with the density of what it produces.
namespace facet::warp {

// The warps of diffuse reflection and of triangle lights are inline: they run several times per
// path vertex.

/// sin and cos of an angle |a| <= π/4 (the concentric map's), by their Taylor polynomials: the
/// first terms left out are below 3e-9 there, so the results are within about an ulp, without
/// the range reduction and the call of std::sin and std::cos (this runs at every diffuse
/// bounce).
inline void sin_cos_quarter_pi(float a, float &s, float &c) {
    // In pairs of terms (Estrin's scheme) rather than one Horner chain: the products of the pairs
    // run side by side, so the result waits for 7 dependent operations instead of 11 (within 8e-8
    // of the sine and cosine, as Horner's 7e-8). The coefficients are products, not divisions: a
    // division by a constant is not turned into a product when its reciprocal is inexact.
    const float a2 = a * a, a4 = a2 * a2;
    s = a * ((1.f + a2 * (-1.f / 6.f)) +
             a4 * ((1.f / 120.f + a2 * (-1.f / 5040.f)) + a4 * (1.f / 362880.f)));
    c = (1.f + a2 * (-1.f / 2.f)) +
        a4 * ((1.f / 24.f + a2 * (-1.f / 720.f)) + a4 * (1.f / 40320.f + a2 * (-1.f / 3628800.f)));
}

/// `c ? a : b` by the bits, so that no branch is taken on a condition that random samples make
/// unpredictable (a compiler may compile the ternary operator on floats to a branch).
inline float select_bits(bool c, float a, float b) {
    uint32_t ia, ib;
    std::memcpy(&ia, &a, sizeof ia);
    std::memcpy(&ib, &b, sizeof ib);
    const uint32_t mask = 0u - uint32_t(c), bits = (ia & mask) | (ib & ~mask);
    float r;
    std::memcpy(&r, &bits, sizeof r);
    return r;
}

inline Point2f square_to_uniform_disk_concentric(const Point2f &u) {
    // Shirley and Chiu's concentric map, in the branch-light form of Shirley's 2011 note: the
    // angle is θ = (π/4)(y/x) in the wedges around ±x and π/2 - (π/4)(x/y) in those around ±y,
    // whose cosine and sine are the sine and cosine of (π/4)(x/y).
    // Which wedge is a coin toss for random samples: chosen without a branch.
    const float x = 2.f * u.x - 1.f, y = 2.f * u.y - 1.f;
    const bool wide = std::abs(x) > std::abs(y); // around ±x
    const float r = select_bits(wide, x, y), t = select_bits(wide, y, x);
    if (r == 0.f) return {0.f, 0.f};
    float s, c;
    sin_cos_quarter_pi((Pi / 4.f) * (t / r), s, c);
    return {r * select_bits(wide, c, s), r * select_bits(wide, s, c)};
}
float square_to_uniform_disk_concentric_pdf(const Point2f &p);
/// Barycentric (b1, b2), uniform over the triangle.
inline Point2f square_to_uniform_triangle(const Point2f &u) {
    float t = safe_sqrt(1.f - u.x);
    return {1.f - t, t * u.y};
}
Vector3f square_to_uniform_sphere(const Point2f &u);
float square_to_uniform_sphere_pdf(const Vector3f &v);
Vector3f square_to_uniform_hemisphere(const Point2f &u);
float square_to_uniform_hemisphere_pdf(const Vector3f &v);
inline Vector3f square_to_cosine_hemisphere(const Point2f &u) {
    // Malley's method: project the uniform disk up to the hemisphere.
    Point2f p = square_to_uniform_disk_concentric(u);
    float z = safe_sqrt(1.f - p.x * p.x - p.y * p.y);
    return {p.x, p.y, z};
}
inline float square_to_cosine_hemisphere_pdf(const Vector3f &v) {
    return v.z >= 0.f ? v.z * InvPi : 0.f;
}
/// Uniform direction inside the cone of directions with cos θ >= cos_cutoff around +Z.
Vector3f square_to_uniform_cone(const Point2f &u, float cos_cutoff);
float square_to_uniform_cone_pdf(const Vector3f &v, float cos_cutoff);
/// 1D tent on [-1, 1].
float interval_to_tent(float u);

/// The point of [0, 1] for u in [0, 1] under the density proportional to the line from v0 at 0 to
/// v1 at 1 (v0, v1 >= 0): the inverse of its CDF, x = (v0 - sqrt(lerp(u, v0², v1²))) / (v0 - v1).
/// Always a point of [0, 1], never NaN: where the density is degenerate (both ends zero, as on
/// an environment map's pole row, or not finite) or nearly constant it is uniform, and x = u.
/// The ends should be of order one (a caller scales its table so): squares of tiny values lose
/// their precision before the nearly-constant test catches them.
inline float interval_to_linear(float v0, float v1, float u) {
    if (!(v0 + v1 > 0.f) || !(v0 + v1 < Infinity)) return u;
    if (std::abs(v0 - v1) < 1e-6f * std::max(v0, v1)) return u;
    const float x = (v0 - safe_sqrt(lerp(u, v0 * v0, v1 * v1))) / (v0 - v1);
    return x > 0.f ? std::min(x, 1.f) : 0.f; // NaN-safe clamp
}

} // namespace facet::warp
