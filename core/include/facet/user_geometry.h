#pragma once

#include <facet/bbox.h>
#include <facet/vector.h>

#include <embree3/rtcore.h>

/// Embree user geometry for exact primitives (sphere, disk): the callbacks are written once here.
namespace facet {

/// What an exact primitive reports for a hit: distance, geometric normal (any length) and two
/// numbers that Embree keeps as hit.u/v and hands back to compute_surface_interaction().
struct UserHit {
    float t = 0.f;
    Normal3f ng;
    Point2f uv;
};

namespace detail {

template <typename T> void user_bounds(const RTCBoundsFunctionArguments *args) {
    const T *shape = static_cast<const T *>(args->geometryUserPtr);
    BoundingBox3f box = shape->bbox();
    // A little slack for the rounding of the box corners.
    float eps = (max_component(abs(box.min)) + max_component(abs(box.max))) * 1e-6f;
    RTCBounds *b = args->bounds_o;
    b->lower_x = box.min.x - eps;
    b->lower_y = box.min.y - eps;
    b->lower_z = box.min.z - eps;
    b->upper_x = box.max.x + eps;
    b->upper_y = box.max.y + eps;
    b->upper_z = box.max.z + eps;
}

inline Point3f ray_origin(RTCRayN *ray, unsigned n, unsigned i) {
    return {RTCRayN_org_x(ray, n, i), RTCRayN_org_y(ray, n, i), RTCRayN_org_z(ray, n, i)};
}
inline Vector3f ray_direction(RTCRayN *ray, unsigned n, unsigned i) {
    return {RTCRayN_dir_x(ray, n, i), RTCRayN_dir_y(ray, n, i), RTCRayN_dir_z(ray, n, i)};
}

template <typename T> void user_intersect(const RTCIntersectFunctionNArguments *args) {
    const T *shape = static_cast<const T *>(args->geometryUserPtr);
    const unsigned n = args->N;
    RTCRayN *ray = RTCRayHitN_RayN(args->rayhit, n);
    RTCHitN *hit = RTCRayHitN_HitN(args->rayhit, n);
    for (unsigned i = 0; i < n; ++i) {
        if (!args->valid[i]) continue;
        UserHit h;
        if (!shape->intersect_user(ray_origin(ray, n, i), ray_direction(ray, n, i),
                                   RTCRayN_tnear(ray, n, i), RTCRayN_tfar(ray, n, i), h))
            continue;
        RTCRayN_tfar(ray, n, i) = h.t;
        RTCHitN_Ng_x(hit, n, i) = h.ng.x;
        RTCHitN_Ng_y(hit, n, i) = h.ng.y;
        RTCHitN_Ng_z(hit, n, i) = h.ng.z;
        RTCHitN_u(hit, n, i) = h.uv.x;
        RTCHitN_v(hit, n, i) = h.uv.y;
        RTCHitN_primID(hit, n, i) = args->primID;
        RTCHitN_geomID(hit, n, i) = args->geomID;
        // Inside an instance the ray is already in the group's space; record which instance.
        RTCHitN_instID(hit, n, i, 0) = args->context->instID[0];
    }
}

template <typename T> void user_occluded(const RTCOccludedFunctionNArguments *args) {
    const T *shape = static_cast<const T *>(args->geometryUserPtr);
    const unsigned n = args->N;
    RTCRayN *ray = args->ray;
    for (unsigned i = 0; i < n; ++i) {
        if (!args->valid[i]) continue;
        UserHit h;
        if (shape->intersect_user(ray_origin(ray, n, i), ray_direction(ray, n, i),
                                  RTCRayN_tnear(ray, n, i), RTCRayN_tfar(ray, n, i), h))
            RTCRayN_tfar(ray, n, i) = -Infinity; // Embree's mark for "occluded"
    }
}

} // namespace detail

/// Committed Embree user geometry of one primitive. `T` provides `BoundingBox3f bbox() const` and
/// `bool intersect_user(const Point3f &o, const Vector3f &d, float tnear, float tfar, UserHit &hit)
/// const`, which must not allocate (it runs inside Embree's traversal).
template <typename T> RTCGeometry make_user_geometry(RTCDevice device, const T *shape) {
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(geom, 1);
    rtcSetGeometryUserData(geom, const_cast<T *>(shape));
    rtcSetGeometryBoundsFunction(geom, &detail::user_bounds<T>, nullptr);
    rtcSetGeometryIntersectFunction(geom, &detail::user_intersect<T>);
    rtcSetGeometryOccludedFunction(geom, &detail::user_occluded<T>);
    rtcCommitGeometry(geom);
    return geom;
}

} // namespace facet
