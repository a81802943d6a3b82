// `facet bench`: how fast the scene's integrator renders, and how that compares with Embree
// tracing the same number of rays with no shading at all.
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
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cstdio>
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
                        Point2f u(rng.next_float(), rng.next_float());
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
    CLI::App app("Measure samples/s and rays/s of the scene's integrator against a plain Embree "
                 "loop tracing the same number of rays",
                 "facet bench");
    cli::add_scene_options(app, opts);
    app.add_option("--spp", spp, "Samples per pixel (default 16)")->check(CLI::PositiveNumber);
    app.add_option("--seed", seed, "Added to the sampler's seed (default 0)");
    if (int code = cli::parse(app, argc, argv); code >= 0) return code;

    std::shared_ptr<Scene> scene = cli::load_scene(opts);
    const auto &sensors = scene->sensors();
    if (opts.sensor < 0 || size_t(opts.sensor) >= sensors.size())
        FACET_THROW("-s {}: the scene has {} sensor(s)", opts.sensor, sensors.size());
    const Sensor &sensor = *sensors[size_t(opts.sensor)];
    int threads = cli::effective_threads(opts.threads);

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

    install_interrupt_handler(&cancel);
    uint64_t rays_before = Scene::ray_count();
    RenderResult result = render(*scene, sensor, ropts);
    uint64_t rays = Scene::ray_count() - rays_before;
    uninstall_interrupt_handler();
    if (result.cancelled) FACET_THROW("interrupted");

    double secs = std::max(result.seconds, 1e-9);
    double render_rays_per_s = double(rays) / secs;
    fmt::print("render      : {}samples in {:.3f} s = {}samples/s\n", mega(double(result.samples)),
               result.seconds, mega(double(result.samples) / secs));
    fmt::print("              {}rays (ray_intersect + ray_test calls, counted exactly; "
               "{:.2f} per sample) = {}rays/s\n",
               mega(double(rays)), double(rays) / std::max<double>(1.0, double(result.samples)),
               mega(render_rays_per_s));

    std::vector<Hit> hits = primary_hits(*scene, sensor);
    if (hits.empty() || rays == 0) {
        fmt::print("embree loop : skipped (no camera ray hits the scene)\n");
        return 0;
    }
    EmbreeLoop loop = embree_loop(*scene, hits, rays, threads);
    double loop_rays_per_s = double(rays) / std::max(loop.seconds, 1e-9);
    fmt::print("embree loop : {}rays in {:.3f} s = {}rays/s (rtcIntersect1 only, no shading; "
               "origins at {} primary hits, cosine directions; {:.1f}% hit)\n",
               mega(double(rays)), loop.seconds, mega(loop_rays_per_s), hits.size(),
               100.0 * double(loop.hits) / double(rays));
    fmt::print("ratio       : the render traces rays at {:.1f}% of the plain Embree rate\n",
               100.0 * render_rays_per_s / loop_rays_per_s);
    return 0;
}
