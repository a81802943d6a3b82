#include "scene_description.h"

#include <facet/film.h>
#include <facet/integrator.h>
#include <facet/logger.h>
#include <facet/properties.h>
#include <facet/random.h>
#include <facet/render.h>
#include <facet/sampler.h>
#include <facet/scene.h>
#include <facet/sensor.h>

#include <sys/ioctl.h>
#include <sys/resource.h>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <mutex>
#include <pmmintrin.h>
#include <signal.h>
#include <thread>
#include <unistd.h>
#include <xmmintrin.h>

namespace facet {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

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

namespace {

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

} // namespace

// ---------------------------------------------------------------------------------------------
// BlockMerger

BlockMerger::BlockMerger(Film &film, bool splat, size_t group)
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

// ---------------------------------------------------------------------------------------------
// The sampling integrators' render loop

double read_timeout(const Properties &props) {
    const double timeout = props.get_float("timeout", -1.0);
    if (std::isnan(timeout))
        FACET_THROW_AT(props.location("timeout"),
                       "timeout must be a number of seconds (<= 0 for none), got {}", timeout);
    return timeout;
}

// Depths are path lengths counted in 32 bits (4294967295: as good as unbounded); a larger value
// is a mistake, not a wish for longer paths.
uint32_t read_max_depth(const Properties &props, const char *plugin) {
    int64_t max_depth = props.get_int("max_depth", -1);
    if (max_depth < -1 || max_depth > int64_t(UINT32_MAX))
        FACET_THROW_AT(props.location("max_depth"),
                       "{}: max_depth must be -1 (unbounded) or a value in [0, {}], got {}", plugin,
                       UINT32_MAX, max_depth);
    return max_depth == -1 ? std::numeric_limits<uint32_t>::max()
                           : uint32_t(std::min<int64_t>(max_depth, 0xfffffffe));
}

uint32_t read_rr_depth(const Properties &props, const char *plugin) {
    int64_t rr_depth = props.get_int("rr_depth", 5);
    if (rr_depth <= 0 || rr_depth > int64_t(UINT32_MAX))
        FACET_THROW_AT(props.location("rr_depth"),
                       "{}: rr_depth must be a value in [1, {}], got {}", plugin, UINT32_MAX,
                       rr_depth);
    return uint32_t(rr_depth);
}

uint32_t read_samples_per_pass(const Properties &props) {
    if (!props.has("samples_per_pass")) {
        props.get_int("samples_per_pass", 0); // recorded as requested (parameter tables)
        return 0;
    }
    int64_t v = props.get_int("samples_per_pass");
    if (v <= 0 || v > int64_t(UINT32_MAX))
        FACET_THROW_AT(props.location("samples_per_pass"),
                       "samples_per_pass must be a positive number of samples, got {}", v);
    return uint32_t(v);
}

SamplingIntegrator::SamplingIntegrator(const Properties &props) {
    m_timeout = read_timeout(props);
    m_samples_per_pass = read_samples_per_pass(props);
    int64_t bs = props.get_int("block_size", 0);
    if (bs < 0 || bs > 4096)
        FACET_THROW_AT(props.location("block_size"),
                       "block_size must be 0 (automatic) or a number of pixels up to 4096, got {}",
                       bs);
    m_block_size = int(bs);
}

SampleRange render_sample_range(const Sensor &sensor, const RenderOptions &opts) {
    if (opts.spp < 0) FACET_THROW("the sample count must be positive, got {}", opts.spp);
    if (opts.pass_count < 1)
        FACET_THROW("the pass count must be at least 1, got {}", opts.pass_count);
    if (opts.pass_index < -1 || opts.pass_index >= opts.pass_count)
        FACET_THROW("the pass index must lie in 0..{} (pass_count {}), or be -1 for all of them, "
                    "got {}",
                    opts.pass_count - 1, opts.pass_count, opts.pass_index);
    // Samplers may round the count (stratified ones to a square); seeding once lets them do so
    // before the count is read back.
    std::unique_ptr<Sampler> sampler = sensor.sampler().clone();
    const uint64_t per_part = opts.spp > 0 ? uint64_t(opts.spp) : sensor.sampler().sample_count();
    const uint64_t whole = per_part * uint64_t(opts.pass_count);
    if (whole > UINT32_MAX / 2)
        FACET_THROW("{} passes of {} samples per pixel are too many (at most {} in all)",
                    opts.pass_count, per_part, UINT32_MAX / 2);
    sampler->set_sample_count(uint32_t(whole));
    sampler->seed(0);
    SampleRange range;
    range.total = std::max(sampler->sample_count(), 1u);
    if (opts.pass_index < 0) { // all the passes
        range.count = range.total;
        return range;
    }
    const uint64_t n = uint64_t(opts.pass_count), i = uint64_t(opts.pass_index);
    range.first = uint32_t(uint64_t(range.total) * i / n);
    range.count = uint32_t(uint64_t(range.total) * (i + 1) / n) - range.first;
    return range;
}

RenderResult SamplingIntegrator::render(const Scene &scene, const Sensor &sensor,
                                        const RenderOptions &opts) const {
    const auto start = Clock::now();
    if (opts.block_size < 0)
        FACET_THROW("the block size must be positive, got {}", opts.block_size);
    const int bs = opts.block_size > 0 ? opts.block_size : m_block_size > 0 ? m_block_size : 32;

    Film &film = sensor.film();
    const Sampler &proto_sampler = sensor.sampler();
    const SampleRange range = render_sample_range(sensor, opts);
    const uint64_t asked =
        uint64_t(opts.spp > 0 ? uint32_t(opts.spp) : proto_sampler.sample_count()) *
        uint64_t(opts.pass_count);
    if (range.total != asked)
        FACET_LOG(Info, "The sampler takes {} samples per pixel instead of {}", range.total, asked);
    if (range.count == 0)
        FACET_THROW("pass {} of {} has no samples: the {} samples per pixel of the whole render "
                    "cannot be split into {} parts",
                    opts.pass_index, opts.pass_count, range.total, opts.pass_count);
    // The per-thread samplers are clones of this one, set to the whole render's sample count.
    std::unique_ptr<Sampler> base_sampler = proto_sampler.clone();
    base_sampler->set_sample_count(range.total);
    base_sampler->seed(0);
    const uint32_t spp = range.count;
    if (m_samples_per_pass > 0 && spp % std::min(m_samples_per_pass, spp) != 0)
        FACET_THROW("the sample count ({}) must be a multiple of samples_per_pass ({})", spp,
                    m_samples_per_pass);
    const uint64_t seed = opts.seed + proto_sampler.base_seed();
    const std::vector<std::string> aov_names = this->aov_names();
    const int aov_count = int(aov_names.size());
    film.prepare(aov_names);

    const Point2i film_size = film.size(), crop_offset = film.crop_offset(),
                  crop_size = film.crop_size();
    const uint64_t film_pixels = uint64_t(film_size.x) * uint64_t(film_size.y);

    // Progressive rendering: the samples are taken in passes over the whole image, and the film
    // only ever holds whole passes, so a render stopped at any moment has every pixel at the
    // same spp. Without samples_per_pass the passes take 1, 1, 2, 4, ... samples, at most
    // about 2^18 samples over the film each (a power of two): early stops keep a useful image
    // and a stop throws away at most one pass. The schedule depends only on the film size and
    // the part's samples, never on the crop or the thread count.
    uint32_t cap = 1;
    while (uint64_t(cap) * 2 * film_pixels <= (uint64_t(1) << 18) && cap < (1u << 30)) cap *= 2;
    const std::vector<uint32_t> pass_start = progressive_schedule(spp, m_samples_per_pass, cap);
    const size_t passes = pass_start.size() - 1;

    const int border = ImageBlock::border_for(film.rfilter());
    // The pixels whose samples reach the crop window through the filter are sampled, in blocks
    // of the grid of the whole film: a crop's pixels receive the same samples, in the same
    // order, as in a render of the whole film.
    const int rx0 = std::max(0, crop_offset.x - border), ry0 = std::max(0, crop_offset.y - border);
    const int rx1 = std::min(film_size.x, crop_offset.x + crop_size.x + border);
    const int ry1 = std::min(film_size.y, crop_offset.y + crop_size.y + border);
    const int gx0 = rx0 / bs, gy0 = ry0 / bs;
    const int blocks_x = (rx1 + bs - 1) / bs - gx0, blocks_y = (ry1 + bs - 1) / bs - gy0;
    const size_t blocks = size_t(blocks_x) * size_t(blocks_y);
    const size_t total = blocks * passes;
    const uint64_t sampled_pixels = uint64_t(rx1 - rx0) * uint64_t(ry1 - ry0);
    const ReconstructionFilter &filter = film.rfilter();
    const bool needs_aperture = sensor.needs_aperture_sample();
    const Point2f inv_film_size(1.f / float(film_size.x), 1.f / float(film_size.y));

    FACET_LOG(Info, "Starting render job ({}x{}, {} samples in {} pass{}{}, {} threads)",
              crop_size.x, crop_size.y, spp, passes, passes == 1 ? "" : "es",
              opts.pass_count > 1 ? fmt::format(", part {} of {}", opts.pass_index, opts.pass_count)
                                  : "",
              render_thread_count(opts));
    if (m_timeout > 0.0) FACET_LOG(Info, "Timeout: {:.2f} seconds", m_timeout);

    StopCondition stop{opts.cancel, m_timeout, start};
    BlockMerger merger(film, /*splat=*/false, blocks);
    std::atomic<uint64_t> samples_done{0}, invalid_samples{0};
    std::atomic<uint64_t> first_invalid_pixel{UINT64_MAX};

    // Unit `index` is block index % blocks of pass index / blocks; blocks are in scanline order.
    auto make_worker = [&]() -> std::function<void(size_t)> {
        auto sampler = std::shared_ptr<Sampler>(base_sampler->clone());
        auto aovs = std::make_shared<std::vector<float>>(size_t(aov_count) + 1, 0.f);
        return [&, sampler, aovs](size_t index) {
            const size_t pass = index / blocks;
            const size_t block_index = index % blocks;
            const int bx = gx0 + int(block_index % size_t(blocks_x)),
                      by = gy0 + int(block_index / size_t(blocks_x));
            const Point2i offset(bx * bs, by * bs);
            const Point2i size(std::min(bs, film_size.x - offset.x),
                               std::min(bs, film_size.y - offset.y));
            std::unique_ptr<ImageBlock> block = merger.acquire();
            block->reset(offset, size, border, aov_count);
            const int x0 = std::max(offset.x, rx0), x1 = std::min(offset.x + size.x, rx1);
            const int y0 = std::max(offset.y, ry0), y1 = std::min(offset.y + size.y, ry1);
            const uint32_t first = range.first + pass_start[pass],
                           last = range.first + pass_start[pass + 1];

            uint64_t invalid = 0;
            uint32_t until_check = 1;
            uint64_t pixel_seeds[4]; // of the row's pixels x0 + 4i .. x0 + 4i + 3
            for (int y = y0; y < y1; ++y) {
                for (int x = x0; x < x1; ++x) {
                    const uint64_t pixel_index = uint64_t(y) * uint64_t(film_size.x) + uint64_t(x);
                    if ((x - x0) % 4 == 0) sample_stream_seeds4(seed, pixel_index, pixel_seeds);
                    sampler->seed(pixel_seeds[(x - x0) % 4]);
                    for (uint32_t s = first; s < last; ++s) {
                        // A stop abandons the unit (its pass is incomplete and is dropped).
                        if (--until_check == 0) {
                            until_check = 16;
                            if (stop()) {
                                merger.release(std::move(block));
                                return;
                            }
                        }
                        sampler->set_sample_index(s);
                        const Point2f u = sampler->draw_2d();
                        const Point2f pos(float(x) + u.x, float(y) + u.y);
                        const Point2f aperture =
                            needs_aperture ? sampler->draw_2d() : Point2f(0.5f, 0.5f);
                        auto [ray, weight] = sensor.sample_ray(0.f, pos * inv_film_size, aperture);
                        // Integrators need not write every AOV for every sample (e.g. on a miss).
                        // (The buffer's extra float only keeps data() valid: nothing reads it.)
                        if (aov_count > 0) std::fill_n(aovs->data(), aov_count, 0.f);
                        Color3f L = sample(scene, *sampler, ray, aovs->data()) * weight;
                        bool valid = L.is_finite();
                        for (int k = 0; k < aov_count; ++k)
                            valid = valid && std::isfinite((*aovs)[size_t(k)]);
                        if (!valid) {
                            // One bad sample must not turn the whole pixel into NaN: drop it.
                            if (invalid++ == 0) {
                                uint64_t cur = first_invalid_pixel.load();
                                while (
                                    pixel_index < cur &&
                                    !first_invalid_pixel.compare_exchange_weak(cur, pixel_index)) {}
                            }
                            continue;
                        }
                        block->put(pos, L, aovs->data(), filter);
                    }
                }
                samples_done.fetch_add(uint64_t(x1 - x0) * (last - first),
                                       std::memory_order_relaxed);
            }
            // An integrator may have cut its last samples short (render_should_stop()); a stop
            // stays true once it is, so this sees it.
            if (stop()) {
                merger.release(std::move(block));
                return;
            }
            invalid_samples += invalid;
            merger.submit(index, std::move(block));
        };
    };
    WorkUnitsRun run =
        run_units(total, opts, stop, samples_done, sampled_pixels * spp, make_worker);
    merger.flush();

    RenderResult result;
    const size_t passes_done = merger.merged() / std::max<size_t>(blocks, 1);
    result.blocks_total = total;
    result.blocks_done = merger.merged();
    result.first_block_cpu_seconds = run.first_unit_cpu_seconds;
    result.cancelled = passes_done < passes;
    result.timed_out = result.cancelled && run.timed_out;
    result.spp_target = spp;
    result.spp = pass_start[passes_done];
    result.samples = sampled_pixels * result.spp;
    result.sample_offset = range.first;
    result.spp_total = range.total;
    if (result.cancelled) {
        const std::string what = fmt::format(
            "after {} of {} passes: the image has {} of {} samples per pixel{}", passes_done,
            passes, result.spp, spp, result.spp == 0 ? " (no pass was finished: it is black)" : "");
        if (result.timed_out)
            FACET_LOG(Warn, "Timeout of {:.2f}s reached {}", m_timeout, what);
        else
            FACET_LOG(Warn, "Rendering stopped {}", what);
    }
    if (invalid_samples > 0) {
        uint64_t p = first_invalid_pixel.load();
        FACET_LOG(Warn,
                  "{} samples had NaN or infinite radiance and were dropped (the first at pixel "
                  "({}, {}))",
                  invalid_samples.load(), p % uint64_t(film_size.x), p / uint64_t(film_size.x));
    }
    result.sampling_seconds = run.seconds;
    const auto develop_start = Clock::now();
    result.image = film.develop();
    result.develop_seconds = seconds_since(develop_start);
    result.seconds = seconds_since(start);
    return result;
}

namespace {

/// A part's raw channels (Film::raw_channel_names) after its developed ones.
void append_raw_channels(Image &image, const Film &film) {
    const std::vector<std::string> names = film.raw_channel_names();
    const std::vector<float> raw = film.raw_sums();
    const size_t pixels = size_t(image.width) * size_t(image.height), nr = names.size();
    const size_t nd = size_t(image.channels), n = nd + nr;
    if (raw.size() != pixels * nr)
        FACET_THROW("the film's raw sums ({} values) do not match its {}x{} image", raw.size(),
                    image.width, image.height);
    std::vector<float> data(pixels * n);
    for (size_t i = 0; i < pixels; ++i) {
        std::copy_n(image.data.data() + i * nd, nd, data.data() + i * n);
        std::copy_n(raw.data() + i * nr, nr, data.data() + i * n + nd);
    }
    image.data = std::move(data);
    image.channels = int(n);
    image.channel_names.insert(image.channel_names.end(), names.begin(), names.end());
}

} // namespace

/// Where the scene file declares `object` (its tag); none for objects not loaded from a file.
static Location declared_at(const Scene &scene, const Object *object) {
    if (const std::shared_ptr<SceneDescription> &d = scene.description())
        for (const SceneDescription::Node &node : d->nodes)
            if (node.instance.get() == object) return node.location;
    return {};
}

/// Every pass of opts.pass_count, one after the other, combined as a merge of the parts combines
/// them: the raw sums of each pass rounded to float (what a part's file holds), added in pass
/// order in double and developed once. The result is bit-identical to the merge of the parts.
static RenderResult render_all_passes(const Scene &scene, const Sensor &sensor,
                                      const RenderOptions &opts) {
    const auto start = Clock::now();
    Film &film = sensor.film();
    RenderResult all;
    std::vector<double> sums;
    std::vector<std::string> raw_names;
    for (int i = 0; i < opts.pass_count; ++i) {
        RenderOptions part = opts;
        part.pass_index = i;
        if (opts.on_progress) // the fraction of the whole, not of the part
            part.on_progress = [&opts, i](double f) {
                opts.on_progress((double(i) + f) / double(opts.pass_count));
            };
        RenderResult r = render(scene, sensor, part);
        const std::vector<std::string> &names = r.image.channel_names;
        if (names.size() < 3 || names[0] != "R" || names[1] != "G" || names[2] != "B")
            FACET_THROW("a render of {} passes in one process develops R, G, B: the film {} "
                        "develops into {} (use the pixel format rgb or rgba, or render the passes "
                        "apart)",
                        opts.pass_count, film.to_string(), names.empty() ? "nothing" : names[0]);
        const std::vector<float> raw = film.raw_sums();
        if (i == 0) {
            raw_names = film.raw_channel_names();
            sums.assign(raw.size(), 0.0);
            all = r;
        } else {
            if (film.raw_channel_names() != raw_names || raw.size() != sums.size())
                FACET_THROW("pass {} of {} has other raw channels than pass 0", i, opts.pass_count);
            all.blocks_done += r.blocks_done;
            all.blocks_total += r.blocks_total;
            all.samples += r.samples;
            all.spp += r.spp;
            all.sampling_seconds += r.sampling_seconds;
            all.develop_seconds += r.develop_seconds;
        }
        for (size_t k = 0; k < sums.size(); ++k) sums[k] += double(raw[k]);
        if (r.cancelled) {
            all.cancelled = true;
            all.timed_out = r.timed_out;
            break;
        }
    }
    const SampleRange range = render_sample_range(sensor, opts);
    // As a merge: splats are divided by the light paths per pixel of all the passes.
    all.image = film.develop_sums(sums, all.spp > 0 ? 1.0 / double(all.spp) : 1.0);
    all.spp_target = range.total;
    all.spp_total = range.total;
    all.sample_offset = 0;
    all.pass_index = 0;
    all.pass_count = 1;
    all.seconds = seconds_since(start);
    return all;
}

RenderResult Integrator::render(const Scene &, const Sensor &, const RenderOptions &) const {
    FACET_THROW("the integrator {} cannot render images", to_string());
}

RenderResult render(const Scene &scene, const Sensor &sensor, const RenderOptions &opts) {
    if (opts.threads > hardware_threads()) {
        FACET_LOG(Warn, "{} render threads asked for: using the {} hardware threads", opts.threads,
                  hardware_threads());
        RenderOptions capped = opts;
        capped.threads = hardware_threads();
        return render(scene, sensor, capped);
    }
    const Scene::RenderLock lock(scene); // no update() of the scene while it renders
    if (!scene.integrator()) FACET_THROW("the scene has no integrator");
    const Integrator &integrator = *scene.integrator();
    Film &film = sensor.film();
    const auto &c = opts.crop;
    if (c[0] == 0 && c[1] == 0 && c[2] == 0 && c[3] == 0) {
        film.reset_crop_window();
    } else {
        if (c[2] <= c[0] || c[3] <= c[1])
            FACET_THROW("the crop window x0 y0 x1 y1 = {} {} {} {} is empty (x1 and y1 are "
                        "exclusive: they must be greater than x0 and y0)",
                        c[0], c[1], c[2], c[3]);
        film.set_crop_window(Point2i(c[0], c[1]), Point2i(c[2] - c[0], c[3] - c[1]));
    }
    const SampleRange range = render_sample_range(sensor, opts); // validates the options
    RenderResult result;
    try {
        if (opts.pass_count > 1 && opts.pass_index < 0)
            return render_all_passes(scene, sensor, opts);
        result = integrator.render(scene, sensor, opts);
    } catch (const Error &e) {
        // An integrator's own error (its parameters against the render's sample count, say), at
        // the integrator's place in the scene file.
        const Location at = e.location().valid() ? Location() : declared_at(scene, &integrator);
        if (!at.valid()) throw;
        throw Error(at, e.message());
    }
    if (result.spp_total == 0) {
        // An integrator that does not fill these in renders one whole part.
        if (opts.pass_count != 1)
            FACET_THROW("the integrator {} renders in one part only (it cannot render part {} of "
                        "{})",
                        integrator.to_string(), opts.pass_index, opts.pass_count);
        result.spp_target = range.count;
        result.spp = range.count;
        result.sample_offset = range.first;
        result.spp_total = range.total;
    }
    result.pass_index = opts.pass_index;
    result.pass_count = opts.pass_count;
    const Point2i o = film.crop_offset(), sz = film.crop_size();
    result.crop = {{o.x, o.y, o.x + sz.x, o.y + sz.y}};
    result.film_width = film.size().x;
    result.film_height = film.size().y;
    result.accel_seconds = scene.accel_build_seconds();
    if (result.sampling_seconds == 0.0) result.sampling_seconds = result.seconds;
    if (opts.pass_count > 1) append_raw_channels(result.image, film);
    return result;
}

// ---------------------------------------------------------------------------------------------
// Interrupt handling

namespace {

std::atomic<bool> *g_interrupt_flag = nullptr;
volatile sig_atomic_t g_interrupt_signal = 0; ///< the first signal since the install
std::atomic<unsigned> g_signals_seen{0};      ///< bit `sig` per signal received
std::atomic<bool> g_deferring{false};
struct sigaction g_old_sigint, g_old_sighup, g_old_sigterm;
bool g_handler_installed = false;
static_assert(std::atomic<unsigned>::is_always_lock_free && std::atomic<bool>::is_always_lock_free,
              "the signal handler uses only lock-free atomics (async-signal-safe)");

extern "C" void facet_interrupt_handler(int sig) {
    const int saved_errno = errno;
    if (g_interrupt_signal == 0) g_interrupt_signal = sig;
    if (g_interrupt_flag) g_interrupt_flag->store(true);
    const unsigned bit = 1u << unsigned(sig);
    const bool repeated = (g_signals_seen.fetch_or(bit) & bit) != 0;
    if (!g_deferring.load()) {
        // While rendering, a second signal of the same kind takes the default action, so the
        // user can force quit: the render may take a while to reach a stop, and nothing but its
        // unfinished passes is lost (no output file is open yet).
        struct sigaction dfl;
        std::memset(&dfl, 0, sizeof(dfl));
        dfl.sa_handler = SIG_DFL;
        sigemptyset(&dfl.sa_mask);
        sigaction(sig, &dfl, nullptr);
    } else if (repeated) {
        // While the output is written, even a repeated signal is not fatal: the write is bounded
        // (encoding one image, writing, fsync, reading it back, renaming), force-quitting would
        // throw away the render the user waited for and leave the temporary file behind, and a
        // write stuck in the kernel (a dead network file system) would not run a handler anyway
        // (SIGKILL remains for that). Say why facet has not exited yet.
        static const char msg[] = "facet: still writing the image; exiting once it is complete\n";
        ssize_t ignored = ::write(STDERR_FILENO, msg, sizeof(msg) - 1);
        (void)ignored;
    }
    errno = saved_errno;
}

/// Points SIGINT, SIGHUP and SIGTERM at facet_interrupt_handler (the previous actions into
/// `old_*` when given).
void set_interrupt_actions(struct sigaction *old_int, struct sigaction *old_hup,
                           struct sigaction *old_term) {
    struct sigaction sa;
    std::memset(&sa, 0, sizeof(sa));
    sa.sa_handler = facet_interrupt_handler;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    sigaction(SIGINT, &sa, old_int);
    sigaction(SIGHUP, &sa, old_hup);
    sigaction(SIGTERM, &sa, old_term);
}

} // namespace

void install_interrupt_handler(std::atomic<bool> *flag) {
    if (g_handler_installed) uninstall_interrupt_handler();
    g_interrupt_flag = flag;
    g_interrupt_signal = 0;
    g_signals_seen = 0;
    g_deferring = false;
    set_interrupt_actions(&g_old_sigint, &g_old_sighup, &g_old_sigterm);
    g_handler_installed = true;
}

void defer_interrupts() {
    if (!g_handler_installed) return;
    g_deferring = true;
    // Back from the default action a first signal while rendering left for its kind.
    set_interrupt_actions(nullptr, nullptr, nullptr);
}

int interrupt_signal() { return int(g_interrupt_signal); }

const char *interrupt_signal_name(int sig) {
    switch (sig) {
    case SIGINT:
        return "SIGINT";
    case SIGHUP:
        return "SIGHUP";
    case SIGTERM:
        return "SIGTERM";
    default:
        return "a signal";
    }
}

void uninstall_interrupt_handler() {
    if (!g_handler_installed) return;
    sigaction(SIGINT, &g_old_sigint, nullptr);
    sigaction(SIGHUP, &g_old_sighup, nullptr);
    sigaction(SIGTERM, &g_old_sigterm, nullptr);
    g_interrupt_flag = nullptr;
    g_deferring = false;
    g_handler_installed = false;
}

} // namespace facet
