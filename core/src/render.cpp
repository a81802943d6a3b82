#include <facet/film.h>
#include <facet/integrator.h>
#include <facet/logger.h>
#include <facet/properties.h>
#include <facet/random.h>
#include <facet/render.h>
#include <facet/sampler.h>
#include <facet/scene.h>
#include <facet/sensor.h>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <mutex>
#include <pmmintrin.h>
#include <signal.h>
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
        constexpr int width = 40;
        const int filled = int(frac * width + 0.5);
        std::string bar(size_t(filled), '=');
        bar.append(size_t(width - filled), ' ');
        std::string eta = done > 0 && done < total
                              ? fmt::format(", ETA {:.1f}s", elapsed * (1.0 - frac) / frac)
                              : "";
        std::string line = fmt::format("\rRendering [{}] {:3d}% ({:.1f}s{})", bar,
                                       int(frac * 100.0), elapsed, eta);
        // Pad to clear what a longer earlier line left behind.
        if (line.size() < m_width) line.append(m_width - line.size(), ' ');
        m_width = line.size();
        std::fputs(line.c_str(), stderr);
        std::fflush(stderr);
        m_drawn = true;
    }
    void finish() {
        if (m_enabled && m_drawn) std::fputs("\n", stderr);
    }

private:
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

// ---------------------------------------------------------------------------------------------
// BlockMerger

BlockMerger::BlockMerger(Film &film, bool splat) : m_film(film), m_splat(splat) {}
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
    for (auto it = m_pending.begin(); it != m_pending.end() && it->first == m_next;
         it = m_pending.begin()) {
        merge(*it->second);
        m_free.push_back(std::move(it->second));
        m_pending.erase(it);
        ++m_next;
    }
    return m_finished;
}

void BlockMerger::flush() {
    std::lock_guard<std::mutex> lock(m_mutex);
    for (auto &[index, block] : m_pending) merge(*block);
    m_pending.clear();
}

size_t BlockMerger::finished() {
    std::lock_guard<std::mutex> lock(m_mutex);
    return m_finished;
}

// ---------------------------------------------------------------------------------------------
// Work units on the render threads

int render_thread_count(const RenderOptions &opts) {
    if (opts.threads < 0)
        FACET_THROW("the thread count must be positive (or 0 for all cores), got {}", opts.threads);
    tbb::task_arena arena(opts.threads > 0 ? opts.threads : tbb::task_arena::automatic);
    return arena.max_concurrency();
}

WorkUnitsRun run_work_units(size_t count, const RenderOptions &opts, double timeout,
                            const std::function<std::function<size_t(size_t)>()> &make_worker) {
    if (opts.threads < 0)
        FACET_THROW("the thread count must be positive (or 0 for all cores), got {}", opts.threads);
    const auto start = Clock::now();
    // More threads than cores is allowed (TBB otherwise caps its workers at the core count).
    std::unique_ptr<tbb::global_control> allow;
    if (opts.threads > 0)
        allow = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                      size_t(opts.threads));
    tbb::task_arena arena(opts.threads > 0 ? opts.threads : tbb::task_arena::automatic);
    const int workers = arena.max_concurrency();

    ProgressLine progress(opts.progress);
    std::atomic<size_t> next_unit{0}, done_units{0};
    std::atomic<bool> cancelled{false}, timed_out{false};
    std::mutex progress_mutex;

    // Each worker takes the next unit until none is left; the caller's merge order, not who took
    // which unit, decides the image.
    auto worker = [&](int) {
        ScopedFlushToZero ftz;
        std::function<size_t(size_t)> run = make_worker();
        for (;;) {
            if (opts.cancel && opts.cancel->load(std::memory_order_relaxed)) {
                cancelled = true;
                return;
            }
            if (timeout > 0.0 && seconds_since(start) >= timeout) {
                timed_out = true;
                return;
            }
            const size_t index = next_unit.fetch_add(1);
            if (index >= count) return;
            const size_t done = run(index);
            done_units = std::max(done_units.load(), done);
            if (progress.enabled()) {
                std::lock_guard<std::mutex> lock(progress_mutex);
                progress.update(done, count, seconds_since(start));
            }
        }
    };
    arena.execute([&] { tbb::parallel_for(0, workers, worker, tbb::simple_partitioner()); });

    WorkUnitsRun run;
    run.seconds = seconds_since(start);
    const size_t taken = std::min(next_unit.load(), count);
    run.cancelled = cancelled && taken < count;
    run.timed_out = timed_out && taken < count;
    progress.update(done_units.load(), count, run.seconds, true);
    progress.finish();
    return run;
}

// ---------------------------------------------------------------------------------------------
// The sampling integrators' render loop

double read_timeout(const Properties &props) { return props.get_float("timeout", -1.0); }

uint32_t read_max_depth(const Properties &props, const char *plugin) {
    int64_t max_depth = props.get_int("max_depth", -1);
    if (max_depth < -1)
        FACET_THROW_AT(props.location("max_depth"),
                       "{}: max_depth must be -1 (unbounded) or a value >= 0, got {}", plugin,
                       max_depth);
    return max_depth == -1 ? std::numeric_limits<uint32_t>::max()
                           : uint32_t(std::min<int64_t>(max_depth, 0xfffffffe));
}

uint32_t read_rr_depth(const Properties &props, const char *plugin) {
    int64_t rr_depth = props.get_int("rr_depth", 5);
    if (rr_depth <= 0)
        FACET_THROW_AT(props.location("rr_depth"),
                       "{}: rr_depth must be a value greater than zero, got {}", plugin, rr_depth);
    return uint32_t(std::min<int64_t>(rr_depth, 0xffffffff));
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

RenderResult SamplingIntegrator::render(const Scene &scene, const Sensor &sensor,
                                        const RenderOptions &opts) const {
    const auto start = Clock::now();
    if (opts.spp < 0) FACET_THROW("the sample count must be positive, got {}", opts.spp);
    if (opts.block_size < 0)
        FACET_THROW("the block size must be positive, got {}", opts.block_size);
    const int bs = opts.block_size > 0 ? opts.block_size : m_block_size > 0 ? m_block_size : 32;

    Film &film = sensor.film();
    const Sampler &proto_sampler = sensor.sampler();
    // The per-thread samplers are clones of this one. Samplers may round the count (stratified
    // ones to a square); seeding once lets them do so before the count is read back.
    std::unique_ptr<Sampler> base_sampler = proto_sampler.clone();
    if (opts.spp > 0) base_sampler->set_sample_count(uint32_t(opts.spp));
    base_sampler->seed(0);
    const uint32_t spp = base_sampler->sample_count();
    if (opts.spp > 0 && spp != uint32_t(opts.spp))
        FACET_LOG(Info, "The sampler takes {} samples per pixel instead of {}", spp, opts.spp);
    const uint32_t spp_per_pass =
        m_samples_per_pass > 0 ? std::min(m_samples_per_pass, spp) : std::max(spp, 1u);
    if (spp % spp_per_pass != 0)
        FACET_THROW("the sample count ({}) must be a multiple of samples_per_pass ({})", spp,
                    spp_per_pass);
    const uint32_t passes = spp / spp_per_pass;
    const uint64_t seed = opts.seed + proto_sampler.base_seed();
    const std::vector<std::string> aov_names = this->aov_names();
    const int aov_count = int(aov_names.size());
    film.prepare(aov_names);

    const Point2i film_size = film.size(), crop_offset = film.crop_offset(),
                  crop_size = film.crop_size();
    const int blocks_x = (crop_size.x + bs - 1) / bs, blocks_y = (crop_size.y + bs - 1) / bs;
    const size_t blocks = size_t(blocks_x) * size_t(blocks_y);
    const size_t total = blocks * passes;
    const uint64_t film_pixels = uint64_t(film_size.x) * uint64_t(film_size.y);
    const int border = ImageBlock::border_for(film.rfilter());
    const ReconstructionFilter &filter = film.rfilter();
    const bool needs_aperture = sensor.needs_aperture_sample();
    const Point2f inv_film_size(1.f / float(film_size.x), 1.f / float(film_size.y));

    FACET_LOG(Info, "Starting render job ({}x{}, {} samples{}, {} threads)", crop_size.x,
              crop_size.y, spp, passes > 1 ? fmt::format(" in {} passes", passes) : "",
              render_thread_count(opts));
    if (m_timeout > 0.0) FACET_LOG(Info, "Timeout: {:.2f} seconds", m_timeout);

    BlockMerger merger(film);
    std::atomic<uint64_t> samples_taken{0}, invalid_samples{0};
    std::atomic<uint64_t> first_invalid_pixel{UINT64_MAX};

    // Unit `index` is block index % blocks of pass index / blocks; blocks are in scanline order.
    auto make_worker = [&]() -> std::function<size_t(size_t)> {
        auto sampler = std::shared_ptr<Sampler>(base_sampler->clone());
        auto aovs = std::make_shared<std::vector<float>>(size_t(aov_count) + 1, 0.f);
        return [&, sampler, aovs](size_t index) -> size_t {
            const uint64_t pass = index / blocks;
            const size_t block_index = index % blocks;
            const int bx = int(block_index % size_t(blocks_x)),
                      by = int(block_index / size_t(blocks_x));
            const Point2i offset(crop_offset.x + bx * bs, crop_offset.y + by * bs);
            const Point2i size(std::min(bs, crop_offset.x + crop_size.x - offset.x),
                               std::min(bs, crop_offset.y + crop_size.y - offset.y));
            std::unique_ptr<ImageBlock> block = merger.acquire();
            block->reset(offset, size, border, aov_count);

            uint64_t invalid = 0;
            for (int y = offset.y; y < offset.y + size.y; ++y) {
                for (int x = offset.x; x < offset.x + size.x; ++x) {
                    const uint64_t pixel_index = uint64_t(y) * uint64_t(film_size.x) + uint64_t(x);
                    sampler->seed(sample_stream_seed(seed, pixel_index + pass * film_pixels));
                    for (uint32_t s = 0; s < spp_per_pass; ++s) {
                        if (s > 0) sampler->advance();
                        const Point2f u = sampler->next_2d();
                        const Point2f pos(float(x) + u.x, float(y) + u.y);
                        const Point2f aperture =
                            needs_aperture ? sampler->next_2d() : Point2f(0.5f, 0.5f);
                        auto [ray, weight] = sensor.sample_ray(0.f, pos * inv_film_size, aperture);
                        // Integrators need not write every AOV for every sample (e.g. on a miss).
                        std::fill(aovs->begin(), aovs->end(), 0.f);
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
            }
            samples_taken += uint64_t(size.x) * uint64_t(size.y) * spp_per_pass;
            invalid_samples += invalid;
            return merger.submit(index, std::move(block));
        };
    };
    WorkUnitsRun run = run_work_units(total, opts, m_timeout, make_worker);
    merger.flush();

    RenderResult result;
    result.blocks_total = total;
    result.blocks_done = merger.finished();
    result.cancelled = (run.cancelled || run.timed_out) && result.blocks_done < total;
    result.timed_out = run.timed_out && result.blocks_done < total;
    result.samples = samples_taken.load();
    result.seconds = seconds_since(start);
    if (result.timed_out)
        FACET_LOG(Warn, "Timeout of {:.2f}s reached after {} of {} blocks", m_timeout,
                  result.blocks_done, total);
    else if (result.cancelled)
        FACET_LOG(Warn, "Rendering cancelled after {} of {} blocks", result.blocks_done, total);
    if (invalid_samples > 0) {
        uint64_t p = first_invalid_pixel.load();
        FACET_LOG(Warn,
                  "{} samples had NaN or infinite radiance and were dropped (the first at pixel "
                  "({}, {}))",
                  invalid_samples.load(), p % uint64_t(film_size.x), p / uint64_t(film_size.x));
    }
    result.image = film.develop();
    return result;
}

RenderResult Integrator::render(const Scene &, const Sensor &, const RenderOptions &) const {
    FACET_THROW("the integrator {} cannot render images", to_string());
}

RenderResult render(const Scene &scene, const Sensor &sensor, const RenderOptions &opts) {
    if (!scene.integrator()) FACET_THROW("the scene has no integrator");
    return scene.integrator()->render(scene, sensor, opts);
}
// ---------------------------------------------------------------------------------------------
// Interrupt handling

namespace {

std::atomic<bool> *g_interrupt_flag = nullptr;
struct sigaction g_old_sigint, g_old_sighup;
bool g_handler_installed = false;

extern "C" void facet_interrupt_handler(int sig) {
    if (g_interrupt_flag) g_interrupt_flag->store(true);
    // A second signal of the same kind takes the default action, so the user can force quit.
    struct sigaction dfl;
    std::memset(&dfl, 0, sizeof(dfl));
    dfl.sa_handler = SIG_DFL;
    sigemptyset(&dfl.sa_mask);
    sigaction(sig, &dfl, nullptr);
}

} // namespace

void install_interrupt_handler(std::atomic<bool> *flag) {
    if (g_handler_installed) uninstall_interrupt_handler();
    g_interrupt_flag = flag;
    struct sigaction sa;
    std::memset(&sa, 0, sizeof(sa));
    sa.sa_handler = facet_interrupt_handler;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    sigaction(SIGINT, &sa, &g_old_sigint);
    sigaction(SIGHUP, &sa, &g_old_sighup);
    g_handler_installed = true;
}

void uninstall_interrupt_handler() {
    if (!g_handler_installed) return;
    sigaction(SIGINT, &g_old_sigint, nullptr);
    sigaction(SIGHUP, &g_old_sighup, nullptr);
    g_interrupt_flag = nullptr;
    g_handler_installed = false;
}

} // namespace facet
