#pragma once

// The queries Scene sends to Embree, seen and sent again from outside (private to libfacet and
// the facet command, not installed): `facet bench` records a render's queries and replays them
// to time Embree on its own (core/apps/ray_recording.h).

#include <facet/scene.h>

#include <cstddef>
#include <cstdint>

namespace facet::detail {

/// One query Scene sent to Embree (from ray_intersect() or ray_test()) and Embree's answer.
struct RayQuery {
    float words[8]; ///< the ray as Embree got it: o.x, o.y, o.z, d.x, d.y, d.z, mint, maxt
    bool occlusion; ///< rtcOccluded1 (ray_test()), else rtcIntersect1 (ray_intersect())
    bool hit;
};

/// Sees every query any Scene sends to Embree, on the thread that sent it (so from every render
/// thread at once), after Embree has answered. Rays Embree cannot trace (a NaN direction, say)
/// are not sent, so not seen.
class RayQueryObserver {
public:
    virtual ~RayQueryObserver();
    virtual void observe(const RayQuery &query) = 0;
};

class SceneQueries {
public:
    /// Makes `observer` (null: none) see the queries of every scene until it is replaced;
    /// returns the one it replaces. Not while a render runs.
    static RayQueryObserver *set_observer(RayQueryObserver *observer);
    /// Sends `count` queries again to the Embree scene of `scene`, in order, on the calling
    /// thread, exactly as Scene sends them and with nothing else around them. Returns how many
    /// answers (hit or not) differ from the queries' `hit`.
    static uint64_t resend(const Scene &scene, const RayQuery *queries, size_t count);
};

} // namespace facet::detail
