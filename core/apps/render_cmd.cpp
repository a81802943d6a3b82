// `facet render`: loads a scene, renders one of its sensors and writes the image.

#include "commands.h"

#include <facet/film.h>
#include <facet/image.h>
#include <facet/integrator.h>
#include <facet/logger.h>
#include <facet/mode.h>
#include <facet/output_metadata.h>
#include <facet/plugin.h>
#include <facet/render.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/xml.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <unistd.h>

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

void add_mode_option(CLI::App &app, std::string &mode) {
    mode = default_mode();
    app.add_option("-m,--mode", mode,
                   fmt::format("Colour mode, by Mitsuba's variant names: {} (default {}); the "
                               "llvm_, cuda_ and _ad_ names of a mode render as that mode",
                               fmt::join(modes(), ", "), default_mode()))
        ->type_name("MODE");
}

int effective_threads(int threads) { return capped_thread_count(std::max(threads, 0)); }

void set_log_level(const SceneOptions &opts) {
    if (opts.verbose >= 2)
        Logger::set_level(LogLevel::Trace);
    else if (opts.verbose == 1)
        Logger::set_level(LogLevel::Debug);
    else if (opts.quiet)
        Logger::set_level(LogLevel::Warn);
}

std::shared_ptr<Scene> load_scene(SceneOptions &opts) {
    set_log_level(opts);

    if (opts.threads_given && opts.threads < 1) {
        FACET_LOG(Warn, "-t {} is less than 1: using 1 thread", opts.threads);
        opts.threads = 1;
    }
    if (opts.threads > hardware_threads()) {
        FACET_LOG(Warn, "-t {}: this machine has {} hardware threads; using {}", opts.threads,
                  hardware_threads(), hardware_threads());
        opts.threads = hardware_threads();
    }

    LoadOptions load;
    load.lenient = opts.lenient;
    load.mode = opts.mode;
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

    std::error_code exists_error; // e.g. a name over NAME_MAX
    if (!fs::exists(opts.scene, exists_error))
        FACET_THROW("scene file \"{}\" {}", opts.scene,
                    exists_error ? exists_error.message() : std::string("does not exist"));
    // The first call fixes Embree's thread count; it must come before the scene builds its BVH.
    embree_device(opts.threads);
    set_activity(fmt::format("loading \"{}\"", opts.scene));
    return facet::load_scene(opts.scene, load);
}

} // namespace facet::cli

namespace {

using namespace facet;

/// Mitsuba's rule: the scene's name (or the -o name) with the film's extension, unless the -o
/// name already has an extension.
std::string output_path(const std::string &scene, const std::string &out, const Film &film) {
    fs::path path = out.empty() ? fs::path(scene) : fs::path(out);
    // -o a folder (existing, or named with a trailing '/'): the scene's name in that folder.
    // (An error such as a name over NAME_MAX is no folder; check_output says what is wrong.)
    std::error_code ec;
    const bool folder = !out.empty() && (out.back() == '/' || fs::is_directory(path, ec));
    if (folder) path = path / fs::path(scene).filename();
    if (out.empty() || folder || !path.has_extension())
        path.replace_extension(film.default_extension());
    return path.string();
}

/// A one-pixel image with the channels of the image `facet render` writes: the film's own
/// colour channels (a one-pixel develop of the sensor's film: a film plugin names them), the
/// integrator's AOVs, and the raw sums of a part of a split render.
struct ChannelsProbe {
    Image image;
    size_t colour = 0, aovs = 0; ///< the first `colour` channels, then `aovs`, then raw sums
};

ChannelsProbe output_channels_probe(const Scene &scene, const Sensor &sensor, bool part) {
    const Film &film = sensor.film();
    std::vector<std::string> aovs;
    if (auto sampling = std::dynamic_pointer_cast<SamplingIntegrator>(scene.integrator()))
        aovs = sampling->aov_names();
    // (A light tracer refuses a film of spectral bands when it renders, with its reasons.)
    const bool splats =
        bool(std::dynamic_pointer_cast<LightTracer>(scene.integrator())) && !film.bands();
    const FilmBuffer buffer(Point2i(0, 0), Point2i(1, 1), film.colour_channels(), aovs, splats);
    ChannelsProbe probe;
    probe.image = film.develop(buffer);
    probe.aovs = aovs.size();
    probe.colour = size_t(probe.image.channels) - aovs.size();
    if (part) {
        const std::vector<std::string> raw = buffer.raw_channel_names();
        Image with_raw(1, 1, probe.image.channels + int(raw.size()));
        with_raw.x = probe.image.x;
        with_raw.y = probe.image.y;
        with_raw.full_width = probe.image.full_width;
        with_raw.full_height = probe.image.full_height;
        with_raw.channel_names = probe.image.channel_names;
        with_raw.channel_names.insert(with_raw.channel_names.end(), raw.begin(), raw.end());
        probe.image = std::move(with_raw);
    }
    return probe;
}

/// Proves before a long render that its output can be written, rather than failing after it:
/// the name (not a directory, fits a file name with its temporary name), the folder (exists, a
/// file can be created there), the display, view and looks of 8-bit formats, channel names that
/// differ (Mitsuba refuses duplicates too: an AOV called "R" would hide the red channel), and a
/// trial write of a one-pixel image with the output's format, channels and options through the
/// same writer (encoded, written, read back, renamed) to a scratch name next to the output.
void check_output(const std::string &path, const ImageWriteOptions &wopts, const Scene &scene,
                  const Sensor &sensor, const std::string &scene_file, bool part) {
    check_output_file(path);
    check_image_output(path, wopts);

    const ChannelsProbe probe = output_channels_probe(scene, sensor, part);
    const std::vector<std::string> &names = probe.image.channel_names;
    auto kind = [&probe](size_t c) {
        return c < probe.colour                ? "a colour channel of the film"
               : c < probe.colour + probe.aovs ? "another AOV"
                                               : "a raw channel of a part";
    };
    for (size_t i = 0; i < names.size(); ++i)
        for (size_t j = 0; j < i; ++j)
            if (names[i] == names[j]) {
                // j < i: the AOV is i, unless i is a raw channel (then j is the AOV).
                const bool raw_i = i >= probe.colour + probe.aovs;
                FACET_THROW("{}: the integrator's AOV \"{}\" has the name of {}: channel names "
                            "must be unique, rename the AOV",
                            scene_file, names[i], kind(raw_i ? i : j));
            }

    fs::path p(path);
    const fs::path trial =
        p.parent_path() / fmt::format(".facet-check-{}{}", ::getpid(), p.extension().string());
    try {
        sensor.film().write(probe.image, trial.string(), wopts);
    } catch (const std::exception &e) {
        std::error_code ec;
        fs::remove(trial, ec);
        std::string why = e.what();
        // The writer's message names the scratch file; say it of the output.
        for (size_t at; (at = why.find(trial.string())) != std::string::npos;)
            why.replace(at, trial.string().size(), path);
        FACET_THROW("{} (a trial write of one pixel, before rendering)", why);
    }
    std::error_code ec;
    fs::remove(trial, ec);
}

std::string format_seconds(double s) {
    if (s < 60.0) return fmt::format("{:.2f} s", s);
    int minutes = int(s / 60.0);
    if (minutes < 60) return fmt::format("{} min {:.1f} s", minutes, s - minutes * 60.0);
    return fmt::format("{} h {} min {:.0f} s", minutes / 60, minutes % 60, s - minutes * 60.0);
}

/// The options of `facet render` beyond the scene's.
struct RenderCommand {
    cli::SceneOptions scene;
    std::string mode; ///< -m, resolved before the first scene loads
    std::vector<std::string> more_scenes;
    std::string output, ocio_config, display, view, looks;
    uint64_t seed = 0;
    int spp = 0;
    std::vector<int> crop;
    int pass_index = -1, pass_count = 0;
    bool pass_given = false; ///< --pass was on the command line
};

void add_render_options(CLI::App &app, RenderCommand &c) {
    cli::add_scene_options(app, c.scene);
    cli::add_mode_option(app, c.mode);
    app.add_option("more_scenes", c.more_scenes,
                   "Further scene files, rendered one after the other with the same options");
    app.add_option("-o,--output", c.output,
                   "Output image (default: the scene's name with .exr); .png/.jpg are tone mapped "
                   "through OpenColorIO");
    app.add_option("--seed", c.seed, "Added to the sampler's seed (default 0)");
    app.add_option("--spp", c.spp,
                   "Samples per pixel (default: the sampler's sample_count; samplers may round "
                   "it, e.g. stratified to a square: the summary and the EXR say what was taken)");
    app.add_option("--crop", c.crop,
                   "Render only film pixels [X0, X1) x [Y0, Y1) (the EXR's data window inside "
                   "the full display window); pixels equal those of a full render")
        ->expected(4)
        ->type_name("X0 Y0 X1 Y1");
    app.add_option("--pass", c.pass_index,
                   "Render part I (0-based) of the --passes N independent parts of one render "
                   "of N x spp samples per pixel (for merging later)")
        ->type_name("I");
    app.add_option("--passes", c.pass_count,
                   "Number of parts for --pass (default 1); without --pass, every part one after "
                   "the other, combined as `facet merge` combines them")
        ->type_name("N");
    app.add_option("--ocio-config", c.ocio_config,
                   "OpenColorIO config for 8-bit outputs (default: $OCIO, else facet's own)");
    app.add_option("--display", c.display,
                   "OpenColorIO display for 8-bit outputs (default: the config's default; "
                   "`facet colors` lists them)");
    app.add_option("--view", c.view,
                   "OpenColorIO view of that display (default: the display's default)");
    app.add_option("--look", c.looks, "OpenColorIO looks to apply (\"a, +b, -c\")");
}

/// The scene files to render, checked before the first renders: several scenes (Mitsuba's
/// `mitsuba a.xml b.xml`) each write their own image, so -o can only be a folder.
std::vector<std::string> scenes_to_render(const RenderCommand &c) {
    std::vector<std::string> scenes{c.scene.scene};
    scenes.insert(scenes.end(), c.more_scenes.begin(), c.more_scenes.end());
    if (scenes.size() > 1 && !c.output.empty() && c.output.back() != '/') {
        std::error_code ec;
        if (!fs::is_directory(c.output, ec))
            FACET_THROW("-o {}: {} scenes are rendered, each to its own image: -o must name a "
                        "folder (an existing one, or ending in '/'), or be left out",
                        c.output, scenes.size());
    }
    // A mistyped name is refused before the first scene renders, not after it.
    for (size_t i = 1; i < scenes.size(); ++i) {
        std::error_code exists_error;
        if (!fs::exists(scenes[i], exists_error))
            FACET_THROW("scene file \"{}\" {} (nothing was rendered)", scenes[i],
                        exists_error ? exists_error.message() : std::string("does not exist"));
    }
    // Two scenes whose images would take one name (a/scene.xml and b/scene.xml with -o a
    // folder): the second would replace the first's image.
    std::map<fs::path, size_t> images;
    for (size_t i = 0; i < scenes.size() && scenes.size() > 1; ++i) {
        const fs::path scene(scenes[i]);
        std::error_code ec;
        fs::path image = c.output.empty() ? fs::weakly_canonical(scene, ec).parent_path()
                                          : fs::weakly_canonical(c.output, ec);
        image /= scene.stem();
        auto [it, added] = images.emplace(image, i);
        if (!added)
            FACET_THROW("scenes \"{}\" and \"{}\" would both write {}.*: render them to "
                        "different folders (nothing was rendered)",
                        scenes[it->second], scenes[i],
                        (c.output.empty() ? scene.parent_path() / scene.stem()
                                          : fs::path(c.output) / scene.stem())
                            .string());
    }
    return scenes;
}

/// The render options of the command line: threads, seed, spp, the crop window (checked against
/// the film) and the part of a split render.
RenderOptions render_options(const RenderCommand &c, const Film &film) {
    RenderOptions ropts;
    ropts.threads = c.scene.threads;
    ropts.seed = c.seed;
    ropts.spp = c.spp;
    ropts.progress = !c.scene.quiet;
    const std::vector<int> &crop = c.crop;
    if (!crop.empty()) {
        const Point2i size = film.size();
        if (crop[0] < 0 || crop[1] < 0 || crop[2] > size.x || crop[3] > size.y ||
            crop[2] <= crop[0] || crop[3] <= crop[1])
            FACET_THROW("--crop {} {} {} {}: expected X0 Y0 X1 Y1 with 0 <= X0 < X1 <= {} and "
                        "0 <= Y0 < Y1 <= {} (the film is {}x{}; X1 and Y1 are exclusive)",
                        crop[0], crop[1], crop[2], crop[3], size.x, size.y, size.x, size.y);
        ropts.crop = {{crop[0], crop[1], crop[2], crop[3]}};
    }
    if (c.pass_count != 0 || c.pass_index >= 0) {
        // --passes N alone: all N parts in this process (pass index -1).
        const int pass_index = c.pass_count >= 1 && !c.pass_given ? -1 : c.pass_index;
        if (c.pass_count < 1 || pass_index < -1 || pass_index >= c.pass_count ||
            (pass_index == -1 && c.pass_given))
            FACET_THROW("--pass I --passes N: expected N >= 1 and 0 <= I < N (or --passes N "
                        "alone for all the parts), got --pass {} --passes {}",
                        pass_index < 0 ? std::string("(none)") : std::to_string(pass_index),
                        c.pass_count == 0 ? std::string("(none)") : std::to_string(c.pass_count));
        ropts.pass_index = pass_index;
        ropts.pass_count = c.pass_count;
    }
    return ropts;
}

/// render_sample_range(), its error naming the options the sample count came from.
SampleRange sample_range(const RenderCommand &c, const Sensor &sensor, const RenderOptions &ropts) {
    try {
        return render_sample_range(sensor, ropts);
    } catch (const Error &e) {
        if (e.location().valid()) throw; // a sampler's error, at its place in the scene
        const std::string count = c.spp > 0 ? fmt::format("--spp {}", c.spp)
                                            : fmt::format("the sampler's sample_count {}",
                                                          sensor.sampler().sample_count());
        const std::string parts =
            c.pass_count > 0 ? fmt::format(", --passes {}", c.pass_count) : "";
        FACET_THROW("{}{}: {}", count, parts, e.message());
    }
}

/// What ties the parts of one render together (checked by a merge): scene_identity() of the
/// scene file, the -D values and the film size.
std::string scene_hash(const cli::SceneOptions &opts, const Film &film) {
    std::map<std::string, std::string> params;
    for (const std::string &define : opts.defines) {
        size_t eq = define.find('=');
        params[define.substr(0, eq)] = define.substr(eq + 1);
    }
    std::ifstream scene_file(opts.scene, std::ios::binary);
    std::string scene_text((std::istreambuf_iterator<char>(scene_file)),
                           std::istreambuf_iterator<char>());
    return scene_identity(scene_text, params, film.size().x, film.size().y);
}

/// "Rendering scene.xml: 64x64 pixels, 16 spp, 8 threads" (and the crop and part rendered).
void print_start(const RenderCommand &c, const Sensor &sensor, const SampleRange &range,
                 const RenderOptions &ropts) {
    const Film &film = sensor.film();
    const std::vector<int> &crop = c.crop;
    const uint64_t asked = uint64_t(c.spp > 0 ? uint32_t(c.spp) : sensor.sampler().sample_count()) *
                           uint64_t(ropts.pass_count);
    // The sampler's rounding, said where the spp is printed.
    const std::string rounding =
        range.total != asked ? fmt::format(" (the sampler rounds {} up to {})", asked, range.total)
                             : "";
    const int threads = cli::effective_threads(c.scene.threads);
    const int w = crop.empty() ? film.crop_size().x : crop[2] - crop[0];
    const int h = crop.empty() ? film.crop_size().y : crop[3] - crop[1];
    fmt::print("Rendering {}: {}x{} pixels{}, {} spp{}{}, {} thread{}\n", c.scene.scene, w, h,
               crop.empty() ? ""
                            : fmt::format(" (crop {} {} {} {} of {}x{})", crop[0], crop[1], crop[2],
                                          crop[3], film.size().x, film.size().y),
               range.count, rounding,
               ropts.pass_count > 1 && ropts.pass_index < 0
                   ? fmt::format(" (in {} parts, combined as a merge of them)", ropts.pass_count)
               : ropts.pass_count > 1 ? fmt::format(" (part {} of {}: samples {}..{} of {})",
                                                    ropts.pass_index, ropts.pass_count, range.first,
                                                    range.first + range.count - 1, range.total)
                                      : "",
               threads, threads == 1 ? "" : "s");
    std::fflush(stdout);
}

/// The summary of where the time went (-v: every phase).
void print_times(const RenderResult &result, double write_seconds, bool verbose) {
    fmt::print("Times: load {} (acceleration structure {}), render {}\n",
               format_seconds(result.load_seconds), format_seconds(result.accel_seconds),
               format_seconds(result.seconds));
    if (verbose) {
        fmt::print("  scene file and plugins  {}\n",
                   format_seconds(std::max(0.0, result.load_seconds - result.accel_seconds)));
        fmt::print("  acceleration structure  {}\n", format_seconds(result.accel_seconds));
        const double rate =
            result.sampling_seconds > 0.0 ? double(result.samples) / result.sampling_seconds : 0.0;
        fmt::print("  sampling                {} ({} of {} work units, {:.3g} samples/s)\n",
                   format_seconds(result.sampling_seconds), result.blocks_done, result.blocks_total,
                   rate);
        if (result.first_block_cpu_seconds > 0.0)
            fmt::print("  first pixels            {:.3f} s CPU from the start of the process "
                       "(every thread)\n",
                       result.first_block_cpu_seconds);
        fmt::print("  developing the film     {}\n", format_seconds(result.develop_seconds));
        fmt::print("  writing the image       {}\n", format_seconds(write_seconds));
    }
    std::fflush(stdout);
}

/// The last word of a render: after a signal one line on stderr (the signal, when it came, what
/// is in the output file) and 128 + the signal; else a line on stdout (unless quiet) and 0.
int report_end(const RenderResult &result, const std::string &out, bool signal_in_render,
               const std::string &write_error, bool quiet) {
    const std::string reached =
        fmt::format("{} of {} spp{}", result.spp, result.spp_target,
                    result.spp == 0 ? ", no pass finished: the image is black" : "");
    if (const int sig = interrupt_signal(); sig != 0) {
        const std::string what =
            result.cancelled && !result.timed_out ? fmt::format("the partial image ({})", reached)
            : result.timed_out ? fmt::format("the image of the timeout ({})", reached)
                               : fmt::format("the complete image ({})", reached);
        const std::string when =
            signal_in_render ? "after " + format_seconds(result.seconds) : "while writing";
        const char *verb = sig == SIGTERM  ? "terminated"
                           : sig == SIGHUP ? "hung up"
                                           : "interrupted";
        if (write_error.empty())
            std::fprintf(stderr, "facet: %s (%s) %s: wrote %s to %s\n", verb,
                         interrupt_signal_name(sig), when.c_str(), what.c_str(), out.c_str());
        else
            std::fprintf(stderr, "facet: %s (%s) %s: %s was not written: %s\n", verb,
                         interrupt_signal_name(sig), when.c_str(), what.c_str(),
                         write_error.c_str());
        return 128 + sig;
    }
    if (result.timed_out) {
        // The integrator's `timeout` is a request, not an interruption: success.
        if (!quiet)
            fmt::print("Timeout reached after {} ({}), wrote {}\n", format_seconds(result.seconds),
                       reached, out);
        return 0;
    }
    if (!quiet) fmt::print("Rendered in {}, wrote {}\n", format_seconds(result.seconds), out);
    return 0;
}

/// How the write of the output went: its time, and the error of a write that a signal
/// interrupted (said with the signal; any other error is thrown).
struct Written {
    double seconds = 0.0;
    std::string error;
};

/// Writes the render's image to `out` with the file attributes of the render.
Written write_image(const RenderCommand &c, const Sensor &sensor, const RenderResult &result,
                    const std::string &hash, const std::string &out, ImageWriteOptions wopts) {
    add_metadata(wopts,
                 render_file_metadata(render_file_info(
                     result, sensor, hash, fs::absolute(c.scene.scene).lexically_normal().string(),
                     c.seed, c.mode)));
    cli::set_activity(fmt::format("writing \"{}\"", out));
    const auto write_start = std::chrono::steady_clock::now();
    Written written;
    try {
        sensor.film().write(result.image, out, wopts);
    } catch (const std::exception &e) {
        if (interrupt_signal() == 0) throw;
        written.error = e.what(); // said with the signal, by report_end()
    }
    written.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - write_start).count();
    return written;
}

/// Loads the scene `c.scene.scene`, renders it and writes its image; returns the exit code.
int render_scene(RenderCommand &c) {
    cli::SceneOptions &opts = c.scene;
    const auto load_start = std::chrono::steady_clock::now();
    std::shared_ptr<Scene> scene = cli::load_scene(opts);
    const double load_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - load_start).count();
    const auto &sensors = scene->sensors();
    if (opts.sensor < 0 || size_t(opts.sensor) >= sensors.size())
        FACET_THROW("-s {}: the scene has {} sensor{} (valid indices 0..{})", opts.sensor,
                    sensors.size(), sensors.size() == 1 ? "" : "s", int(sensors.size()) - 1);
    const Sensor &sensor = *sensors[size_t(opts.sensor)];
    const Film &film = sensor.film();

    std::string out = output_path(opts.scene, c.output, film);
    ImageWriteOptions wopts;
    wopts.ocio_config = c.ocio_config;
    wopts.display = c.display;
    wopts.view = c.view;
    wopts.looks = c.looks;
    const bool part = c.pass_count > 1 && c.pass_given; // raw sums follow
    check_output(out, wopts, *scene, sensor, opts.scene, part);

    RenderOptions ropts = render_options(c, film);
    std::atomic<bool> cancel{false};
    ropts.cancel = &cancel;
    const SampleRange range = sample_range(c, sensor, ropts);
    const std::string hash = scene_hash(opts, film);

    // From here on Ctrl-C, SIGTERM and SIGHUP stop the render and the partial image is written;
    // from the end of the render to the rename of the output, no signal is fatal (the write
    // finishes, or removes its temporary file), and facet exits 128 + the signal after it.
    install_interrupt_handler(&cancel);
    struct HandlerGuard {
        ~HandlerGuard() { uninstall_interrupt_handler(); }
    } handler_guard;
    if (!opts.quiet) print_start(c, sensor, range, ropts);
    cli::set_activity(fmt::format("rendering \"{}\" ({}x{} pixels, {} spp)", opts.scene,
                                  film.crop_size().x, film.crop_size().y, range.count));
    // The module that writes the output loads while the render runs, from its first pixels on.
    ropts.on_first_block = [out] { preload_image_writer(out); };
    RenderResult result = render(*scene, sensor, ropts);
    defer_interrupts();
    const bool signal_in_render = interrupt_signal() != 0;
    result.load_seconds = load_seconds;

    const Written written = write_image(c, sensor, result, hash, out, wopts);
    if (!opts.quiet) print_times(result, written.seconds, opts.verbose > 0);
    return report_end(result, out, signal_in_render, written.error, opts.quiet);
}

} // namespace

int render_main(int argc, char **argv) {
    RenderCommand c;
    CLI::App app("Render a Mitsuba 3 scene", "facet render");
    add_render_options(app, c);
    if (int code = cli::parse(app, argc, argv); code >= 0) return code;
    c.pass_given = app.count("--pass") > 0;
    if (app.count("--spp") > 0 && c.spp < 1)
        FACET_THROW("--spp {}: the number of samples per pixel must be at least 1", c.spp);
    cli::set_log_level(c.scene); // -q hides the note of a vectorised mode name
    c.mode = resolve_mode(c.mode);
    c.scene.mode = c.mode;

    // Several scenes render one after the other; the first error or signal ends the sequence.
    for (const std::string &scene_path : scenes_to_render(c)) {
        c.scene.scene = scene_path;
        if (const int code = render_scene(c); code != 0) return code;
    }
    return 0;
}
