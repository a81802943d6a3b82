#pragma once

#include <facet/transform.h>
#include <facet/vector.h>

#include <fmt/format.h>

#include <cmath>
#include <string>

namespace facet {

/// Axis-aligned bounding box; an empty box has min = +inf, max = -inf.
struct BoundingBox3f {
    Point3f min{Infinity, Infinity, Infinity};
    Point3f max{-Infinity, -Infinity, -Infinity};

    BoundingBox3f() = default;
    BoundingBox3f(const Point3f &a, const Point3f &b) : min(a), max(b) {}
    bool valid() const { return min.x <= max.x && min.y <= max.y && min.z <= max.z; }
    void expand(const Point3f &p) {
        min = facet::min(min, p);
        max = facet::max(max, p);
    }
    void expand(const BoundingBox3f &b) {
        min = facet::min(min, b.min);
        max = facet::max(max, b.max);
    }
    Point3f center() const { return (min + max) * 0.5f; }
    /// Radius of the bounding sphere around center().
    float bounding_sphere_radius() const { return valid() ? norm(max - min) * 0.5f : 0.f; }
};

/// Empty when `b` (possibly empty) lies within ±MaxSceneCoordinate; otherwise what is wrong, to
/// follow "its bounding box ".
inline std::string bounds_problem(const BoundingBox3f &b) {
    const float values[6] = {b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z};
    for (float v : values)
        if (std::isnan(v)) return "is NaN";
    if (!b.valid()) return {}; // empty: nothing reaches Embree
    for (float v : values)
        if (!(std::abs(v) <= MaxSceneCoordinate))
            return fmt::format("reaches {:g}, beyond the supported coordinate range of ±{:g}", v,
                               MaxSceneCoordinate);
    return {};
}

} // namespace facet
