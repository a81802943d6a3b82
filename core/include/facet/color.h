#pragma once

#include <facet/math.h>

#include <ostream>

namespace facet {

/// Linear Rec.709 RGB radiance, reflectance or weight.
struct Color3f {
    float r = 0, g = 0, b = 0;
    constexpr Color3f() = default;
    constexpr Color3f(float r_, float g_, float b_) : r(r_), g(g_), b(b_) {}
    constexpr explicit Color3f(float v) : r(v), g(v), b(v) {}
    float &operator[](int i) { return i == 0 ? r : (i == 1 ? g : b); }
    float operator[](int i) const { return i == 0 ? r : (i == 1 ? g : b); }
    constexpr Color3f operator+(const Color3f &o) const { return {r + o.r, g + o.g, b + o.b}; }
    constexpr Color3f operator-(const Color3f &o) const { return {r - o.r, g - o.g, b - o.b}; }
    constexpr Color3f operator*(const Color3f &o) const { return {r * o.r, g * o.g, b * o.b}; }
    constexpr Color3f operator/(const Color3f &o) const { return {r / o.r, g / o.g, b / o.b}; }
    constexpr Color3f operator*(float s) const { return {r * s, g * s, b * s}; }
    constexpr Color3f operator/(float s) const { return {r / s, g / s, b / s}; }
    Color3f &operator+=(const Color3f &o) {
        r += o.r;
        g += o.g;
        b += o.b;
        return *this;
    }
    Color3f &operator-=(const Color3f &o) {
        r -= o.r;
        g -= o.g;
        b -= o.b;
        return *this;
    }
    Color3f &operator*=(const Color3f &o) {
        r *= o.r;
        g *= o.g;
        b *= o.b;
        return *this;
    }
    Color3f &operator*=(float s) {
        r *= s;
        g *= s;
        b *= s;
        return *this;
    }
    Color3f &operator/=(float s) {
        r /= s;
        g /= s;
        b /= s;
        return *this;
    }
    constexpr bool operator==(const Color3f &o) const { return r == o.r && g == o.g && b == o.b; }
    constexpr bool operator!=(const Color3f &o) const { return !(*this == o); }

    bool is_black() const { return r == 0.f && g == 0.f && b == 0.f; }
    bool is_finite() const { return std::isfinite(r) && std::isfinite(g) && std::isfinite(b); }
    float max() const { return std::max(r, std::max(g, b)); }
    float mean() const { return (r + g + b) * (1.f / 3.f); }
    /// Rec.709 luminance.
    float luminance() const { return 0.212671f * r + 0.715160f * g + 0.072169f * b; }
};

constexpr Color3f operator*(float s, const Color3f &c) { return c * s; }

/// The wavelengths (nm) a value of the spectral modes holds its channels at: channel i of every
/// colour along a path is the quantity at wavelength i (see ColourMode::Spectral).
using Wavelengths = Color3f;

inline std::ostream &operator<<(std::ostream &os, const Color3f &c) {
    return os << "[" << c.r << ", " << c.g << ", " << c.b << "]";
}

} // namespace facet
