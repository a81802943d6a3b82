#pragma once

#include <facet/fwd.h>
#include <facet/image.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace facet {

struct RenderOptions {
    int threads = 0;   ///< 0 = all cores
    uint64_t seed = 0; ///< added to the sampler's seed
    int spp = 0;       ///< 0 = the sampler's sample_count
    /// Side of the square image blocks of a sampling integrator; 0 = the integrator's
    /// `block_size` parameter (32 when that is 0 too).
    int block_size = 0;
    bool progress = true; ///< progress line on a terminal (never when stderr is not a tty)
    /// Set to true (e.g. by a signal handler) to stop within moments: a sampling integrator
    /// keeps the passes over the image finished so far (see RenderResult::spp).
    std::atomic<bool> *cancel = nullptr;
    /// Film pixels [x0, x1) x [y0, y1) to render, as {x0, y0, x1, y1}, instead of the film's crop
    /// window (validated against the film). The developed image is that window of the film (an
    /// EXR's data window inside the full display window) and its pixels are bit-identical to the
    /// same pixels of a render of the whole film. All zero: the crop window of the scene file.
    std::array<int, 4> crop{{0, 0, 0, 0}};
    /// Part `pass_index` (0-based) of `pass_count` independent parts of one render of
    /// pass_count x spp samples per pixel: the part takes the samples
    /// [pass_index·T/pass_count, (pass_index+1)·T/pass_count) of every pixel, T being that total
    /// after the sampler's rounding (T = pass_count·spp for the independent sampler). A part's
    /// image carries the raw sums of its pixels (FilmBuffer::raw_channel_names) after its developed
    /// channels: the parts merge exactly (sums added in pass order, developed once), whatever
    /// the filter. pass_index -1: every part, one after the other in this process, combined as
    /// their merge combines them (bit-identical to it; a merge of crops of parts too).
    int pass_index = 0;
    int pass_count = 1;
    /// Called once, on a render thread, when the first work unit is done (`facet render` starts
    /// loading the image library for the write then, not before: while the dynamic loader loads
    /// a library, creating a thread waits for it, and the render creates its threads first).
    std::function<void()> on_first_block;
    /// Called with the fraction of the work done (0 to 1), from a monitor thread, about every
    /// 50 ms while the render runs and once with the final fraction (the Python `progress=`).
    std::function<void(double)> on_progress;
};

/// The samples per pixel a render takes: sample indices [first, first + count) of each pixel of
/// a render whose sampler pattern spans `total` samples (see RenderOptions::pass_index).
struct SampleRange {
    uint32_t first = 0, count = 0, total = 0;
};

/// The sample range `opts` asks of `sensor`'s sampler, after the sampler's own rounding of
/// pass_count x spp (stratified samplers take a square number, ldsampler a power of two, ...).
/// Throws on a bad spp or pass index/count.
SampleRange render_sample_range(const Sensor &sensor, const RenderOptions &opts);

struct RenderResult {
    Image image;          ///< developed film (crop window), plus AOV channels
    double seconds = 0.0; ///< the render (sampling and developing the film)
    /// Times of the phases, in seconds: loading the scene (filled in by whoever loaded it:
    /// render() cannot know), building the acceleration structure (Scene::accel_build_seconds,
    /// part of the load), sampling, and developing the film (parts of `seconds`).
    double load_seconds = 0.0, accel_seconds = 0.0, sampling_seconds = 0.0, develop_seconds = 0.0;
    /// Samples per pixel in the image (of a stopped render: what was reached), and what the
    /// render was to take (after the sampler's rounding).
    uint32_t spp = 0, spp_target = 0;
    /// This part's place in the whole estimator: sample indices [sample_offset, sample_offset +
    /// spp_target) of spp_total, part pass_index of pass_count (see RenderOptions).
    uint32_t sample_offset = 0, spp_total = 0;
    int pass_index = 0, pass_count = 1;
    std::array<int, 4> crop{{0, 0, 0, 0}}; ///< the film pixels rendered: {x0, y0, x1, y1}
    int film_width = 0, film_height = 0;
    bool cancelled = false; ///< stopped early by the cancel flag (Ctrl-C) or the timeout
    bool timed_out = false; ///< stopped early by the integrator's `timeout`
    /// Work units in the image and in total: image blocks times passes of a sampling integrator
    /// (whole passes only), light-path batches of a light tracer.
    size_t blocks_done = 0, blocks_total = 0;
    uint64_t samples = 0; ///< camera samples (or light paths) taken
    /// Time to first pixels: CPU time of the whole process (start-up, scene loading and every
    /// thread included) when the first image block of a sampling integrator was rendered; 0 when
    /// none was (or for a light tracer).
    double first_block_cpu_seconds = 0.0;
};

/// Renders `sensor` of `scene` with the scene's integrator: a render job that owns everything of
/// this one render (its sample range, pass schedule, stop condition, accumulation buffers,
/// timing and result) and runs the integrator's per-sample work in core's loop. The scene, its
/// sensors and films are only read: any number of renders of one scene may run at once (from
/// different threads), each giving the image it gives alone. Deterministic: the same scene, seed
/// and spp give the same image for any thread count.
RenderResult render(const Scene &scene, const Sensor &sensor, const RenderOptions &opts);

/// Installs SIGINT/SIGHUP/SIGTERM handlers that set `flag` and record the first signal (restored
/// by uninstall_interrupt_handler). While rendering, a second signal of the same kind takes its
/// default action (force quit); after defer_interrupts() no signal is fatal any more.
void install_interrupt_handler(std::atomic<bool> *flag);
/// From now on (the write of the output: encoding, writing, fsync, read-back and rename) every
/// signal, repeated or not, is only recorded; the caller exits after the write, 128 + the signal.
void defer_interrupts();
void uninstall_interrupt_handler();
/// The first signal received since install_interrupt_handler() (0: none); kept after the
/// uninstall.
int interrupt_signal();
/// "SIGINT", "SIGHUP" or "SIGTERM".
const char *interrupt_signal_name(int sig);

/// Number of threads a render with `opts` uses: capped_thread_count(opts.threads).
int render_thread_count(const RenderOptions &opts);

/// Hardware threads this process may run on (its CPU affinity).
int hardware_threads();

/// Threads a render asked for `threads` runs on: every hardware thread for 0, else `threads` but
/// at most hardware_threads() (more only cost memory: a million took half a gigabyte, and TBB
/// crashed on ten million). render() says so once, as a warning, when it caps opts.threads.
/// Throws for a negative count.
int capped_thread_count(int threads);

/// For a loop inside one sample or light path that may run long (a path of unbounded depth in a
/// closed mirror, thousands of emitter samples): true when the render the calling thread works
/// for is to stop, because its cancel flag is set or its timeout has passed (false outside a
/// render). The loop then ends at once; the render loop drops the work unit it was part of, so
/// the sample cut short never reaches the image. Costs a thread-local lookup and a clock read:
/// ask through render_should_stop(iteration) in per-bounce code.
bool render_should_stop();

/// render_should_stop(), asked on every 16th value of a loop counter only (false on the others),
/// so that a check on every bounce of a path costs next to nothing.
inline bool render_should_stop(uint32_t iteration) {
    return (iteration & 15u) == 15u && render_should_stop();
}

/// CPU seconds (user + system, every thread) of the whole process so far.
double process_cpu_seconds();

} // namespace facet
