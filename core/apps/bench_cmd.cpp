// `facet bench`: how fast the scene's integrator renders, and how much of that time Embree's own
// work takes.
//
// Time is CPU time (user + system of the whole process around the render, i.e. of every render
// thread), not wall clock, which on a shared machine mostly measures the other processes.
// Instructions are counted with Linux perf events (one counter per thread) where the kernel
// allows it. With --reference, the equal-error mode renders at doubling sample counts and reports
// the RMSE against the reference image as a function of CPU time, and the efficiency
// 1 / (RMSE² · CPU time): an estimator that reaches the same error sooner is faster even if each
// sample costs more.
//
// Rays of the render are counted exactly: libfacet's statistics counters (stats.h) count every
// ray_intersect() and ray_test() call per thread (plain thread-local increments, no locks or
// atomics in the hot path). Embree's share is measured, not attributed by a profiler: a second
// render, at fewer samples, records the queries it sends to Embree (ray_recording.h), and they
// are sent again, on one thread with nothing else around them. Their CPU time per ray, times the
// render's rays, is Embree's own work in the render; the rest of the render's CPU time is facet's.

#include "commands.h"
#include "ray_recording.h"
#include "stats.h"

#include <facet/logger.h>
#include <facet/mode.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <linux/perf_event.h>
#include <sys/syscall.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <dirent.h>
#include <unistd.h>
#include <utility>
#include <vector>

namespace {

using namespace facet;

/// User-space instructions retired by every thread of the process (those alive when started
/// and, through `inherit`, those they create), from Linux perf events. available() is false
/// where the kernel or the machine (many VMs) does not provide the counter.
class InstructionCounter {
public:
    InstructionCounter() {
        perf_event_attr attr{};
        attr.type = PERF_TYPE_HARDWARE;
        attr.size = sizeof(attr);
        attr.config = PERF_COUNT_HW_INSTRUCTIONS;
        attr.exclude_kernel = 1;
        attr.exclude_hv = 1;
        attr.inherit = 1;
        DIR *dir = opendir("/proc/self/task");
        if (!dir) {
            m_error = "no /proc/self/task";
            return;
        }
        while (dirent *entry = readdir(dir)) {
            if (entry->d_name[0] == '.') continue;
            pid_t tid = pid_t(std::atoi(entry->d_name));
            long fd = syscall(SYS_perf_event_open, &attr, tid, -1, -1, 0);
            if (fd < 0) {
                m_error = fmt::format("perf_event_open: {}", std::strerror(errno));
                continue;
            }
            m_fds.push_back(int(fd));
        }
        closedir(dir);
        if (!m_fds.empty()) m_error.clear();
    }
    ~InstructionCounter() {
        for (int fd : m_fds) close(fd);
    }
    InstructionCounter(const InstructionCounter &) = delete;
    InstructionCounter &operator=(const InstructionCounter &) = delete;

    bool available() const { return !m_fds.empty(); }
    const std::string &error() const { return m_error; }
    uint64_t read() const {
        uint64_t total = 0;
        for (int fd : m_fds) {
            uint64_t v = 0;
            if (::read(fd, &v, sizeof(v)) == ssize_t(sizeof(v))) total += v;
        }
        return total;
    }

private:
    std::vector<int> m_fds;
    std::string m_error = "perf events unavailable";
};

/// The rays traced so far, all threads together: ray_intersect() calls (closest hit) and
/// ray_test() calls (any hit, for shadow rays).
struct RayCount {
    uint64_t intersect = 0;
    uint64_t test = 0;

    static RayCount now() {
        return {stats::total("scene.ray_intersect"), stats::total("scene.ray_test")};
    }
    uint64_t total() const { return intersect + test; }
    RayCount operator-(const RayCount &o) const { return {intersect - o.intersect, test - o.test}; }
};

/// A render with its cost: wall and CPU seconds, instructions (0 when not counted), rays.
struct Measured {
    RenderResult result;
    double cpu_seconds = 0.0;
    uint64_t instructions = 0;
    RayCount rays;
};

Measured measure_render(const Scene &scene, const Sensor &sensor, const RenderOptions &ropts,
                        const InstructionCounter *counter) {
    Measured m;
    const RayCount rays_before = RayCount::now();
    uint64_t instr_before = counter ? counter->read() : 0;
    double cpu_before = process_cpu_seconds();
    m.result = render(scene, sensor, ropts);
    m.cpu_seconds = process_cpu_seconds() - cpu_before;
    m.instructions = counter ? counter->read() - instr_before : 0;
    m.rays = RayCount::now() - rays_before;
    return m;
}

/// Root mean square difference of the first three channels of `image` from `reference`.
double rmse(const Image &image, const Image &reference) {
    double sum = 0.0;
    size_t n = size_t(image.width) * size_t(image.height);
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) {
            double d = double(image.data[i * size_t(image.channels) + size_t(c)]) -
                       double(reference.data[i * size_t(reference.channels) + size_t(c)]);
            sum += d * d;
        }
    return std::sqrt(sum / double(3 * n));
}

/// CPU seconds of the calling thread.
double thread_cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

std::string mega(double v) { return fmt::format("{:.3f} M", v * 1e-6); }

/// The options of `facet bench` beyond the scene's.
struct BenchCommand {
    cli::SceneOptions scene;
    int spp = 16;
    uint64_t seed = 0;
    std::string reference;
    int rounds = 6;
    double target_rmse = 0.0;
    bool machine = false;
};

void add_bench_options(CLI::App &app, BenchCommand &c) {
    cli::add_scene_options(app, c.scene);
    cli::add_mode_option(app, c.scene.mode);
    app.add_option("--spp", c.spp,
                   "Samples per pixel (default 16); with --reference, of the first round")
        ->check(CLI::PositiveNumber);
    app.add_option("--seed", c.seed, "Added to the sampler's seed (default 0)");
    app.add_option("--reference", c.reference,
                   "Equal-error mode: RMSE against this image (e.g. a high-spp EXR of the same "
                   "scene) for renders at doubling sample counts");
    app.add_option("--rounds", c.rounds, "Equal-error mode: number of renders (default 6)")
        ->check(CLI::Range(1, 20));
    app.add_option("--target-rmse", c.target_rmse,
                   "Equal-error mode: also report the CPU time to reach this RMSE (interpolated "
                   "on the log-log curve, or extrapolated with RMSE ~ 1/sqrt(time))")
        ->check(CLI::PositiveNumber);
    app.add_flag("--machine", c.machine,
                 "Also print the figures as one line of key=value pairs, starting with "
                 "\"machine:\" (what `facet bench --suite` reads)");
}

/// The --reference image (its header only when `header_only`), checked against the size of the
/// sensor's film.
Image read_reference(const std::string &reference, const Sensor &sensor, bool header_only) {
    Image ref_image = header_only ? read_image_header(reference).image : read_image(reference);
    Point2i size = sensor.film().crop_size();
    if (ref_image.width != size.x || ref_image.height != size.y || ref_image.channels < 3)
        FACET_THROW("--reference {}: {}x{} pixels with {} channels, expected {}x{} with at "
                    "least 3 (R, G, B)",
                    reference, ref_image.width, ref_image.height, ref_image.channels, size.x,
                    size.y);
    return ref_image;
}

/// Throws "interrupted" when a signal stopped the render (giving the signals back first).
void throw_if_interrupted(const RenderResult &result) {
    if (result.cancelled) {
        uninstall_interrupt_handler();
        FACET_THROW("interrupted");
    }
}

/// What the render cost: samples, rays and instructions per CPU second.
void print_render_cost(const Measured &m, int threads, const InstructionCounter &counter) {
    const RenderResult &result = m.result;
    const uint64_t rays = m.rays.total();
    const double samples = std::max<double>(1.0, double(result.samples));
    const double cpu = std::max(m.cpu_seconds, 1e-9);
    fmt::print("render      : {}samples in {:.3f} CPU-s ({:.3f} CPU-s per thread; wall {:.3f} s) "
               "= {}samples per CPU-s, {:.1f} CPU-ns per sample\n",
               mega(double(result.samples)), m.cpu_seconds, m.cpu_seconds / threads, result.seconds,
               mega(double(result.samples) / cpu), 1e9 * cpu / samples);
    fmt::print("              {}rays (ray_intersect + ray_test calls, counted exactly; "
               "{:.2f} per sample, {:.1f}% of them ray_test) = {}rays per CPU-s\n",
               mega(double(rays)), double(rays) / samples,
               100.0 * double(m.rays.test) / std::max<double>(1.0, double(rays)),
               mega(double(rays) / cpu));
    if (counter.available())
        fmt::print("instructions: {:.0f} per sample ({:.0f} per ray; user space, all threads)\n",
                   double(m.instructions) / samples,
                   double(m.instructions) / std::max<double>(1.0, double(rays)));
    else
        fmt::print("instructions: not counted ({})\n", counter.error());
}

/// The CPU time at which the RMSE curve (CPU-s, RMSE) reaches `target`: log(RMSE) against
/// log(time) between the two rounds that bracket the target, else from the nearest round with the
/// Monte Carlo rate RMSE ~ time^(-1/2).
void print_time_to_rmse(const std::vector<std::pair<double, double>> &curve, double target) {
    double time = 0.0;
    for (size_t k = 1; k < curve.size() && time == 0.0; ++k) {
        auto [t0, e0] = curve[k - 1];
        auto [t1, e1] = curve[k];
        if ((e0 - target) * (e1 - target) <= 0.0 && e0 != e1) {
            double a = (std::log(target) - std::log(e0)) / (std::log(e1) - std::log(e0));
            time = std::exp(std::log(t0) + a * (std::log(t1) - std::log(t0)));
        }
    }
    bool extrapolated = time == 0.0;
    if (extrapolated) {
        auto [t, e] = target < curve.back().second ? curve.back() : curve.front();
        time = t * (e / target) * (e / target);
    }
    fmt::print("              RMSE {:.6g} reached after {:.3f} CPU-s ({})\n", target, time,
               extrapolated ? "extrapolated with RMSE ~ 1/sqrt(time)" : "interpolated");
}

/// Equal error: renders at spp, 2 spp, 4 spp, ... each with its own CPU time and error against
/// the reference; the first round is the render already measured, `first`.
void print_equal_error(const BenchCommand &c, const Scene &scene, const Sensor &sensor,
                       const RenderOptions &ropts, const Measured &first, const Image &ref_image) {
    fmt::print("equal error : RMSE against {} (R, G, B)\n", c.reference);
    fmt::print("              {:>8} {:>12} {:>12} {:>14}\n", "spp", "CPU-s", "RMSE", "1/(RMSE² s)");
    std::vector<std::pair<double, double>> curve; // (CPU-s, RMSE)
    Measured later;
    for (int k = 0; k < c.rounds; ++k) {
        RenderOptions r = ropts;
        r.spp = c.spp << k;
        const Measured &round =
            k == 0 ? first : (later = measure_render(scene, sensor, r, nullptr));
        throw_if_interrupted(round.result);
        double e = rmse(round.result.image, ref_image);
        double t = std::max(round.cpu_seconds, 1e-9);
        curve.emplace_back(t, e);
        fmt::print("              {:>8} {:>12.3f} {:>12.6g} {:>14.6g}\n", r.spp, t, e,
                   1.0 / (e * e * t));
        std::fflush(stdout);
    }
    if (c.target_rmse > 0.0) print_time_to_rmse(curve, c.target_rmse);
}

/// The recorded queries sent again to Embree: the first pass, and the timed passes after it.
struct Replayed {
    RayRecording::Replay first, timed; ///< timed.differing counts the first pass's too
    uint64_t passes = 0;               ///< timed passes
    double cpu_seconds = 0.0;          ///< of the timed passes
};

/// Sends the recorded queries again to Embree on the calling thread. A first pass counts the
/// rays (and warms the caches, as the render had them); the timed passes send as many rays as
/// the render traced, `rays` (at most 64 passes), for a CPU time long enough to measure.
Replayed replay_timed(const RayRecording &recording, const Scene &scene, uint64_t rays) {
    Replayed r;
    r.first = recording.replay(scene);
    r.passes = r.first.rays == 0
                   ? 0
                   : std::clamp<uint64_t>((rays + r.first.rays - 1) / r.first.rays, 1, 64);
    const double replay_before = thread_cpu_seconds();
    for (uint64_t i = 0; i < r.passes; ++i) {
        const RayRecording::Replay pass = recording.replay(scene);
        r.timed.rays += pass.rays;
        r.timed.differing += pass.differing;
    }
    r.cpu_seconds = thread_cpu_seconds() - replay_before;
    r.timed.differing += r.first.differing;
    return r;
}

/// Embree alone: the queries of a render at fewer samples, at most RecordBudget of them (36
/// bytes each), sent to Embree again; their CPU time per ray, times the rays of the measured
/// render `m`, is Embree's share of it. Gives the signals back (uninstall_interrupt_handler).
/// Returns the share (0 to 1), or a negative value when it was skipped.
double print_embree_share(const Scene &scene, const Sensor &sensor, const RenderOptions &ropts,
                          const Measured &m) {
    const uint64_t rays = m.rays.total();
    if (rays == 0) {
        uninstall_interrupt_handler();
        fmt::print("embree alone: skipped (the render sent no ray to Embree)\n");
        return -1.0;
    }
    constexpr size_t RecordBudget = size_t(1) << 20;
    RenderOptions record = ropts;
    record.spp = int(std::clamp(double(ropts.spp) * double(RecordBudget) / double(rays), 1.0,
                                double(ropts.spp)));
    RayRecording recording(RecordBudget);
    RenderResult recorded = render(scene, sensor, record);
    recording.stop();
    uninstall_interrupt_handler();
    if (recorded.cancelled) FACET_THROW("interrupted");
    const Replayed replayed = replay_timed(recording, scene, rays);
    const RayRecording::Replay &replay = replayed.timed;
    if (replay.rays == 0) {
        fmt::print("embree alone: skipped (no ray recorded)\n");
        return -1.0;
    }
    const double samples = std::max<double>(1.0, double(m.result.samples));
    const double cpu = std::max(m.cpu_seconds, 1e-9);
    const double per_ray = replayed.cpu_seconds / double(replay.rays);
    const double embree_cpu = per_ray * double(rays);
    fmt::print("embree alone: {}rays from a {}-spp render sent again to Embree {}, on one "
               "thread with nothing around them: {}rays in {:.3f} CPU-s = {:.1f} CPU-ns per ray "
               "({})\n",
               mega(double(replayed.first.rays)), record.spp,
               replayed.passes == 1 ? std::string("once")
                                    : fmt::format("{} times", replayed.passes),
               mega(double(replay.rays)), replayed.cpu_seconds, 1e9 * per_ray,
               replay.differing == 0
                   ? std::string("every answer as in the render")
                   : fmt::format("{} answers differ from the render's", replay.differing));
    fmt::print("share       : Embree's own work is {:.1f}% of the render's CPU time ({}rays at "
               "{:.1f} CPU-ns); the rest, {:.1f} CPU-ns per sample, is facet's\n",
               100.0 * embree_cpu / cpu, mega(double(rays)), 1e9 * per_ray,
               1e9 * std::max(cpu - embree_cpu, 0.0) / samples);
    return embree_cpu / cpu;
}

/// The figures of the bench as one line of key=value pairs (--machine): samples are camera
/// samples (pixels x spp), time is CPU time; embree_share is "-" when it was not measured.
/// rmse: of the render against --reference ("-" without one).
void print_machine_line(const Measured &m, int spp, int threads, double embree_share, double rmse) {
    const double samples = std::max<double>(1.0, double(m.result.samples));
    const uint64_t rays = m.rays.total();
    fmt::print("machine: spp={} threads={} samples={} rays={} cpu_seconds={:.6f} "
               "cpu_ns_per_sample={:.3f} rays_per_sample={:.4f} embree_share={} rmse={}\n",
               spp, threads, m.result.samples, rays, m.cpu_seconds, 1e9 * m.cpu_seconds / samples,
               double(rays) / samples,
               embree_share < 0.0 ? std::string("-") : fmt::format("{:.4f}", embree_share),
               rmse < 0.0 ? std::string("-") : fmt::format("{:.9g}", rmse));
}

} // namespace

int bench_main(int argc, char **argv) {
    for (int i = 1; i < argc; ++i)
        if (std::strcmp(argv[i], "--suite") == 0 || std::strncmp(argv[i], "--suite=", 8) == 0)
            return bench_suite_main(argc, argv);
    BenchCommand c;
    CLI::App app("Measure samples and rays per CPU second of the scene's integrator and the share "
                 "of its CPU time that is Embree's own work; with --reference, the error against "
                 "a reference image as a function of CPU time",
                 "facet bench");
    add_bench_options(app, c);
    app.footer("facet bench --suite FILE [--runs N] [-t T] [--root DIR] benches the scenes "
               "FILE lists, each in a process of its own (see facet bench --suite --help)");
    if (int code = cli::parse(app, argc, argv); code >= 0) return code;
    cli::set_log_level(c.scene); // -q hides the note of a vectorised mode name
    c.scene.mode = resolve_mode(c.scene.mode);

    cli::SceneOptions &opts = c.scene;
    std::shared_ptr<Scene> scene = cli::load_scene(opts);
    const auto &sensors = scene->sensors();
    if (opts.sensor < 0 || size_t(opts.sensor) >= sensors.size())
        FACET_THROW("-s {}: the scene has {} sensor(s)", opts.sensor, sensors.size());
    const Sensor &sensor = *sensors[size_t(opts.sensor)];
    const int threads = cli::effective_threads(opts.threads);
    // The reference's size is checked before the render, its pixels read after it: they are not
    // part of the render's peak memory.
    if (!c.reference.empty()) read_reference(c.reference, sensor, true);

    RenderOptions ropts;
    ropts.threads = opts.threads;
    ropts.spp = c.spp;
    ropts.seed = c.seed;
    ropts.progress = false;
    std::atomic<bool> cancel{false};
    ropts.cancel = &cancel;

    fmt::print("bench {}: {}x{} pixels, {} spp, {} thread{}\n", opts.scene,
               sensor.film().crop_size().x, sensor.film().crop_size().y, c.spp, threads,
               threads == 1 ? "" : "s");
    std::fflush(stdout);

    InstructionCounter counter;
    install_interrupt_handler(&cancel);
    const Measured m = measure_render(*scene, sensor, ropts, &counter);
    throw_if_interrupted(m.result);
    print_render_cost(m, threads, counter);
    const Image ref_image =
        c.reference.empty() ? Image() : read_reference(c.reference, sensor, false);
    if (!c.reference.empty()) print_equal_error(c, *scene, sensor, ropts, m, ref_image);
    const double share = print_embree_share(*scene, sensor, ropts, m);
    if (c.machine)
        print_machine_line(m, c.spp, threads, share,
                           c.reference.empty() ? -1.0 : rmse(m.result.image, ref_image));
    return 0;
}
