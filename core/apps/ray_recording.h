#pragma once

// `facet bench`'s recording of the queries a render sends to Embree, and their replay: the
// render's own rays sent again to Embree on one thread with nothing else around them, so that
// their CPU time is Embree's own work. Scene only shows its queries to an observer
// (scene_queries.h, private to libfacet and the facet command); the rest is here.

#include "scene_queries.h"

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

namespace facet {

/// Records the queries every scene sends to Embree, from every thread, with Embree's answers:
/// from construction to stop() (or destruction), the first `max_rays` of them in all. One
/// recording at a time, and none may start or stop while a render runs.
class RayRecording : private detail::RayQueryObserver {
public:
    explicit RayRecording(size_t max_rays);
    ~RayRecording() override;
    RayRecording(const RayRecording &) = delete;
    RayRecording &operator=(const RayRecording &) = delete;

    void stop();

    struct Replay {
        uint64_t rays = 0;      ///< queries sent again
        uint64_t differing = 0; ///< answers (hit or not) that differ from the recorded ones
    };
    /// Sends the recorded queries again to the Embree scene of `scene` (the scene that traced
    /// them, for the time of Embree's work in its render), each thread's in its order, all on
    /// the calling thread. Not while recording.
    Replay replay(const Scene &scene) const;

    /// One thread's queries. Written only by its thread while recording.
    struct ThreadLog {
        std::vector<detail::RayQuery> queries;
        size_t room = 0; ///< queries of the budget this log has claimed and not used yet
    };

private:
    void observe(const detail::RayQuery &query) override;

    const uint64_t m_id; ///< tells this recording's thread logs from an earlier one's
    bool m_recording = false;
    std::atomic<size_t> m_budget; ///< queries that may still be recorded, all threads together
    std::mutex m_mutex;           ///< guards m_logs while recording
    std::vector<std::unique_ptr<ThreadLog>> m_logs;
};

} // namespace facet
