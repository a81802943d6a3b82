#pragma once

#include <facet/math.h>

#include <ostream>

namespace facet {

/// Two-component vector (also used for points and sample pairs).
template <typename T> struct Vec2 {
    T x = 0, y = 0;
    constexpr Vec2() = default;
    constexpr Vec2(T x_, T y_) : x(x_), y(y_) {}
    constexpr explicit Vec2(T v) : x(v), y(v) {}
    template <typename U> constexpr explicit Vec2(const Vec2<U> &o) : x(T(o.x)), y(T(o.y)) {}
    T &operator[](int i) { return i == 0 ? x : y; }
    T operator[](int i) const { return i == 0 ? x : y; }
    constexpr Vec2 operator+(const Vec2 &o) const { return {x + o.x, y + o.y}; }
    constexpr Vec2 operator-(const Vec2 &o) const { return {x - o.x, y - o.y}; }
    constexpr Vec2 operator*(const Vec2 &o) const { return {x * o.x, y * o.y}; }
    constexpr Vec2 operator/(const Vec2 &o) const { return {x / o.x, y / o.y}; }
    constexpr Vec2 operator*(T s) const { return {x * s, y * s}; }
    constexpr Vec2 operator/(T s) const { return {x / s, y / s}; }
    constexpr Vec2 operator-() const { return {-x, -y}; }
    Vec2 &operator+=(const Vec2 &o) {
        x += o.x;
        y += o.y;
        return *this;
    }
    Vec2 &operator-=(const Vec2 &o) {
        x -= o.x;
        y -= o.y;
        return *this;
    }
    Vec2 &operator*=(T s) {
        x *= s;
        y *= s;
        return *this;
    }
    constexpr bool operator==(const Vec2 &o) const { return x == o.x && y == o.y; }
    constexpr bool operator!=(const Vec2 &o) const { return !(*this == o); }
};

/// Three-component vector (points, directions and normals share this type).
template <typename T> struct Vec3 {
    T x = 0, y = 0, z = 0;
    constexpr Vec3() = default;
    constexpr Vec3(T x_, T y_, T z_) : x(x_), y(y_), z(z_) {}
    constexpr explicit Vec3(T v) : x(v), y(v), z(v) {}
    template <typename U> constexpr explicit Vec3(const Vec3<U> &o)
        : x(T(o.x)), y(T(o.y)), z(T(o.z)) {}
    T &operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
    T operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    constexpr Vec3 operator+(const Vec3 &o) const { return {x + o.x, y + o.y, z + o.z}; }
    constexpr Vec3 operator-(const Vec3 &o) const { return {x - o.x, y - o.y, z - o.z}; }
    constexpr Vec3 operator*(const Vec3 &o) const { return {x * o.x, y * o.y, z * o.z}; }
    constexpr Vec3 operator/(const Vec3 &o) const { return {x / o.x, y / o.y, z / o.z}; }
    constexpr Vec3 operator*(T s) const { return {x * s, y * s, z * s}; }
    constexpr Vec3 operator/(T s) const { return {x / s, y / s, z / s}; }
    constexpr Vec3 operator-() const { return {-x, -y, -z}; }
    Vec3 &operator+=(const Vec3 &o) {
        x += o.x;
        y += o.y;
        z += o.z;
        return *this;
    }
    Vec3 &operator-=(const Vec3 &o) {
        x -= o.x;
        y -= o.y;
        z -= o.z;
        return *this;
    }
    Vec3 &operator*=(T s) {
        x *= s;
        y *= s;
        z *= s;
        return *this;
    }
    Vec3 &operator/=(T s) {
        x /= s;
        y /= s;
        z /= s;
        return *this;
    }
    constexpr bool operator==(const Vec3 &o) const { return x == o.x && y == o.y && z == o.z; }
    constexpr bool operator!=(const Vec3 &o) const { return !(*this == o); }
};

template <typename T> constexpr Vec2<T> operator*(T s, const Vec2<T> &v) { return v * s; }
template <typename T> constexpr Vec3<T> operator*(T s, const Vec3<T> &v) { return v * s; }

using Vector2f = Vec2<float>;
using Point2f = Vec2<float>;
using Vector2i = Vec2<int>;
using Point2i = Vec2<int>;
using Vector3f = Vec3<float>;
using Point3f = Vec3<float>;
using Normal3f = Vec3<float>;
using Vector3d = Vec3<double>;

template <typename T> constexpr T dot(const Vec3<T> &a, const Vec3<T> &b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <typename T> constexpr T dot(const Vec2<T> &a, const Vec2<T> &b) {
    return a.x * b.x + a.y * b.y;
}
template <typename T> inline T absdot(const Vec3<T> &a, const Vec3<T> &b) {
    return std::abs(dot(a, b));
}
template <typename T> constexpr Vec3<T> cross(const Vec3<T> &a, const Vec3<T> &b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <typename T> constexpr T squared_norm(const Vec3<T> &v) { return dot(v, v); }
template <typename T> inline T norm(const Vec3<T> &v) { return std::sqrt(dot(v, v)); }
template <typename T> inline T norm(const Vec2<T> &v) { return std::sqrt(dot(v, v)); }
template <typename T> inline Vec3<T> normalize(const Vec3<T> &v) { return v / norm(v); }
template <typename T> inline Vec3<T> abs(const Vec3<T> &v) {
    return {std::abs(v.x), std::abs(v.y), std::abs(v.z)};
}
template <typename T> inline Vec3<T> min(const Vec3<T> &a, const Vec3<T> &b) {
    return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
template <typename T> inline Vec3<T> max(const Vec3<T> &a, const Vec3<T> &b) {
    return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
template <typename T> inline T max_component(const Vec3<T> &v) {
    return std::max(v.x, std::max(v.y, v.z));
}
template <typename T> inline bool is_finite(const Vec3<T> &v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

template <typename T> std::ostream &operator<<(std::ostream &os, const Vec3<T> &v) {
    return os << "[" << v.x << ", " << v.y << ", " << v.z << "]";
}
template <typename T> std::ostream &operator<<(std::ostream &os, const Vec2<T> &v) {
    return os << "[" << v.x << ", " << v.y << "]";
}

} // namespace facet
