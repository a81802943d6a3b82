#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace facet {

constexpr float Pi = 3.14159265358979323846f;
constexpr float InvPi = 0.31830988618379067154f;
constexpr float InvTwoPi = 0.15915494309189533577f;
constexpr float InvFourPi = 0.07957747154594766788f;
constexpr float Infinity = std::numeric_limits<float>::infinity();
constexpr float OneMinusEpsilon = 0x1.fffffep-1f;
/// Relative offset used to spawn rays (see Interaction::spawn_ray): 1500 half-ulps of 1, about
/// 8.9e-5, as in Mitsuba 3, so that small geometry is shadowed as there.
constexpr float RayEpsilon = 1500.f * 0x1p-24f;
/// Fraction of its length by which a ray towards a point stops short (Interaction::spawn_ray_to).
constexpr float ShadowEpsilon = 10.f * RayEpsilon;

template <typename T> constexpr T sqr(T x) { return x * x; }
template <typename T> constexpr T clamp(T v, T lo, T hi) { return v < lo ? lo : (v > hi ? hi : v); }
template <typename T> constexpr T lerp(float t, T a, T b) { return a * (1.f - t) + b * t; }

inline float safe_sqrt(float x) { return std::sqrt(std::max(x, 0.f)); }
inline double safe_sqrt(double x) { return std::sqrt(std::max(x, 0.0)); }
inline float safe_acos(float x) { return std::acos(clamp(x, -1.f, 1.f)); }
inline float deg_to_rad(float d) { return d * (Pi / 180.f); }
inline float rad_to_deg(float r) { return r * (180.f / Pi); }
inline float mulsign(float x, float s) { return std::signbit(s) ? -x : x; }
inline float sign(float x) { return std::signbit(x) ? -1.f : 1.f; }

/// atan2(y, x) within 2.1 ulp of the exact angle, with std::atan2's signs and quadrants for zeros
/// (atan2(±0, -0) = ±π), at about 2.5x its speed: a polynomial of degree 17 in min/max of |x|, |y|
/// (relative error 1.5e-8 on [0, 1], fitted for facet). For finite arguments. The polynomial is
/// a·c0 + a·s·q(s) with q in pairs of terms (Estrin's scheme): 7 dependent steps where Horner's
/// scheme takes 18, and the leading term rounded alone (2.09 ulp at worst over 1.3e8 test points;
/// Horner's 2.42).
inline float fast_atan2(float y, float x) {
    const float ax = std::abs(x), ay = std::abs(y);
    const float hi = std::max(ax, ay), lo = std::min(ax, ay);
    const float a = hi > 0.f ? lo / hi : 0.f; // atan(a) for a in [0, 1], a = tan of the angle
    const float s = a * a, s2 = s * s, s4 = s2 * s2;
    const float q = (-0.33333073341183894f + 0.1999261934141776f * s) +
                    s2 * (-0.14203644170195534f + 0.10640933087262631f * s) +
                    s4 * ((-0.07504292833775185f + 0.04269150140993726f * s) +
                          s2 * (-0.01606861892272382f + 0.002849887274578758f * s));
    float r = a * 0.9999999847649031f + (a * s) * q;
    if (ay > ax) r = 1.57079632679489662f - r;
    if (std::signbit(x)) r = Pi - r;
    return std::copysign(r, y);
}

/// Inverse error function (Giles' single-precision approximation): erf of the result is x within
/// 1.2e-7.
float erfinv(float x);

} // namespace facet
