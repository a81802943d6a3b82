#pragma once
// Private to libfacet: the machinery of core's render loop (render.cpp), not installed. Plugins
// see only render.h and integrator.h.

#include <facet/fwd.h>
#include <facet/render.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

namespace facet {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Seed of one sample stream (a pixel, a light path) from the render seed and an index.
uint64_t sample_stream_seed(uint64_t seed, uint64_t index);
/// sample_stream_seed() of indices first .. first + 3, bit for bit, for the instructions of one
/// (the four hashes run in the lanes of one register).
void sample_stream_seeds4(uint64_t seed, uint64_t first, uint64_t (&out)[4]);

/// Image blocks that finished, merged into the render's buffer strictly in index order, so the
/// result does not depend on which thread finished first. Also recycles block memory. `splat`
/// blocks go through FilmBuffer::put_splats(), the others through FilmBuffer::put_block().
class BlockMerger {
public:
    /// With `group` > 1 the blocks are merged only in whole groups [g·group, (g+1)·group) (the
    /// blocks of one pass over the image), so the buffer only ever holds whole passes.
    BlockMerger(FilmBuffer &film, bool splat = false, size_t group = 1);
    ~BlockMerger();
    std::unique_ptr<ImageBlock> acquire();
    /// Hands in block `index` (each index in [0, n) exactly once, or not at all after a
    /// cancellation); merges every block that is now next in order. Returns the number of blocks
    /// handed in so far.
    size_t submit(size_t index, std::unique_ptr<ImageBlock> block);
    /// Takes back a block that is not handed in (a unit abandoned by a stop).
    void release(std::unique_ptr<ImageBlock> block);
    /// After a cancelled render: merges what is left, still in index order (gaps are skipped);
    /// with groups, the blocks of incomplete groups are dropped instead.
    void flush();
    size_t finished();
    /// Number of blocks merged into the buffer (whole groups only, with groups).
    size_t merged();

private:
    void merge(const ImageBlock &block);
    FilmBuffer &m_film;
    bool m_splat;
    std::mutex m_mutex;
    std::map<size_t, std::unique_ptr<ImageBlock>> m_pending;
    std::vector<std::unique_ptr<ImageBlock>> m_free;
    size_t m_group = 1;
    size_t m_next = 0, m_finished = 0;
};

/// When a render stops early: the cancel flag is set, or `timeout` seconds (if > 0) have passed
/// since `start`. Cheap enough to ask every few samples.
struct StopCondition {
    const std::atomic<bool> *cancel = nullptr;
    double timeout = -1.0;
    Clock::time_point start = Clock::now();
    bool cancelled() const { return cancel && cancel->load(std::memory_order_relaxed); }
    bool timed_out() const;
    bool operator()() const { return cancelled() || timed_out(); }
};

/// The passes of a progressive render of `spp` samples per pixel: pass p takes the samples
/// [s[p], s[p + 1]) of every pixel (s[0] = 0, the last is spp). With `samples_per_pass` > 0
/// passes of that many; else 1, 1, 2, 4, ... samples, at most `cap` per pass. The render's buffer
/// holds whole passes only (BlockMerger groups), so a stopped render has every pixel at the same
/// spp, s[passes done].
std::vector<uint32_t> progressive_schedule(uint32_t spp, uint32_t samples_per_pass, uint32_t cap);

/// What run_units() did.
struct WorkUnitsRun {
    bool cancelled = false; ///< stopped by the cancel flag before every unit was taken
    bool timed_out = false; ///< stopped by the timeout before every unit was taken
    double seconds = 0.0;
    /// CPU time of the whole process (all its threads, from its start) when the first unit was
    /// done; 0 when none was.
    double first_unit_cpu_seconds = 0.0;
};

/// Runs work units 0..count-1 on opts.threads threads (a TBB arena; every thread sets
/// flush-to-zero). `make_worker` is called once per thread and returns the function that runs
/// one unit; each thread takes the next unit index until none is left or `stop` says so; a unit
/// may itself return early (without handing in its result) when `stop` says so. The progress
/// line shows work_done / work_total, redrawn by a monitor thread (so it moves while long units
/// run), which also says "stopping" at the first cancellation.
WorkUnitsRun run_units(size_t count, const RenderOptions &opts, const StopCondition &stop,
                       const std::atomic<uint64_t> &work_done, uint64_t work_total,
                       const std::function<std::function<void(size_t)>()> &make_worker);

} // namespace facet
