#include "ray_recording.h"

#include <facet/logger.h>

#include <algorithm>

namespace facet {

namespace {

/// The calling thread's log and the recording it belongs to: a thread takes a new log the first
/// time it sends a query during a recording. Recording ids are never reused, so a log of an
/// earlier recording is never written again.
thread_local RayRecording::ThreadLog *t_log = nullptr;
thread_local uint64_t t_log_recording = 0;
std::atomic<uint64_t> g_last_recording{0};

} // namespace

RayRecording::RayRecording(size_t max_rays)
    : m_id(g_last_recording.fetch_add(1, std::memory_order_relaxed) + 1), m_budget(max_rays) {
    if (detail::RayQueryObserver *other = detail::SceneQueries::set_observer(this)) {
        detail::SceneQueries::set_observer(other);
        FACET_THROW("a recording of Embree queries is already running");
    }
    m_recording = true;
}

RayRecording::~RayRecording() { stop(); }

void RayRecording::stop() {
    if (!m_recording) return;
    detail::SceneQueries::set_observer(nullptr);
    m_recording = false;
}

void RayRecording::observe(const detail::RayQuery &query) {
    if (t_log_recording != m_id) {
        std::lock_guard<std::mutex> lock(m_mutex);
        m_logs.push_back(std::make_unique<ThreadLog>());
        t_log = m_logs.back().get();
        t_log_recording = m_id;
    }
    ThreadLog &log = *t_log;
    if (log.room == 0) {
        // The budget is claimed 4096 queries at a time, one atomic operation per block.
        size_t budget = m_budget.load(std::memory_order_relaxed), claim = 0;
        do {
            claim = std::min<size_t>(budget, 4096);
            if (claim == 0) return;
        } while (
            !m_budget.compare_exchange_weak(budget, budget - claim, std::memory_order_relaxed));
        log.room = claim;
    }
    log.queries.push_back(query);
    --log.room;
}

RayRecording::Replay RayRecording::replay(const Scene &scene) const {
    Replay replay;
    for (const std::unique_ptr<ThreadLog> &log : m_logs) {
        replay.rays += log->queries.size();
        replay.differing +=
            detail::SceneQueries::resend(scene, log->queries.data(), log->queries.size());
    }
    return replay;
}

} // namespace facet
