// `facet bench`: how fast the scene's integrator renders, and how that compares with Embree
// tracing the same number of rays with no shading at all.
//
// Time is CPU time (user + system of the whole process around the render, i.e. of every render
// thread), not wall clock, which on a shared machine mostly measures the other processes.
// Instructions are counted with Linux perf events (one counter per thread) where the kernel
// allows it. With --reference, the equal-error mode renders at doubling sample counts and reports
// the RMSE against the reference image as a function of CPU time, and the efficiency
// 1 / (RMSE² · CPU time): an estimator that reaches the same error sooner is faster even if each
// sample costs more.
//
// Rays of the render are counted exactly: Scene::ray_count() sums per-thread counts of every
// ray_intersect() and ray_test() call (plain thread-local increments, no locks or atomics in the
// hot path). The plain Embree loop then traces that many incoherent rays through the same RTCScene
// on the same number of threads: origins at the primary hit points of a pixel grid, directions
// cosine-distributed about the hit's geometric normal, one rtcIntersect1 each (closest hit; the
// render's mix also has rtcOccluded1 shadow rays, which are cheaper).

#include "commands.h"

#include <facet/frame.h>
#include <facet/interaction.h>
#include <facet/logger.h>
#include <facet/random.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/warp.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <linux/perf_event.h>
#include <sys/syscall.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <dirent.h>
#include <unistd.h>
#include <vector>

namespace {

using namespace facet;

struct Hit {
    Point3f p;
    Normal3f n; ///< geometric normal, facing the camera
};

/// Primary hits of a grid of up to 256x256 camera rays through pixel centres.
std::vector<Hit> primary_hits(const Scene &scene, const Sensor &sensor) {
    Point2i size = sensor.film().size();
    int nx = std::min(size.x, 256), ny = std::min(size.y, 256);
    std::vector<Hit> hits;
    hits.reserve(size_t(nx) * size_t(ny));
    for (int y = 0; y < ny; ++y) {
        for (int x = 0; x < nx; ++x) {
            Point2f film_pos((x + 0.5f) / float(nx), (y + 0.5f) / float(ny));
            Ray ray = sensor.sample_ray(0.f, film_pos, Point2f(0.5f, 0.5f)).first;
            SurfaceInteraction si;
            if (!scene.ray_intersect(ray, si)) continue;
            Normal3f n = dot(si.n, ray.d) > 0.f ? -si.n : si.n;
            hits.push_back({si.p, n});
        }
    }
    return hits;
}

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

/// A render with its cost: wall and CPU seconds, instructions (0 when not counted), rays.
struct Measured {
    RenderResult result;
    double cpu_seconds = 0.0;
    uint64_t instructions = 0;
    uint64_t rays = 0;
};

Measured measure_render(const Scene &scene, const Sensor &sensor, const RenderOptions &ropts,
                        const InstructionCounter *counter) {
    Measured m;
    uint64_t rays_before = Scene::ray_count();
    uint64_t instr_before = counter ? counter->read() : 0;
    double cpu_before = process_cpu_seconds();
    m.result = render(scene, sensor, ropts);
    m.cpu_seconds = process_cpu_seconds() - cpu_before;
    m.instructions = counter ? counter->read() - instr_before : 0;
    m.rays = Scene::ray_count() - rays_before;
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

struct EmbreeLoop {
    double seconds = 0.0;
    uint64_t hits = 0;
};

/// Traces `count` rays from the hit points with cosine-distributed directions on `threads` threads.
EmbreeLoop embree_loop(const Scene &scene, const std::vector<Hit> &hits, uint64_t count,
                       int threads) {
    constexpr uint64_t Chunk = 4096;
    RTCScene rtc = scene.embree_scene();
    uint64_t chunks = (count + Chunk - 1) / Chunk;
    tbb::task_arena arena(threads);
    auto start = std::chrono::steady_clock::now();
    uint64_t hit_count = arena.execute([&] {
        return tbb::parallel_reduce(
            tbb::blocked_range<uint64_t>(0, chunks), uint64_t(0),
            [&](const tbb::blocked_range<uint64_t> &range, uint64_t found) {
                RTCIntersectContext context;
                for (uint64_t chunk = range.begin(); chunk != range.end(); ++chunk) {
                    PCG32 rng(chunk, 0x6a09e667f3bcc909ULL);
                    uint64_t end = std::min(count, (chunk + 1) * Chunk);
                    for (uint64_t i = chunk * Chunk; i < end; ++i) {
                        const Hit &hit = hits[rng.next_uint32(uint32_t(hits.size()))];
                        const float ux = rng.next_float(); // one draw per statement: a set
                        const float uy = rng.next_float(); // order whatever the compiler
                        Point2f u(ux, uy);
                        Vector3f d = Frame(hit.n).to_world(warp::square_to_cosine_hemisphere(u));
                        Interaction it;
                        it.p = hit.p;
                        it.n = hit.n;
                        it.t = 0.f;
                        Ray ray = it.spawn_ray(d);

                        RTCRayHit rh;
                        rh.ray.org_x = ray.o.x;
                        rh.ray.org_y = ray.o.y;
                        rh.ray.org_z = ray.o.z;
                        rh.ray.dir_x = ray.d.x;
                        rh.ray.dir_y = ray.d.y;
                        rh.ray.dir_z = ray.d.z;
                        rh.ray.tnear = ray.mint;
                        rh.ray.tfar = ray.maxt;
                        rh.ray.time = 0.f;
                        rh.ray.mask = uint32_t(-1);
                        rh.ray.id = 0;
                        rh.ray.flags = 0;
                        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
                        rtcInitIntersectContext(&context);
                        rtcIntersect1(rtc, &context, &rh);
                        found += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
                    }
                }
                return found;
            },
            [](uint64_t a, uint64_t b) { return a + b; });
    });
    EmbreeLoop result;
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.hits = hit_count;
    return result;
}

std::string mega(double v) { return fmt::format("{:.3f} M", v * 1e-6); }

} // namespace

int bench_main(int argc, char **argv) {
    cli::SceneOptions opts;
    int spp = 16;
    uint64_t seed = 0;
    std::string reference;
    int rounds = 6;
    double target_rmse = 0.0;
    CLI::App app("Measure samples and rays per CPU second of the scene's integrator against a "
                 "plain Embree loop tracing the same number of rays; with --reference, the error "
                 "against a reference image as a function of CPU time",
                 "facet bench");
    cli::add_scene_options(app, opts);
    app.add_option("--spp", spp,
                   "Samples per pixel (default 16); with --reference, of the first round")
        ->check(CLI::PositiveNumber);
    app.add_option("--seed", seed, "Added to the sampler's seed (default 0)");
    app.add_option("--reference", reference,
                   "Equal-error mode: RMSE against this image (e.g. a high-spp EXR of the same "
                   "scene) for renders at doubling sample counts");
    app.add_option("--rounds", rounds, "Equal-error mode: number of renders (default 6)")
        ->check(CLI::Range(1, 20));
    app.add_option("--target-rmse", target_rmse,
                   "Equal-error mode: also report the CPU time to reach this RMSE (interpolated "
                   "on the log-log curve, or extrapolated with RMSE ~ 1/sqrt(time))")
        ->check(CLI::PositiveNumber);
    if (int code = cli::parse(app, argc, argv); code >= 0) return code;

    std::shared_ptr<Scene> scene = cli::load_scene(opts);
    const auto &sensors = scene->sensors();
    if (opts.sensor < 0 || size_t(opts.sensor) >= sensors.size())
        FACET_THROW("-s {}: the scene has {} sensor(s)", opts.sensor, sensors.size());
    const Sensor &sensor = *sensors[size_t(opts.sensor)];
    int threads = cli::effective_threads(opts.threads);

    Image ref_image;
    if (!reference.empty()) {
        ref_image = read_image(reference);
        Point2i size = sensor.film().crop_size();
        if (ref_image.width != size.x || ref_image.height != size.y || ref_image.channels < 3)
            FACET_THROW("--reference {}: {}x{} pixels with {} channels, expected {}x{} with at "
                        "least 3 (R, G, B)",
                        reference, ref_image.width, ref_image.height, ref_image.channels, size.x,
                        size.y);
    }

    RenderOptions ropts;
    ropts.threads = opts.threads;
    ropts.spp = spp;
    ropts.seed = seed;
    ropts.progress = false;
    std::atomic<bool> cancel{false};
    ropts.cancel = &cancel;

    fmt::print("bench {}: {}x{} pixels, {} spp, {} thread{}\n", opts.scene,
               sensor.film().crop_size().x, sensor.film().crop_size().y, spp, threads,
               threads == 1 ? "" : "s");
    std::fflush(stdout);

    InstructionCounter counter;
    install_interrupt_handler(&cancel);
    Measured m = measure_render(*scene, sensor, ropts, &counter);
    if (m.result.cancelled) {
        uninstall_interrupt_handler();
        FACET_THROW("interrupted");
    }

    const RenderResult &result = m.result;
    const uint64_t rays = m.rays;
    const double samples = std::max<double>(1.0, double(result.samples));
    double cpu = std::max(m.cpu_seconds, 1e-9);
    fmt::print("render      : {}samples in {:.3f} CPU-s ({:.3f} CPU-s per thread; wall {:.3f} s) "
               "= {}samples per CPU-s, {:.1f} CPU-ns per sample\n",
               mega(double(result.samples)), m.cpu_seconds, m.cpu_seconds / threads, result.seconds,
               mega(double(result.samples) / cpu), 1e9 * cpu / samples);
    fmt::print("              {}rays (ray_intersect + ray_test calls, counted exactly; "
               "{:.2f} per sample) = {}rays per CPU-s\n",
               mega(double(rays)), double(rays) / samples, mega(double(rays) / cpu));
    if (counter.available())
        fmt::print("instructions: {:.0f} per sample ({:.0f} per ray; user space, all threads)\n",
                   double(m.instructions) / samples,
                   double(m.instructions) / std::max<double>(1.0, double(rays)));
    else
        fmt::print("instructions: not counted ({})\n", counter.error());

    if (!reference.empty()) {
        // Equal error: renders at spp, 2 spp, 4 spp, ... each with its own CPU time and error.
        fmt::print("equal error : RMSE against {} (R, G, B)\n", reference);
        fmt::print("              {:>8} {:>12} {:>12} {:>14}\n", "spp", "CPU-s", "RMSE",
                   "1/(RMSE² s)");
        std::vector<std::pair<double, double>> curve; // (CPU-s, RMSE)
        for (int k = 0; k < rounds; ++k) {
            RenderOptions r = ropts;
            r.spp = spp << k;
            Measured round = k == 0 ? std::move(m) : measure_render(*scene, sensor, r, nullptr);
            if (round.result.cancelled) {
                uninstall_interrupt_handler();
                FACET_THROW("interrupted");
            }
            double e = rmse(round.result.image, ref_image);
            double t = std::max(round.cpu_seconds, 1e-9);
            curve.emplace_back(t, e);
            fmt::print("              {:>8} {:>12.3f} {:>12.6g} {:>14.6g}\n", r.spp, t, e,
                       1.0 / (e * e * t));
            std::fflush(stdout);
        }
        if (target_rmse > 0.0) {
            // log(RMSE) against log(time): between the two rounds that bracket the target, else
            // from the nearest round with the Monte Carlo rate RMSE ~ time^(-1/2).
            double time = 0.0;
            for (size_t k = 1; k < curve.size() && time == 0.0; ++k) {
                auto [t0, e0] = curve[k - 1];
                auto [t1, e1] = curve[k];
                if ((e0 - target_rmse) * (e1 - target_rmse) <= 0.0 && e0 != e1) {
                    double a =
                        (std::log(target_rmse) - std::log(e0)) / (std::log(e1) - std::log(e0));
                    time = std::exp(std::log(t0) + a * (std::log(t1) - std::log(t0)));
                }
            }
            bool extrapolated = time == 0.0;
            if (extrapolated) {
                auto [t, e] = target_rmse < curve.back().second ? curve.back() : curve.front();
                time = t * (e / target_rmse) * (e / target_rmse);
            }
            fmt::print("              RMSE {:.6g} reached after {:.3f} CPU-s ({})\n", target_rmse,
                       time,
                       extrapolated ? "extrapolated with RMSE ~ 1/sqrt(time)" : "interpolated");
        }
    }
    uninstall_interrupt_handler();

    std::vector<Hit> hits = primary_hits(*scene, sensor);
    if (hits.empty() || rays == 0) {
        fmt::print("embree loop : skipped (no camera ray hits the scene)\n");
        return 0;
    }
    double loop_cpu_before = process_cpu_seconds();
    EmbreeLoop loop = embree_loop(*scene, hits, rays, threads);
    double loop_cpu = std::max(process_cpu_seconds() - loop_cpu_before, 1e-9);
    double render_rays_per_cpu_s = double(rays) / cpu;
    double loop_rays_per_cpu_s = double(rays) / loop_cpu;
    fmt::print("embree loop : {}rays in {:.3f} CPU-s (wall {:.3f} s) = {}rays per CPU-s "
               "(rtcIntersect1 only, no shading; origins at {} primary hits, cosine directions; "
               "{:.1f}% hit)\n",
               mega(double(rays)), loop_cpu, loop.seconds, mega(loop_rays_per_cpu_s), hits.size(),
               100.0 * double(loop.hits) / double(rays));
    fmt::print("ratio       : the render traces rays at {:.1f}% of the plain Embree rate (per "
               "CPU-s)\n",
               100.0 * render_rays_per_cpu_s / loop_rays_per_cpu_s);
    return 0;
}
