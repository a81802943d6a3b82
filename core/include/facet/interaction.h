#pragma once

#include <facet/frame.h>
#include <facet/fwd.h>
#include <facet/math.h>
#include <facet/ray.h>

#include <cstdint>
#include <cstring>

namespace facet {

/// A point with a geometric normal (a reference point for emitter sampling).
struct Interaction {
    Point3f p;
    Normal3f n; ///< geometric normal; zero for points in space
    float t = Infinity;
    /// The path's wavelengths (Ray::wavelengths): spectral textures and emitters evaluate at them.
    Wavelengths wavelengths;

    bool is_valid() const { return t != Infinity; }

    /// Ray leaving p in direction d, offset along n to avoid self-intersection. The offset grows
    /// with the magnitude of p so it stays above float rounding at large coordinates. (Inline:
    /// it runs once or twice per path vertex.)
    Ray spawn_ray(const Vector3f &d) const {
        Ray ray(offset_origin(p, n, d), d, 0.f, Infinity);
        ray.wavelengths = wavelengths;
        return ray;
    }
    /// Ray from p towards `target`, ending just before it (shadow rays): it stops short by the
    /// fraction ShadowEpsilon of its length, since the target usually lies on a surface too.
    Ray spawn_ray_to(const Point3f &target) const {
        Point3f o = offset_origin(p, n, target - p);
        Vector3f d = target - o;
        float dist = norm(d);
        Ray ray(o, Vector3f(0.f, 0.f, 1.f), 0.f, 0.f);
        if (dist > 0.f) {
            ray.d = d / dist;
            ray.maxt = dist * (1.f - ShadowEpsilon);
        }
        ray.wavelengths = wavelengths;
        return ray;
    }

    /// Distance by which spawned rays leave a surface: (1 + max |p_i|) · RayEpsilon, Mitsuba 3's
    /// offset. Hit points carry an error of a few ulps of their largest coordinate, and
    /// Embree's own tests work in float relative to the ray origin, so the offset grows with
    /// |p|. Its size is a convention more than a necessity (a tenth of it escapes as well), but
    /// light leaking past small geometry depends on it: small shapes are shadowed as in Mitsuba
    /// only with the same offset.
    static float offset_scale(const Point3f &p) {
        return (1.f + max_component(abs(p))) * RayEpsilon;
    }
    /// p moved off the surface along the geometric normal, to the side `d` points to.
    static Point3f offset_origin(const Point3f &p, const Normal3f &n, const Vector3f &d) {
        // A point in space (n is exactly zero, surface normals are unit vectors): nothing to
        // escape from. Tested on the bits, which are zero but for the signs: three unordered
        // float compares take twice the instructions on this hot path.
        uint32_t bx, by, bz;
        std::memcpy(&bx, &n.x, 4);
        std::memcpy(&by, &n.y, 4);
        std::memcpy(&bz, &n.z, 4);
        if (((bx | by | bz) & 0x7fffffffu) == 0) return p;
        float offset = offset_scale(p);
        return p + n * mulsign(offset, dot(n, d));
    }
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
