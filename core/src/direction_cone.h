// Cones of directions and their union, for bounding the normals of emitting surfaces and the
// emission of groups of emitters (the scene's light hierarchy).
#pragma once

#include <facet/math.h>
#include <facet/vector.h>

#include <algorithm>
#include <cmath>

namespace facet::detail {

/// The directions within `theta` (radians) of the unit `axis`; theta >= π: every direction,
/// theta < 0: none.
struct DirectionCone {
    Vector3f axis = Vector3f(0.f, 0.f, 1.f);
    float theta = -1.f;

    bool empty() const { return theta < 0.f; }
    bool everything() const { return theta >= Pi; }
    static DirectionCone all() { return {Vector3f(0.f, 0.f, 1.f), Pi}; }
    bool contains(const Vector3f &d) const {
        return everything() || (!empty() && dot(axis, d) >= std::cos(theta));
    }
};

/// The angle between unit vectors, accurate for nearly equal and nearly opposite ones.
inline float angle_between(const Vector3f &a, const Vector3f &b) {
    if (dot(a, b) >= 0.f) return 2.f * std::asin(std::min(norm(a - b) * 0.5f, 1.f));
    return Pi - 2.f * std::asin(std::min(norm(a + b) * 0.5f, 1.f));
}

/// The smallest cone (around an axis in the plane of the two axes) holding both cones.
inline DirectionCone merge(const DirectionCone &a, const DirectionCone &b) {
    if (a.empty()) return b;
    if (b.empty()) return a;
    if (a.everything() || b.everything()) return DirectionCone::all();
    const float between = angle_between(a.axis, b.axis);
    if (std::min(between + b.theta, Pi) <= a.theta) return a;
    if (std::min(between + a.theta, Pi) <= b.theta) return b;
    const float theta = 0.5f * (a.theta + between + b.theta);
    if (theta >= Pi) return DirectionCone::all();
    // a's axis turned towards b's by theta - a.theta, about their common perpendicular.
    Vector3f w = cross(a.axis, b.axis);
    const float len = norm(w);
    if (!(len > 1e-6f)) {
        // (Nearly) the same axis, a rounding apart: a's, widened by the angle between them;
        // opposite axes: every direction.
        if (dot(a.axis, b.axis) > 0.f)
            return {a.axis, std::min(std::max(a.theta, between + b.theta), Pi)};
        return DirectionCone::all();
    }
    w /= len;
    const float turn = theta - a.theta;
    const Vector3f axis = a.axis * std::cos(turn) + cross(w, a.axis) * std::sin(turn);
    return {normalize(axis), theta};
}

} // namespace facet::detail
