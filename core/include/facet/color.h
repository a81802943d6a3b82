#pragma once

#include <facet/math.h>

#include <ostream>

namespace facet {

/**
 * A colour value: radiance, reflectance or a path's weight.
 * - In the rgb mode, linear Rec.709 RGB in r, g, b; in the mono mode, three equal values.
 * - In the spectral modes, the quantity at each of the path's four wavelengths (Wavelengths),
 *   channel i at wavelength i: r, g, b, w.
 *
 * The fourth channel `w` exists for the spectral modes. A value built from three numbers (the
 * rgb and mono modes build no other) holds a copy of `g` there, and every channel-wise operation
 * keeps it that copy, so the four-channel checks (is_black(), is_finite(), max()) see only real
 * values in every mode. Code that builds a value channel by channel in the spectral modes builds
 * all four: the four-number constructor, map(), or operator[] up to Channels.
 */
struct Color3f {
    /// The channels a value holds (the spectral modes' wavelengths per path).
    static constexpr int Channels = 4;

    float r = 0, g = 0, b = 0, w = 0;
    constexpr Color3f() = default;
    /// An RGB (or mono) value: `w` is a copy of `g_`.
    constexpr Color3f(float r_, float g_, float b_) : r(r_), g(g_), b(b_), w(g_) {}
    /// A value of the spectral modes, one number per wavelength.
    constexpr Color3f(float r_, float g_, float b_, float w_) : r(r_), g(g_), b(b_), w(w_) {}
    constexpr explicit Color3f(float v) : r(v), g(v), b(v), w(v) {}
    float &operator[](int i) { return i == 0 ? r : (i == 1 ? g : (i == 2 ? b : w)); }
    float operator[](int i) const { return i == 0 ? r : (i == 1 ? g : (i == 2 ? b : w)); }
    constexpr Color3f operator+(const Color3f &o) const {
        return {r + o.r, g + o.g, b + o.b, w + o.w};
    }
    constexpr Color3f operator-(const Color3f &o) const {
        return {r - o.r, g - o.g, b - o.b, w - o.w};
    }
    constexpr Color3f operator*(const Color3f &o) const {
        return {r * o.r, g * o.g, b * o.b, w * o.w};
    }
    constexpr Color3f operator/(const Color3f &o) const {
        return {r / o.r, g / o.g, b / o.b, w / o.w};
    }
    constexpr Color3f operator*(float s) const { return {r * s, g * s, b * s, w * s}; }
    constexpr Color3f operator/(float s) const { return {r / s, g / s, b / s, w / s}; }
    Color3f &operator+=(const Color3f &o) { return *this = *this + o; }
    Color3f &operator-=(const Color3f &o) { return *this = *this - o; }
    Color3f &operator*=(const Color3f &o) { return *this = *this * o; }
    Color3f &operator*=(float s) { return *this = *this * s; }
    Color3f &operator/=(float s) { return *this = *this / s; }
    constexpr bool operator==(const Color3f &o) const {
        return r == o.r && g == o.g && b == o.b && w == o.w;
    }
    constexpr bool operator!=(const Color3f &o) const { return !(*this == o); }

    bool is_black() const { return r == 0.f && g == 0.f && b == 0.f && w == 0.f; }
    bool is_finite() const {
        return std::isfinite(r) && std::isfinite(g) && std::isfinite(b) && std::isfinite(w);
    }
    float max() const { return std::max(std::max(r, g), std::max(b, w)); }
    /// The mean of the colour channels r, g, b: a heuristic's summary (a spectral value's first
    /// three wavelengths).
    float mean() const { return (r + g + b) * (1.f / 3.f); }
    /// Rec.709 luminance of r, g, b.
    float luminance() const { return 0.212671f * r + 0.715160f * g + 0.072169f * b; }
};

constexpr Color3f operator*(float s, const Color3f &c) { return c * s; }

/// `f` applied to each channel of `c` (all four). Where `c`'s fourth channel is a copy of its
/// second (any rgb or mono value), the copy is taken instead of a fourth call: same result, as
/// `f` must be a function of its argument alone.
template <class F> Color3f map(const Color3f &c, F &&f) {
    const float r = f(c.r), g = f(c.g), b = f(c.b);
    return {r, g, b, c.w == c.g ? g : f(c.w)};
}
/// `f` applied channel by channel to `a` and `b` (all four; the copy rule of map()).
template <class F> Color3f map(const Color3f &a, const Color3f &b, F &&f) {
    const float r = f(a.r, b.r), g = f(a.g, b.g), bl = f(a.b, b.b);
    return {r, g, bl, a.w == a.g && b.w == b.g ? g : f(a.w, b.w)};
}

/// The wavelengths (nm) a value of the spectral modes holds its channels at: channel i of every
/// colour along a path is the quantity at wavelength i (see ColourMode::Spectral).
using Wavelengths = Color3f;

inline std::ostream &operator<<(std::ostream &os, const Color3f &c) {
    os << "[" << c.r << ", " << c.g << ", " << c.b;
    if (c.w != c.g) os << ", " << c.w;
    return os << "]";
}

} // namespace facet
