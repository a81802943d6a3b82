// The machinery of core's render loop: threads, the progress line, the stop condition, the pass
// schedule, sample seeds and the in-order merge of finished blocks (render_loop.h).
#include "render_loop.h"

#include <facet/film.h>
#include <facet/logger.h>
#include <facet/random.h>
#include <facet/render.h>

#include <sys/ioctl.h>
#include <sys/resource.h>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <pmmintrin.h>
#include <thread>
#include <unistd.h>
#include <xmmintrin.h>

namespace facet {

namespace {

/// Sets flush-to-zero / denormals-are-zero for the lifetime of the object (Embree wants both).
class ScopedFlushToZero {
public:
    ScopedFlushToZero() : m_csr(_mm_getcsr()) {
        _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
        _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    }
    ~ScopedFlushToZero() { _mm_setcsr(m_csr); }

private:
    unsigned int m_csr;
};

/// One line on a terminal: "Rendering [=====     ] 42% (1.2s, ETA 1.6s)".
class ProgressLine {
public:
    explicit ProgressLine(bool enabled) : m_enabled(enabled && ::isatty(2)) {}
    bool enabled() const { return m_enabled; }

    /// Redraws at most every 500 ms unless `force`.
    void update(size_t done, size_t total, double elapsed, bool force = false) {
        if (!m_enabled || total == 0) return;
        if (!force && elapsed - m_last < 0.5) return;
        m_last = elapsed;
        const double frac = double(done) / double(total);
        std::string eta = done > 0 && done < total
                              ? fmt::format(", ETA {:.1f}s", elapsed * (1.0 - frac) / frac)
                              : "";
        const std::string tail =
            fmt::format(" {:3d}% ({:.1f}s{})", int(frac * 100.0), elapsed, eta);
        // The line fits the terminal (one column spare: a full line would wrap on some
        // terminals): the bar shrinks, then goes, then the line is cut.
        const size_t columns = terminal_columns() - 1;
        const size_t room = columns > tail.size() + 12 ? columns - tail.size() - 12 : 0;
        const size_t width = std::min<size_t>(40, room);
        std::string line = "Rendering";
        if (width >= 5) {
            const size_t filled = std::min(width, size_t(frac * double(width) + 0.5));
            line += " [" + std::string(filled, '=') + std::string(width - filled, ' ') + "]";
        }
        line += tail;
        if (line.size() > columns) line.resize(columns);
        // Pad to clear what a longer earlier line left behind (within the terminal).
        const size_t drawn = line.size();
        if (drawn < m_width) line.append(m_width - drawn, ' ');
        m_width = drawn;
        line.insert(0, "\r");
        std::fputs(line.c_str(), stderr);
        std::fflush(stderr);
        m_drawn = true;
    }
    void finish() {
        if (m_enabled && m_drawn) std::fputs("\n", stderr);
    }
    bool drawn() const { return m_drawn; }

private:
    /// Columns of the terminal on stderr ($COLUMNS, else 80, when it does not say).
    static size_t terminal_columns() {
        struct winsize ws {};
        if (::ioctl(2, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0)
            return std::max<size_t>(ws.ws_col, 2);
        if (const char *c = std::getenv("COLUMNS"))
            if (int n = std::atoi(c); n > 1) return size_t(n);
        return 80;
    }

    bool m_enabled;
    bool m_drawn = false;
    double m_last = -1.0;
    size_t m_width = 0;
};

} // namespace

uint64_t sample_stream_seed(uint64_t seed, uint64_t index) {
    uint64_t h = tea_hash(uint32_t(index), uint32_t(seed) ^ uint32_t(index >> 32));
    return h ^ (uint64_t(uint32_t(seed >> 32)) << 32);
}

/// sample_stream_seed() of indices first .. first + 3, bit for bit, for the instructions of one
/// (the four hashes run in the lanes of one register).
void sample_stream_seeds4(uint64_t seed, uint64_t first, uint64_t (&out)[4]) {
    uint32_t v0[4], v1[4];
    for (int k = 0; k < 4; ++k) {
        const uint64_t index = first + uint64_t(k);
        v0[k] = uint32_t(index);
        v1[k] = uint32_t(seed) ^ uint32_t(index >> 32);
    }
    tea_hash4(v0, v1, out);
    for (uint64_t &h : out) h ^= uint64_t(uint32_t(seed >> 32)) << 32;
}

// ---------------------------------------------------------------------------------------------
// BlockMerger

BlockMerger::BlockMerger(FilmBuffer &film, bool splat, size_t group)
    : m_film(film), m_splat(splat), m_group(std::max<size_t>(group, 1)) {}
BlockMerger::~BlockMerger() = default;

std::unique_ptr<ImageBlock> BlockMerger::acquire() {
    std::lock_guard<std::mutex> lock(m_mutex);
    if (m_free.empty()) return std::make_unique<ImageBlock>();
    auto b = std::move(m_free.back());
    m_free.pop_back();
    return b;
}

void BlockMerger::merge(const ImageBlock &block) {
    if (m_splat)
        m_film.put_splats(block);
    else
        m_film.put_block(block);
}

size_t BlockMerger::submit(size_t index, std::unique_ptr<ImageBlock> block) {
    std::lock_guard<std::mutex> lock(m_mutex);
    m_pending.emplace(index, std::move(block));
    ++m_finished;
    // Merge every whole group that is next in order: the keys are distinct and sorted, so the
    // group is complete when its first and last blocks are the first m_group pending ones.
    while (m_pending.size() >= m_group && m_pending.begin()->first == m_next &&
           std::next(m_pending.begin(), std::ptrdiff_t(m_group - 1))->first ==
               m_next + m_group - 1) {
        for (size_t k = 0; k < m_group; ++k) {
            auto it = m_pending.begin();
            merge(*it->second);
            m_free.push_back(std::move(it->second));
            m_pending.erase(it);
        }
        m_next += m_group;
    }
    return m_finished;
}

void BlockMerger::release(std::unique_ptr<ImageBlock> block) {
    std::lock_guard<std::mutex> lock(m_mutex);
    m_free.push_back(std::move(block));
}

void BlockMerger::flush() {
    std::lock_guard<std::mutex> lock(m_mutex);
    if (m_group == 1) {
        for (auto &[index, block] : m_pending) merge(*block);
        m_next += m_pending.size();
    }
    m_pending.clear();
}

size_t BlockMerger::merged() {
    std::lock_guard<std::mutex> lock(m_mutex);
    return m_next;
}

size_t BlockMerger::finished() {
    std::lock_guard<std::mutex> lock(m_mutex);
    return m_finished;
}

// ---------------------------------------------------------------------------------------------
// Work units on the render threads

double process_cpu_seconds() {
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);
    return double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
           1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

int hardware_threads() { return std::max(1, tbb::info::default_concurrency()); }

int capped_thread_count(int threads) {
    if (threads < 0)
        FACET_THROW("the thread count must be positive (or 0 for all cores), got {}", threads);
    const int hardware = hardware_threads();
    return threads > 0 ? std::min(threads, hardware) : hardware;
}

int render_thread_count(const RenderOptions &opts) { return capped_thread_count(opts.threads); }

bool StopCondition::timed_out() const { return timeout > 0.0 && seconds_since(start) >= timeout; }

namespace {

/// The stop condition of the render whose work unit the thread runs (render_should_stop()).
thread_local const StopCondition *t_render_stop = nullptr;

} // namespace

bool render_should_stop() {
    const StopCondition *stop = t_render_stop;
    return stop && (*stop)();
}

std::vector<uint32_t> progressive_schedule(uint32_t spp, uint32_t samples_per_pass, uint32_t cap) {
    cap = std::max(cap, 1u);
    std::vector<uint32_t> pass_start; // pass p takes samples [pass_start[p], pass_start[p + 1])
    uint32_t next = 0, size = 1;
    while (next < spp) {
        pass_start.push_back(next);
        const uint32_t take =
            samples_per_pass > 0 ? std::min(samples_per_pass, spp) : std::min(size, cap);
        next += std::min(take, spp - next);
        if (next > 1) size = std::min(cap, size * 2);
    }
    pass_start.push_back(spp);
    return pass_start;
}

WorkUnitsRun run_units(size_t count, const RenderOptions &opts, const StopCondition &stop,
                       const std::atomic<uint64_t> &work_done, uint64_t work_total,
                       const std::function<std::function<void(size_t)>()> &make_worker) {
    const int threads = capped_thread_count(opts.threads);
    const auto start = Clock::now();
    std::unique_ptr<tbb::global_control> allow;
    if (opts.threads > 0)
        allow = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                      size_t(threads));
    tbb::task_arena arena(threads);
    const int workers = arena.max_concurrency();

    ProgressLine progress(opts.progress);
    std::atomic<size_t> next_unit{0};
    std::atomic<bool> cancelled{false}, timed_out{false};
    std::atomic<bool> first_done{false};
    double first_unit_cpu = 0.0; // written once, by the thread that finished the first unit

    std::mutex monitor_mutex;
    std::condition_variable monitor_cv;
    bool finished = false, announced = false;
    auto announce_stop = [&] {
        // Under monitor_mutex. The line ends the progress line; the render stops within
        // moments, keeping the passes finished so far.
        if (announced) return;
        announced = true;
        std::fputs(progress.drawn() ? "\nfacet: stopping...\n" : "facet: stopping...\n", stderr);
        std::fflush(stderr);
    };
    std::thread monitor([&] {
        std::unique_lock<std::mutex> lock(monitor_mutex);
        while (
            !monitor_cv.wait_for(lock, std::chrono::milliseconds(50), [&] { return finished; })) {
            if (stop.cancelled()) announce_stop();
            if (!announced) progress.update(work_done.load(), work_total, seconds_since(start));
            if (opts.on_progress && work_total > 0)
                opts.on_progress(double(work_done.load()) / double(work_total));
        }
    });

    auto worker = [&](int) {
        ScopedFlushToZero ftz;
        // render_should_stop() on this thread asks `stop` (the previous one again afterwards).
        struct ScopedStop {
            const StopCondition *saved = t_render_stop;
            explicit ScopedStop(const StopCondition *s) { t_render_stop = s; }
            ~ScopedStop() { t_render_stop = saved; }
        } scoped_stop(&stop);
        std::function<void(size_t)> run = make_worker();
        for (;;) {
            if (stop.cancelled()) {
                cancelled = true;
                return;
            }
            if (stop.timed_out()) {
                timed_out = true;
                return;
            }
            const size_t index = next_unit.fetch_add(1);
            if (index >= count) return;
            run(index);
            if (!first_done.load(std::memory_order_relaxed) && !first_done.exchange(true)) {
                first_unit_cpu = process_cpu_seconds();
                if (opts.on_first_block) opts.on_first_block();
            }
        }
    };
    try {
        arena.execute([&] { tbb::parallel_for(0, workers, worker, tbb::simple_partitioner()); });
    } catch (...) {
        {
            std::lock_guard<std::mutex> lock(monitor_mutex);
            finished = true;
        }
        monitor_cv.notify_all();
        monitor.join();
        throw;
    }

    WorkUnitsRun run;
    run.seconds = seconds_since(start);
    run.first_unit_cpu_seconds = first_unit_cpu; // the threads were joined: no race
    run.cancelled = cancelled || stop.cancelled();
    run.timed_out = !run.cancelled && (timed_out || stop.timed_out());
    {
        std::lock_guard<std::mutex> lock(monitor_mutex);
        finished = true;
        if (run.cancelled) announce_stop();
        if (!announced) progress.update(work_done.load(), work_total, run.seconds, true);
        if (opts.on_progress && work_total > 0)
            opts.on_progress(double(work_done.load()) / double(work_total));
    }
    monitor_cv.notify_all();
    monitor.join();
    if (!announced) progress.finish();
    return run;
}

} // namespace facet
