// Core's render loop: render() builds a RenderJob per part, which runs the integrator's
// per-sample (or per-light-path) work in passes of blocks on the render threads (render_loop.h).
#include "render_loop.h"
#include "scene_description.h"

#include <facet/film.h>
#include <facet/integrator.h>
#include <facet/logger.h>
#include <facet/properties.h>
#include <facet/render.h>
#include <facet/sampler.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/spectrum.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <tuple>
#include <utility>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace facet {

// ---------------------------------------------------------------------------------------------
// Integrator parameters

namespace {

double read_timeout(const Properties &props) {
    const double timeout = props.get_float("timeout", -1.0);
    if (std::isnan(timeout))
        FACET_THROW_AT(props.location("timeout"),
                       "timeout must be a number of seconds (<= 0 for none), got {}", timeout);
    return timeout;
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

} // namespace

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

Integrator::Integrator(const Properties &props)
    : m_timeout(read_timeout(props)), m_samples_per_pass(read_samples_per_pass(props)) {}

SamplingIntegrator::SamplingIntegrator(const Properties &props) : Integrator(props) {
    int64_t bs = props.get_int("block_size", 0);
    if (bs < 0 || bs > 4096)
        FACET_THROW_AT(props.location("block_size"),
                       "block_size must be 0 (automatic) or a number of pixels up to 4096, got {}",
                       bs);
    m_block_size = int(bs);
}

// ---------------------------------------------------------------------------------------------
// The render job

SampleRange render_sample_range(const Sensor &sensor, const RenderOptions &opts) {
    if (opts.spp < 0) FACET_THROW("the sample count must be positive, got {}", opts.spp);
    if (opts.pass_count < 1)
        FACET_THROW("the pass count must be at least 1, got {}", opts.pass_count);
    if (opts.pass_index < -1 || opts.pass_index >= opts.pass_count)
        FACET_THROW("the pass index must lie in 0..{} (pass_count {}), or be -1 for all of them, "
                    "got {}",
                    opts.pass_count - 1, opts.pass_count, opts.pass_index);
    const uint64_t per_part = opts.spp > 0 ? uint64_t(opts.spp) : sensor.sampler().sample_count();
    const uint64_t whole = per_part * uint64_t(opts.pass_count);
    if (whole > UINT32_MAX / 2)
        FACET_THROW("{} passes of {} samples per pixel are too many (at most {} in all)",
                    opts.pass_count, per_part, UINT32_MAX / 2);
    // Samplers may round the count (stratified ones to a square).
    SampleRange range;
    range.total = std::max(sensor.sampler().clone()->set_sample_count(uint32_t(whole)), 1u);
    if (opts.pass_index < 0) { // all the passes
        range.count = range.total;
        return range;
    }
    const uint64_t n = uint64_t(opts.pass_count), i = uint64_t(opts.pass_index);
    range.first = uint32_t(uint64_t(range.total) * i / n);
    range.count = uint32_t(uint64_t(range.total) * (i + 1) / n) - range.first;
    return range;
}

void SplatTarget::splat(const Point2f &film_pos, const Color3f &value) {
    m_block.splat(film_pos, value, m_filter);
}

namespace {

/// The film pixels a render develops: `offset` + [0, size).
struct Window {
    Point2i offset, size;
};

/// RenderOptions::crop (validated against the film), else the film's crop window.
Window render_window(const Film &film, const RenderOptions &opts) {
    const auto &c = opts.crop;
    if (c[0] == 0 && c[1] == 0 && c[2] == 0 && c[3] == 0)
        return {film.crop_offset(), film.crop_size()};
    if (c[2] <= c[0] || c[3] <= c[1])
        FACET_THROW("the crop window x0 y0 x1 y1 = {} {} {} {} is empty (x1 and y1 are "
                    "exclusive: they must be greater than x0 and y0)",
                    c[0], c[1], c[2], c[3]);
    const Window w{Point2i(c[0], c[1]), Point2i(c[2] - c[0], c[3] - c[1])};
    film.check_crop_window(w.offset, w.size);
    return w;
}

/// The blocks of a sampling render: the pixels whose samples reach the window through the
/// filter, in square blocks of the grid of the whole film, so a crop's pixels receive the same
/// samples, in the same order, as in a render of the whole film.
struct BlockGrid {
    BlockGrid(const Film &film, const Window &window, int block_size) : bs(block_size) {
        const Point2i film_size = film.size();
        border = ImageBlock::border_for(film.rfilter());
        x0 = std::max(0, window.offset.x - border);
        y0 = std::max(0, window.offset.y - border);
        x1 = std::min(film_size.x, window.offset.x + window.size.x + border);
        y1 = std::min(film_size.y, window.offset.y + window.size.y + border);
        gx0 = x0 / bs;
        gy0 = y0 / bs;
        blocks_x = (x1 + bs - 1) / bs - gx0;
        blocks_y = (y1 + bs - 1) / bs - gy0;
    }
    size_t blocks() const { return size_t(blocks_x) * size_t(blocks_y); }
    uint64_t sampled_pixels() const { return uint64_t(x1 - x0) * uint64_t(y1 - y0); }
    /// Film pixel of the top left corner of block `index` (scanline order).
    Point2i block_offset(size_t index) const {
        return {(gx0 + int(index % size_t(blocks_x))) * bs,
                (gy0 + int(index / size_t(blocks_x))) * bs};
    }

    int bs, border;
    int x0, y0, x1, y1; ///< the sampled pixels [x0, x1) x [y0, y1)
    int gx0, gy0, blocks_x, blocks_y;
};

/// The first sample that had a NaN or infinite value, and how many did (dropped).
struct InvalidSamples {
    std::atomic<uint64_t> count{0};
    std::atomic<uint64_t> first_pixel{UINT64_MAX};
    void add(uint64_t n, uint64_t pixel) {
        if (n == 0) return;
        count += n;
        uint64_t cur = first_pixel.load();
        while (pixel < cur && !first_pixel.compare_exchange_weak(cur, pixel)) {}
    }
};

/// One render of one part (RenderOptions::pass_index) of a sensor: everything that belongs to
/// it, and core's loop render -> pass -> block -> sample around the integrator's per-sample
/// work. The scene, sensor and film are only read.
class RenderJob {
public:
    RenderJob(const Scene &scene, const Sensor &sensor, const RenderOptions &opts,
              const Window &window)
        : m_scene(scene), m_sensor(sensor), m_film(sensor.film()), m_opts(opts), m_window(window),
          m_range(render_sample_range(sensor, opts)) {}

    RenderResult run(const Integrator &integrator);
    /// The accumulation buffer of the finished render (its raw sums for a part's file).
    std::unique_ptr<FilmBuffer> take_buffer() { return std::move(m_buffer); }

private:
    /// The sample range, the sampler set to the whole render's sample count, the seed and the
    /// pass schedule; `what` names a sample in messages ("samples", "light paths").
    void plan(const Integrator &integrator, uint32_t cap, const char *what);
    /// Logs what the render takes: "Starting <kind> (WxH, <spp> <what> in <n> passes, ...)".
    void announce(const char *kind, const char *what) const;
    RenderResult run_sampling(const SamplingIntegrator &integrator);
    RenderResult run_light_tracing(const LightTracer &tracer);
    /// Samples [first, last) of every pixel of block `index` of the grid into `block`; false
    /// when a stop cut it short. `lanes`: Scene::PacketSize samplers when the integrator takes
    /// the camera rays' hits (their rays are then traced in packets), else null.
    bool render_block(const SamplingIntegrator &integrator, const BlockGrid &grid, size_t index,
                      uint32_t first, uint32_t last, Sampler &sampler,
                      const std::unique_ptr<Sampler> *lanes, std::vector<float> &aovs,
                      ImageBlock &block, InvalidSamples &invalid) const;
    /// Light paths [begin, end) of the render into `block`; false when a stop cut it short.
    bool trace_paths(const LightTracer &tracer, uint64_t begin, uint64_t end, Sampler &sampler,
                     ImageBlock &block) const;
    /// The result of `passes_done` whole passes of `units` work units each, developed.
    RenderResult finish(const WorkUnitsRun &run, size_t units_per_pass, size_t passes_done,
                        uint64_t pixels, const char *what);

    const Scene &m_scene;
    const Sensor &m_sensor;
    const Film &m_film;
    const RenderOptions &m_opts;
    const Window m_window;
    const Clock::time_point m_start = Clock::now();
    const SampleRange m_range;
    std::unique_ptr<Sampler> m_sampler; ///< the threads' samplers are clones of it
    uint64_t m_seed = 0;
    double m_timeout = -1.0;
    std::vector<uint32_t> m_pass_start; ///< pass p takes samples [m_pass_start[p], [p + 1])
    StopCondition m_stop;
    std::unique_ptr<FilmBuffer> m_buffer;
    std::unique_ptr<BlockMerger> m_merger;
};

RenderResult RenderJob::run(const Integrator &integrator) {
    if (const auto *sampling = dynamic_cast<const SamplingIntegrator *>(&integrator))
        return run_sampling(*sampling);
    if (const auto *tracer = dynamic_cast<const LightTracer *>(&integrator))
        return run_light_tracing(*tracer);
    FACET_THROW("the integrator {} cannot render images", integrator.to_string());
}

void RenderJob::plan(const Integrator &integrator, uint32_t cap, const char *what) {
    const Sampler &proto = m_sensor.sampler();
    const uint64_t asked = uint64_t(m_opts.spp > 0 ? uint32_t(m_opts.spp) : proto.sample_count()) *
                           uint64_t(m_opts.pass_count);
    if (m_range.total != asked)
        FACET_LOG(Info, "The sampler takes {} samples per pixel instead of {}", m_range.total,
                  asked);
    if (m_range.count == 0)
        FACET_THROW("pass {} of {} has no samples: the {} {} per pixel of the whole render "
                    "cannot be split into {} parts",
                    m_opts.pass_index, m_opts.pass_count, m_range.total, what, m_opts.pass_count);
    m_sampler = proto.clone();
    m_sampler->set_sample_count(m_range.total);
    const uint32_t spp = m_range.count, per_pass = integrator.samples_per_pass();
    if (per_pass > 0 && spp % std::min(per_pass, spp) != 0)
        FACET_THROW("the sample count ({}) must be a multiple of samples_per_pass ({})", spp,
                    per_pass);
    m_seed = m_opts.seed + proto.base_seed();
    m_timeout = integrator.timeout();
    m_pass_start = progressive_schedule(spp, per_pass, cap);
    m_stop = StopCondition{m_opts.cancel, m_timeout, m_start};
}

void RenderJob::announce(const char *kind, const char *what) const {
    const size_t passes = m_pass_start.size() - 1;
    FACET_LOG(Info, "Starting {} ({}x{}, {} {} in {} pass{}{}, {} threads)", kind, m_window.size.x,
              m_window.size.y, m_range.count, what, passes, passes == 1 ? "" : "es",
              m_opts.pass_count > 1
                  ? fmt::format(", part {} of {}", m_opts.pass_index, m_opts.pass_count)
                  : "",
              render_thread_count(m_opts));
    if (m_timeout > 0.0) FACET_LOG(Info, "Timeout: {:.2f} seconds", m_timeout);
}

RenderResult RenderJob::run_sampling(const SamplingIntegrator &integrator) {
    if (m_opts.block_size < 0)
        FACET_THROW("the block size must be positive, got {}", m_opts.block_size);
    const int bs = m_opts.block_size > 0         ? m_opts.block_size
                   : integrator.block_size() > 0 ? integrator.block_size()
                                                 : 32;
    // Progressive rendering: the samples are taken in passes over the whole image, and the
    // buffer only ever holds whole passes, so a render stopped at any moment has every pixel at
    // the same spp. Without samples_per_pass the passes take 1, 1, 2, 4, ... samples, at most
    // about 2^18 samples over the film each (a power of two): early stops keep a useful image
    // and a stop throws away at most one pass. The schedule depends only on the film size and
    // the part's samples, never on the crop or the thread count.
    const Point2i film_size = m_film.size();
    const uint64_t film_pixels = uint64_t(film_size.x) * uint64_t(film_size.y);
    uint32_t cap = 1;
    while (uint64_t(cap) * 2 * film_pixels <= (uint64_t(1) << 18) && cap < (1u << 30)) cap *= 2;
    plan(integrator, cap, "samples");
    m_scene.prepare_light_sampling();
    integrator.begin_render(m_sensor);
    const std::vector<std::string> aov_names = integrator.aov_names();
    m_buffer = std::make_unique<FilmBuffer>(m_window.offset, m_window.size,
                                            m_film.colour_channels(), aov_names, false);
    // A film's bands come before the AOVs in each sample's values.
    const size_t bands = m_film.bands() ? m_film.bands()->size() : 0;
    for (const std::string &colour : m_buffer->colour_names())
        if (std::find(aov_names.begin(), aov_names.end(), colour) != aov_names.end())
            FACET_THROW("the integrator's AOV \"{}\" has the name of a colour channel of the "
                        "film {}: channel names must be unique, rename the AOV or the band",
                        colour, m_film.to_string());

    const BlockGrid grid(m_film, m_window, bs);
    const size_t blocks = grid.blocks(), passes = m_pass_start.size() - 1;
    const uint32_t spp = m_range.count;
    announce("render job", "samples");

    m_merger = std::make_unique<BlockMerger>(*m_buffer, /*splat=*/false, blocks);
    std::atomic<uint64_t> samples_done{0};
    InvalidSamples invalid;
    const bool packets = integrator.takes_first_hit();
    // Unit `index` is block index % blocks of pass index / blocks.
    auto make_worker = [&]() -> std::function<void(size_t)> {
        auto sampler = std::shared_ptr<Sampler>(m_sampler->clone());
        auto aovs = std::make_shared<std::vector<float>>(bands + aov_names.size() + 1, 0.f);
        // With an integrator that takes the camera rays' hits, one sampler per packet lane.
        auto lanes = std::make_shared<std::vector<std::unique_ptr<Sampler>>>();
        if (packets)
            for (int k = 0; k < Scene::PacketSize; ++k) lanes->push_back(m_sampler->clone());
        return [&, sampler, aovs, lanes](size_t index) {
            const size_t pass = index / blocks;
            const uint32_t first = m_range.first + m_pass_start[pass],
                           last = m_range.first + m_pass_start[pass + 1];
            std::unique_ptr<ImageBlock> block = m_merger->acquire();
            if (!render_block(integrator, grid, index % blocks, first, last, *sampler,
                              packets ? lanes->data() : nullptr, *aovs, *block, invalid)) {
                m_merger->release(std::move(block));
                return;
            }
            const Point2i o = block->offset(), s = block->size();
            const uint64_t pixels =
                uint64_t(std::max(0, std::min(o.x + s.x, grid.x1) - std::max(o.x, grid.x0))) *
                uint64_t(std::max(0, std::min(o.y + s.y, grid.y1) - std::max(o.y, grid.y0)));
            samples_done.fetch_add(pixels * (last - first), std::memory_order_relaxed);
            m_merger->submit(index, std::move(block));
        };
    };
    const WorkUnitsRun run = run_units(blocks * passes, m_opts, m_stop, samples_done,
                                       grid.sampled_pixels() * spp, make_worker);
    m_merger->flush();
    if (const uint64_t n = invalid.count.load(); n > 0) {
        const uint64_t p = invalid.first_pixel.load();
        FACET_LOG(Warn,
                  "{} samples had NaN or infinite radiance and were dropped (the first at pixel "
                  "({}, {}))",
                  n, p % uint64_t(film_size.x), p / uint64_t(film_size.x));
    }
    return finish(run, blocks, m_merger->merged() / std::max<size_t>(blocks, 1),
                  grid.sampled_pixels(), "samples");
}

bool RenderJob::render_block(const SamplingIntegrator &integrator, const BlockGrid &grid,
                             size_t index, uint32_t first, uint32_t last, Sampler &sampler,
                             const std::unique_ptr<Sampler> *lanes, std::vector<float> &aovs,
                             ImageBlock &block, InvalidSamples &invalid) const {
    const Point2i film_size = m_film.size(), offset = grid.block_offset(index);
    const Point2i size(std::min(grid.bs, film_size.x - offset.x),
                       std::min(grid.bs, film_size.y - offset.y));
    // A film's bands, then the AOVs (the extra float keeps data() valid).
    const SpectralBands *bands = m_film.bands();
    // A sensor's spectral response draws the wavelengths and weighs the radiance.
    const SpectralBands *srf = m_sensor.srf();
    const int band_count = bands ? int(bands->size()) : 0;
    const int aov_count = int(aovs.size()) - 1 - band_count;
    float *const aov_values = aovs.data() + band_count;
    block.reset(offset, size, grid.border, aov_count, bands ? band_count : 3);
    const int x0 = std::max(offset.x, grid.x0), x1 = std::min(offset.x + size.x, grid.x1);
    const int y0 = std::max(offset.y, grid.y0), y1 = std::min(offset.y + size.y, grid.y1);
    const ReconstructionFilter &filter = m_film.rfilter();
    const bool needs_aperture = m_sensor.needs_aperture_sample();
    const bool spectral = is_spectral(m_scene.mode());
    const Point2f inv_film_size(1.f / float(film_size.x), 1.f / float(film_size.y));

    // A sample's camera ray: the sampler, set to the sample, draws the position in pixel (x, y),
    // the aperture if the sensor has one and, in the spectral mode, the wavelengths (drawn from
    // the film's bands or the sensor's response if there is one; the radiance at them becomes
    // the film's RGB through XYZ, times the sensor's response, or the bands).
    // The ray itself is kept apart (the packet's rays lie side by side).
    struct CameraSample {
        Point2f pos;
        Color3f weight, wavelength_weight;
    };
    auto camera = [&](Sampler &s, int x, int y, CameraSample &c, Ray &ray) {
        const Point2f u = s.draw_2d();
        c.pos = Point2f(float(x) + u.x, float(y) + u.y);
        const Point2f aperture = needs_aperture ? s.draw_2d() : Point2f(0.5f, 0.5f);
        std::tie(ray, c.weight) = m_sensor.sample_ray(0.f, c.pos * inv_film_size, aperture);
        if (spectral) {
            const float uw = s.draw_1d();
            if (bands) {
                std::tie(ray.wavelengths, c.wavelength_weight) = bands->sample_wavelengths(uw);
            } else if (srf) {
                std::tie(ray.wavelengths, c.wavelength_weight) = srf->sample_wavelengths(uw);
                c.wavelength_weight = c.wavelength_weight * srf->eval(0, ray.wavelengths);
            } else {
                std::tie(ray.wavelengths, c.wavelength_weight) = sample_wavelengths(uw);
            }
        }
    };
    uint64_t bad = 0, first_bad_pixel = UINT64_MAX;
    // The radiance L of camera sample c with wavelengths `lambda` (of pixel `pixel_index`) into
    // the block, with the AOVs the integrator wrote; a sample that is not finite is dropped.
    auto record = [&](const CameraSample &c, const Wavelengths &lambda, Color3f L,
                      uint64_t pixel_index) {
        bool valid = true;
        if (bands) {
            bands->develop(L, lambda, c.wavelength_weight, aovs.data());
            for (int k = 0; k < band_count; ++k) valid = valid && std::isfinite(aovs[size_t(k)]);
        } else {
            if (spectral) L = spectral_to_srgb(L, lambda, c.wavelength_weight);
            valid = L.is_finite();
        }
        for (int k = 0; k < aov_count; ++k) valid = valid && std::isfinite(aov_values[k]);
        if (!valid) {
            // One bad sample must not turn the whole pixel into NaN: drop it.
            if (bad++ == 0) first_bad_pixel = pixel_index;
            return;
        }
        if (bands)
            block.put_values(c.pos, aovs.data(), filter);
        else
            block.put(c.pos, L, aov_values, filter);
    };

    uint32_t until_check = 1;
    if (lanes) {
        // The camera rays of eight neighbouring pixels in a row, one sample each, are traced
        // together (Scene::ray_intersect_packet()). The eight are fixed by the film: pixels
        // 8k .. 8k + 7 of a row (the last group padded with copies of its first ray), whatever
        // the block, crop, part or thread count, so that each ray meets the same packet in every
        // render of the scene. A pixel of the group outside the block has its ray traced, not
        // its path. Lane k's sampler follows pixel 8k + k's stream.
        constexpr int N = Scene::PacketSize;
        CameraSample cams[N];
        Ray rays[N];
        SurfaceInteraction sis[N];
        bool hits[N];
        for (int y = y0; y < y1; ++y) {
            const uint64_t row_index = uint64_t(y) * uint64_t(film_size.x);
            for (int gx = x0 - x0 % N; gx < x1; gx += N) {
                const int count = std::min(N, film_size.x - gx);
                for (int k = 0; k < count; k += 4) {
                    uint64_t seeds[4];
                    sample_stream_seeds4(m_seed, row_index + uint64_t(gx + k), seeds);
                    for (int j = 0; j < 4 && k + j < count; ++j) lanes[k + j]->seed(seeds[j]);
                }
                for (uint32_t s = first; s < last; ++s) {
                    // A stop abandons the block (its pass is incomplete and is dropped).
                    if (m_stop()) return false;
                    for (int k = 0; k < count; ++k) {
                        lanes[k]->set_sample_index(s);
                        camera(*lanes[k], gx + k, y, cams[k], rays[k]);
                    }
                    for (int k = count; k < N; ++k) rays[k] = rays[0];
                    m_scene.ray_intersect_packet(rays, N, sis, hits);
                    for (int k = std::max(0, x0 - gx); k < std::min(count, x1 - gx); ++k) {
                        // Integrators need not write every AOV for every sample (e.g. on a miss).
                        if (aov_count > 0) std::fill_n(aov_values, aov_count, 0.f);
                        const Color3f L = integrator.sample_from_hit(m_scene, *lanes[k], rays[k],
                                                                     sis[k], hits[k], aov_values);
                        record(cams[k], rays[k].wavelengths, L * cams[k].weight,
                               row_index + uint64_t(gx + k));
                    }
                }
            }
        }
    } else {
        uint64_t pixel_seeds[4]; // of the row's pixels x0 + 4i .. x0 + 4i + 3
        CameraSample cam;
        Ray ray;
        for (int y = y0; y < y1; ++y) {
            for (int x = x0; x < x1; ++x) {
                const uint64_t pixel_index = uint64_t(y) * uint64_t(film_size.x) + uint64_t(x);
                if ((x - x0) % 4 == 0) sample_stream_seeds4(m_seed, pixel_index, pixel_seeds);
                sampler.seed(pixel_seeds[(x - x0) % 4]);
                for (uint32_t s = first; s < last; ++s) {
                    // A stop abandons the block (its pass is incomplete and is dropped).
                    if (--until_check == 0) {
                        until_check = 16;
                        if (m_stop()) return false;
                    }
                    sampler.set_sample_index(s);
                    camera(sampler, x, y, cam, ray);
                    // Integrators need not write every AOV for every sample (e.g. on a miss).
                    if (aov_count > 0) std::fill_n(aov_values, aov_count, 0.f);
                    const Color3f L = integrator.sample(m_scene, sampler, ray, aov_values);
                    record(cam, ray.wavelengths, L * cam.weight, pixel_index);
                }
            }
        }
    }
    // An integrator may have cut its last samples short (render_should_stop()); a stop stays
    // true once it is, so this sees it.
    if (m_stop()) return false;
    invalid.add(bad, first_bad_pixel);
    return true;
}

RenderResult RenderJob::run_light_tracing(const LightTracer &tracer) {
    if (m_film.bands())
        FACET_THROW("a light tracer splats R, G, B: it cannot render into the spectral bands of "
                    "the film {} (use a sampling integrator such as path)",
                    m_film.to_string());
    if (m_sensor.srf())
        FACET_THROW("a light tracer draws its wavelengths at the emitters: it cannot render "
                    "through the sensor's spectral response (srf; use a sampling integrator "
                    "such as path)");
    if (!m_sensor.supports_direction_sampling())
        FACET_THROW("a light tracer cannot connect to the sensor {} (it does not support "
                    "sampling a direction towards it)",
                    m_sensor.to_string());
    // Sample s of the whole render (of range.total samples per pixel) is the light paths
    // [s·P, (s + 1)·P) for a P-pixel film; a part takes the samples of its range. The passes
    // double without a cap: each work unit splats into a block of the whole window, so few
    // units for any spp.
    plan(tracer, 1u << 30, "light paths");
    m_buffer = std::make_unique<FilmBuffer>(m_window.offset, m_window.size,
                                            std::vector<std::string>{}, /*splats=*/true);
    const Point2i film_size = m_film.size();
    const uint64_t film_pixels = uint64_t(film_size.x) * uint64_t(film_size.y);
    // A fixed number of work units per pass whatever the thread count (determinism).
    constexpr uint64_t UnitsPerPass = 64;
    const uint64_t units = std::min<uint64_t>(UnitsPerPass, film_pixels);
    const size_t passes = m_pass_start.size() - 1;
    const uint32_t spp = m_range.count;
    announce("particle tracing", "light paths per pixel");

    m_merger = std::make_unique<BlockMerger>(*m_buffer, /*splat=*/true, size_t(units));
    std::atomic<uint64_t> paths_done{0};
    auto make_worker = [&]() -> std::function<void(size_t)> {
        auto sampler = std::shared_ptr<Sampler>(m_sampler->clone());
        return [&, sampler](size_t index) {
            const size_t pass = index / units;
            const uint64_t unit = index % units;
            // The pass's light paths, numbered over the whole render.
            const uint64_t first = uint64_t(m_range.first + m_pass_start[pass]) * film_pixels,
                           count =
                               uint64_t(m_pass_start[pass + 1] - m_pass_start[pass]) * film_pixels;
            const uint64_t begin = first + count * unit / units,
                           end = first + count * (unit + 1) / units;
            std::unique_ptr<ImageBlock> block = m_merger->acquire();
            if (!trace_paths(tracer, begin, end, *sampler, *block)) {
                m_merger->release(std::move(block));
                return;
            }
            paths_done.fetch_add(end - begin, std::memory_order_relaxed);
            m_merger->submit(index, std::move(block));
        };
    };
    const WorkUnitsRun run = run_units(size_t(units) * passes, m_opts, m_stop, paths_done,
                                       film_pixels * spp, make_worker);
    m_merger->flush();
    return finish(run, size_t(units), m_merger->merged() / size_t(units), film_pixels,
                  "light paths");
}

bool RenderJob::trace_paths(const LightTracer &tracer, uint64_t begin, uint64_t end,
                            Sampler &sampler, ImageBlock &block) const {
    block.reset(m_window.offset, m_window.size, ImageBlock::border_for(m_film.rfilter()));
    SplatTarget target(block, m_film.rfilter());
    for (uint64_t i = begin; i < end; ++i) {
        // A stop abandons the unit (its pass is incomplete and is dropped).
        if ((i - begin) % 64 == 63 && m_stop()) return false;
        sampler.seed(sample_stream_seed(m_seed, i));
        tracer.trace(m_scene, m_sensor, sampler, target);
    }
    // trace() may have cut the last paths short (render_should_stop()); a stop stays true once
    // it is, so this sees it.
    return !m_stop();
}

RenderResult RenderJob::finish(const WorkUnitsRun &run, size_t units_per_pass, size_t passes_done,
                               uint64_t pixels, const char *what) {
    const size_t passes = m_pass_start.size() - 1;
    const uint32_t spp = m_range.count;
    RenderResult result;
    result.blocks_total = units_per_pass * passes;
    result.blocks_done = m_merger->merged();
    // The blocks' memory (a pass of them waits for its last one) goes before the image comes,
    // back to the system: the blocks are small allocations of the render threads' heaps, which
    // would keep their pages while the image's large allocation takes new ones.
    m_merger.reset();
#if defined(__GLIBC__)
    malloc_trim(0);
#endif
    result.first_block_cpu_seconds = run.first_unit_cpu_seconds;
    result.cancelled = passes_done < passes;
    result.timed_out = result.cancelled && run.timed_out;
    result.spp_target = spp;
    result.spp = m_pass_start[passes_done];
    result.samples = pixels * result.spp;
    result.sample_offset = m_range.first;
    result.spp_total = m_range.total;
    if (m_buffer->has_splats())
        // The importance of the sensor integrates to one over the whole film: every pixel
        // receives spp times its value from width x height x spp paths.
        m_buffer->set_splat_scale(result.spp > 0 ? 1.0 / double(result.spp) : 1.0);
    if (result.cancelled) {
        const std::string done = fmt::format(
            "after {} of {} passes: the image has {} of {} {} per pixel{}", passes_done, passes,
            result.spp, spp, what, result.spp == 0 ? " (no pass was finished: it is black)" : "");
        if (result.timed_out)
            FACET_LOG(Warn, "Timeout of {:.2f}s reached {}", m_timeout, done);
        else
            FACET_LOG(Warn, "Rendering stopped {}", done);
    }
    result.sampling_seconds = run.seconds;
    const auto develop_start = Clock::now();
    result.image = m_film.develop(*m_buffer);
    result.develop_seconds = seconds_since(develop_start);
    result.seconds = seconds_since(m_start);
    result.crop = {{m_window.offset.x, m_window.offset.y, m_window.offset.x + m_window.size.x,
                    m_window.offset.y + m_window.size.y}};
    result.film_width = m_film.size().x;
    result.film_height = m_film.size().y;
    result.pass_index = m_opts.pass_index;
    result.pass_count = m_opts.pass_count;
    result.accel_seconds = m_scene.accel_build_seconds();
    return result;
}

/// One render of a part, and its accumulation buffer.
std::pair<RenderResult, std::unique_ptr<FilmBuffer>>
render_job(const Scene &scene, const Sensor &sensor, const RenderOptions &opts,
           const Window &window, const Integrator &integrator) {
    RenderJob job(scene, sensor, opts, window);
    RenderResult result = job.run(integrator);
    return {std::move(result), job.take_buffer()};
}

/// Every pass of opts.pass_count, one after the other, combined as a merge of the parts combines
/// them: the raw sums of each pass rounded to float (what a part's file holds), added in pass
/// order in double and developed once. The result is bit-identical to the merge of the parts.
RenderResult render_all_passes(const Scene &scene, const Sensor &sensor, const RenderOptions &opts,
                               const Window &window, const Integrator &integrator) {
    const auto start = Clock::now();
    const Film &film = sensor.film();
    RenderResult all;
    std::vector<double> sums;
    std::vector<std::string> raw_names;
    std::unique_ptr<FilmBuffer> first;
    for (int i = 0; i < opts.pass_count; ++i) {
        RenderOptions part = opts;
        part.pass_index = i;
        if (opts.on_progress) // the fraction of the whole, not of the part
            part.on_progress = [&opts, i](double f) {
                opts.on_progress((double(i) + f) / double(opts.pass_count));
            };
        auto [r, buffer] = render_job(scene, sensor, part, window, integrator);
        const std::vector<std::string> names = buffer->raw_channel_names();
        const std::vector<float> raw = buffer->raw_sums();
        // The passes are developed as a merge develops them: the film's colour channels (R, G,
        // B or its bands) as they are summed.
        const std::vector<std::string> &channels = r.image.channel_names,
                                       colours = buffer->colour_names();
        if (channels.size() < colours.size() ||
            !std::equal(colours.begin(), colours.end(), channels.begin()))
            FACET_THROW("a render of {} passes in one process develops {}: the film {} "
                        "develops into {} (use the pixel format rgb or rgba, or render the passes "
                        "apart)",
                        opts.pass_count, fmt::join(colours, ", "), film.to_string(),
                        channels.empty() ? "nothing" : channels[0]);
        if (i == 0) {
            raw_names = names;
            sums.assign(raw.size(), 0.0);
            first = std::move(buffer);
            all = r;
        } else {
            if (names != raw_names || raw.size() != sums.size())
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
    first->set_raw_sums(sums);
    first->set_splat_scale(all.spp > 0 ? 1.0 / double(all.spp) : 1.0);
    // The base class's development, as a merge of the parts develops them.
    all.image = film.Film::develop(*first);
    all.spp_target = range.total;
    all.spp_total = range.total;
    all.sample_offset = 0;
    all.pass_index = 0;
    all.pass_count = 1;
    all.seconds = seconds_since(start);
    return all;
}

/// A part's raw channels (FilmBuffer::raw_channel_names) after its developed ones.
void append_raw_channels(Image &image, const std::vector<std::string> &names,
                         const std::vector<float> &raw) {
    const size_t pixels = size_t(image.width) * size_t(image.height), nr = names.size();
    const size_t nd = size_t(image.channels), n = nd + nr;
    if (raw.size() != pixels * nr)
        FACET_THROW("the render's raw sums ({} values) do not match its {}x{} image", raw.size(),
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

/// Where the scene file declares `object` (its tag); none for objects not loaded from a file.
Location declared_at(const Scene &scene, const Object *object) {
    if (const std::shared_ptr<SceneDescription> &d = scene.description())
        for (const SceneDescription::Node &node : d->nodes)
            if (node.instance.get() == object) return node.location;
    return {};
}

} // namespace

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
    const Window window = render_window(sensor.film(), opts);
    render_sample_range(sensor, opts); // validates the options
    try {
        if (opts.pass_count > 1 && opts.pass_index < 0)
            return render_all_passes(scene, sensor, opts, window, integrator);
        auto [result, buffer] = render_job(scene, sensor, opts, window, integrator);
        if (opts.pass_count > 1)
            append_raw_channels(result.image, buffer->raw_channel_names(), buffer->raw_sums());
        return std::move(result);
    } catch (const Error &e) {
        // An integrator's own error (its parameters against the render's sample count, say), at
        // the integrator's place in the scene file.
        const Location at = e.location().valid() ? Location() : declared_at(scene, &integrator);
        if (!at.valid()) throw;
        throw Error(at, e.message());
    }
}

} // namespace facet
