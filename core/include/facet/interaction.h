#pragma once

#include <facet/frame.h>
#include <facet/fwd.h>
#include <facet/ray.h>

namespace facet {

/// A point with a geometric normal (a reference point for emitter sampling).
struct Interaction {
    Point3f p;
    Normal3f n; ///< geometric normal; zero for points in space
    float t = Infinity;

    bool is_valid() const { return t != Infinity; }

    /// Ray leaving p in direction d, offset along n to avoid self-intersection. The offset grows
    /// with the magnitude of p so it stays above float rounding at large coordinates.
    Ray spawn_ray(const Vector3f &d) const;
    /// Ray from p towards `target`, ending just before it (shadow rays).
    Ray spawn_ray_to(const Point3f &target) const;
};

/// A ray-surface hit with everything shading needs.
struct SurfaceInteraction : Interaction {
    Frame sh_frame; ///< shading frame (n = shading normal)
    Point2f uv;
    Vector3f dp_du, dp_dv;
    Vector3f wi; ///< direction towards the ray origin, in the local shading frame
    const Shape *shape = nullptr;
    uint32_t prim_index = 0;
    uint32_t instance_index = uint32_t(-1);

    Vector3f to_world(const Vector3f &v) const { return sh_frame.to_world(v); }
    Vector3f to_local(const Vector3f &v) const { return sh_frame.to_local(v); }
    /// BSDF of the shape that was hit (never null for a valid hit).
    const BSDF *bsdf() const;
    /// Area emitter of the shape that was hit, or nullptr.
    const Emitter *emitter() const;
};

/// A point sampled on a shape's surface, with its density per unit area.
struct PositionSample {
    Point3f p;
    Normal3f n;
    Point2f uv;
    float pdf = 0.f;
    bool delta = false;
};

/// A direction sampled from a reference point towards an emitter.
struct DirectionSample : PositionSample {
    Vector3f d;       ///< unit direction from the reference point to p
    float dist = 0.f; ///< distance to p (Infinity for environment emitters)
    const Emitter *emitter = nullptr;
};

} // namespace facet
