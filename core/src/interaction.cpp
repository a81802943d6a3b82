#include <facet/interaction.h>
#include <facet/shape.h>

namespace facet {

namespace {

/// Distance by which spawned rays leave a surface. Hit points carry an error of a few ulps of
/// their largest coordinate, and Embree's own tests work in float relative to the ray origin, so
/// the offset must grow with |p|; a fixed relative size keeps it well above both (about 80 ulps)
/// while staying far below any geometric feature a scene resolves in float.
inline float offset_scale(const Point3f &p) {
    return (1.f + max_component(abs(p))) * (RayEpsilon * 0.1f);
}

/// p moved off the surface along the geometric normal, to the side `d` points to.
inline Point3f offset_origin(const Point3f &p, const Normal3f &n, const Vector3f &d) {
    if (n.x == 0.f && n.y == 0.f && n.z == 0.f)
        return p; // a point in space: nothing to escape from
    float offset = offset_scale(p);
    return p + n * mulsign(offset, dot(n, d));
}

} // namespace

Ray Interaction::spawn_ray(const Vector3f &d) const {
    return Ray(offset_origin(p, n, d), d, 0.f, Infinity);
}

Ray Interaction::spawn_ray_to(const Point3f &target) const {
    Point3f o = offset_origin(p, n, target - p);
    Vector3f d = target - o;
    float dist = norm(d);
    if (!(dist > 0.f)) return Ray(o, Vector3f(0.f, 0.f, 1.f), 0.f, 0.f);
    d /= dist;
    // Stop short of the target by the same margin, since it usually lies on a surface too.
    float maxt = std::max(0.f, dist - offset_scale(target));
    return Ray(o, d, 0.f, maxt);
}

const BSDF *SurfaceInteraction::bsdf() const { return shape ? shape->bsdf() : nullptr; }

const Emitter *SurfaceInteraction::emitter() const { return shape ? shape->emitter() : nullptr; }

} // namespace facet
