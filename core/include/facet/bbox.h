#pragma once

#include <facet/vector.h>

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
    Vector3f extents() const { return max - min; }
    /// Radius of the bounding sphere around center().
    float bounding_sphere_radius() const { return valid() ? norm(max - min) * 0.5f : 0.f; }
};

} // namespace facet
