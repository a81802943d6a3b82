// `facet render`: loads a scene, renders one of its sensors and writes the image.

#include "commands.h"

#include <facet/film.h>
#include <facet/image.h>
#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <CLI/CLI.hpp>
#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <tbb/info.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <map>

namespace fs = std::filesystem;

namespace facet::cli {

void add_scene_options(CLI::App &app, SceneOptions &opts) {
    app.add_option("scene", opts.scene, "Scene file (Mitsuba 3 XML)")->required();
    app.add_option("-D,--define", opts.defines, "Set a scene parameter: -D key=value (repeatable)")
        ->take_all();
    app.add_option("-a", opts.plugin_dirs,
                   "Add folders to the plugin and file search paths (';' separates several)");
    app.add_option("-t,--threads", opts.threads, "Render threads (default: all cores)")
        ->each([&opts](const std::string &) { opts.threads_given = true; });
    app.add_option("-s,--sensor", opts.sensor, "Index of the sensor to render (default 0)");
    app.add_flag("-v,--verbose", opts.verbose, "More log output (repeat for even more)");
    app.add_flag("-q,--quiet", opts.quiet, "Only warnings and errors; no progress line");
    app.add_flag("--lenient", opts.lenient,
                 "Unused -D values and unused scene parameters are warnings, not errors");
}

int effective_threads(int threads) {
    return threads > 0 ? threads : tbb::info::default_concurrency();
}

std::shared_ptr<Scene> load_scene(SceneOptions &opts) {
    if (opts.verbose >= 2)
        Logger::set_level(LogLevel::Trace);
    else if (opts.verbose == 1)
        Logger::set_level(LogLevel::Debug);
    else if (opts.quiet)
        Logger::set_level(LogLevel::Warn);

    if (opts.threads_given && opts.threads < 1) {
        FACET_LOG(Warn, "-t {} is less than 1: using 1 thread", opts.threads);
        opts.threads = 1;
    }

    LoadOptions load;
    load.lenient = opts.lenient;
    for (const std::string &value : opts.plugin_dirs) {
        size_t start = 0;
        while (start <= value.size()) {
            size_t end = value.find(';', start);
            if (end == std::string::npos) end = value.size();
            std::string dir = value.substr(start, end - start);
            if (!dir.empty()) {
                PluginRegistry::instance().add_search_dir(dir);
                load.search_path.push_back(dir);
            }
            start = end + 1;
        }
    }
    for (const std::string &define : opts.defines) {
        size_t eq = define.find('=');
        if (eq == std::string::npos) FACET_THROW("-D expects key=value, got \"{}\"", define);
        if (eq == 0) FACET_THROW("-D \"{}\" has no parameter name before '='", define);
        load.params[define.substr(0, eq)] = define.substr(eq + 1);
    }

    if (!fs::exists(opts.scene)) FACET_THROW("scene file \"{}\" does not exist", opts.scene);
    // The first call fixes Embree's thread count; it must come before the scene builds its BVH.
    embree_device(opts.threads);
    return facet::load_scene(opts.scene, load);
}

} // namespace facet::cli

namespace {

using namespace facet;

/// Mitsuba's rule: the scene's name (or the -o name) with the film's extension, unless the -o
/// name already has an extension.
std::string output_path(const std::string &scene, const std::string &out, const Film &film) {
    fs::path path = out.empty() ? fs::path(scene) : fs::path(out);
    if (out.empty() || !path.has_extension()) path.replace_extension(film.default_extension());
    return path.string();
}

/// Catches a bad output name before a long render rather than after it.
void check_output(const std::string &path) {
    fs::path p(path);
    fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
    if (!fs::is_directory(dir))
        FACET_THROW("cannot write \"{}\": folder \"{}\" does not exist", path, dir.string());
    if (!OIIO::ImageOutput::create(path))
        FACET_THROW("cannot write \"{}\": no image format for the extension \"{}\"", path,
                    p.extension().string());
}

std::string format_seconds(double s) {
    if (s < 60.0) return fmt::format("{:.2f} s", s);
    int minutes = int(s / 60.0);
    if (minutes < 60) return fmt::format("{} min {:.1f} s", minutes, s - minutes * 60.0);
    return fmt::format("{} h {} min {:.0f} s", minutes / 60, minutes % 60, s - minutes * 60.0);
}

} // namespace

int render_main(int argc, char **argv) {
    cli::SceneOptions opts;
    std::string output, ocio_config, view = "Standard";
    uint64_t seed = 0;
    int spp = 0;

    CLI::App app("Render a Mitsuba 3 scene", "facet render");
    cli::add_scene_options(app, opts);
    app.add_option("-o,--output", output,
                   "Output image (default: the scene's name with .exr); .png/.jpg are tone mapped "
                   "through OpenColorIO");
    app.add_option("--seed", seed, "Added to the sampler's seed (default 0)");
    app.add_option("--spp", spp, "Samples per pixel (default: the sampler's sample_count)")
        ->check(CLI::PositiveNumber);
    app.add_option("--ocio-config", ocio_config,
                   "OpenColorIO config for 8-bit outputs (default: $OCIO, else facet's own)");
    app.add_option("--view", view, "OpenColorIO view for 8-bit outputs: Standard or Raw");
    if (int code = cli::parse(app, argc, argv); code >= 0) return code;

    std::shared_ptr<Scene> scene = cli::load_scene(opts);
    const auto &sensors = scene->sensors();
    if (opts.sensor < 0 || size_t(opts.sensor) >= sensors.size())
        FACET_THROW("-s {}: the scene has {} sensor{} (valid indices 0..{})", opts.sensor,
                    sensors.size(), sensors.size() == 1 ? "" : "s", int(sensors.size()) - 1);
    const Sensor &sensor = *sensors[size_t(opts.sensor)];
    const Film &film = sensor.film();

    std::string out = output_path(opts.scene, output, film);
    check_output(out);

    RenderOptions ropts;
    ropts.threads = opts.threads;
    ropts.seed = seed;
    ropts.spp = spp;
    ropts.progress = !opts.quiet;
    std::atomic<bool> cancel{false};
    ropts.cancel = &cancel;
    int used_spp = spp > 0 ? spp : int(sensor.sampler().sample_count());
    int threads = cli::effective_threads(opts.threads);

    // From here on Ctrl-C stops the render and the partial image is written.
    install_interrupt_handler(&cancel);
    if (!opts.quiet) {
        fmt::print("Rendering {}: {}x{} pixels, {} spp, {} thread{}\n", opts.scene,
                   film.crop_size().x, film.crop_size().y, used_spp, threads,
                   threads == 1 ? "" : "s");
        std::fflush(stdout);
    }
    RenderResult result;
    try {
        result = render(*scene, sensor, ropts);
    } catch (...) {
        uninstall_interrupt_handler();
        throw;
    }
    uninstall_interrupt_handler();

    ImageWriteOptions wopts;
    wopts.ocio_config = ocio_config;
    wopts.view = view;
    wopts.metadata["facet:spp"] = std::to_string(used_spp);
    wopts.metadata["facet:render_time"] = fmt::format("{:.3f}", result.seconds);
    wopts.metadata["facet:scene"] = fs::absolute(opts.scene).lexically_normal().string();
    wopts.metadata["facet:seed"] = std::to_string(seed);
    if (result.cancelled)
        wopts.metadata["facet:blocks"] =
            fmt::format("{}/{}", result.blocks_done, result.blocks_total);
    film.write(result.image, out, wopts);

    if (result.timed_out) {
        // The integrator's `timeout` is a request, not an interruption: success.
        if (!opts.quiet)
            fmt::print("Timeout reached after {} ({} of {} work units), wrote {}\n",
                       format_seconds(result.seconds), result.blocks_done, result.blocks_total,
                       out);
        return 0;
    }
    if (result.cancelled) {
        std::fprintf(stderr,
                     "facet: interrupted after %s: wrote the partial image (%zu of %zu blocks) "
                     "to %s\n",
                     format_seconds(result.seconds).c_str(), result.blocks_done,
                     result.blocks_total, out.c_str());
        return 130;
    }
    if (!opts.quiet) fmt::print("Rendered in {}, wrote {}\n", format_seconds(result.seconds), out);
    return 0;
}
