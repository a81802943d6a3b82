// `facet info`: what a scene file declares (film size, samples per pixel, sensors, plugins),
// read by parsing it alone: no plugin is created, no mesh read, no BVH built.

#include "commands.h"

#include <facet/logger.h>
#include <facet/mode.h>
#include <facet/xml.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <filesystem>
#include <string>
#include <vector>

namespace fs = std::filesystem;

int info_main(int argc, char **argv) {
    std::string scene, mode;
    std::vector<std::string> defines, dirs;
    int sensor = 0;
    bool film_size = false, lenient = false;
    CLI::App app("Print what a scene declares: film size, samples per pixel, sensors, plugins "
                 "and mode (the scene is parsed, not loaded)",
                 "facet info");
    app.add_option("scene", scene, "Scene file (Mitsuba 3 XML)")->required();
    app.add_option("-D,--define", defines, "Set a scene parameter: -D key=value (repeatable)")
        ->take_all();
    app.add_option("-a", dirs, "Add folders to the file search path (';' separates several)");
    app.add_option("-s,--sensor", sensor, "The sensor --film-size speaks of (default 0)");
    app.add_flag("--film-size", film_size,
                 "Print only \"WIDTH HEIGHT\" of the sensor's film (for scripts)");
    app.add_flag("--lenient", lenient, "Unused -D values are warnings, not errors");
    facet::cli::add_mode_option(app, mode);
    if (int code = facet::cli::parse(app, argc, argv); code >= 0) return code;
    mode = facet::resolve_mode(mode);

    facet::LoadOptions load;
    load.lenient = lenient;
    load.mode = mode;
    for (const std::string &value : dirs) {
        size_t start = 0;
        while (start <= value.size()) {
            size_t end = value.find(';', start);
            if (end == std::string::npos) end = value.size();
            if (end > start) load.search_path.push_back(value.substr(start, end - start));
            start = end + 1;
        }
    }
    for (const std::string &define : defines) {
        size_t eq = define.find('=');
        if (eq == std::string::npos) FACET_THROW("-D expects key=value, got \"{}\"", define);
        if (eq == 0) FACET_THROW("-D \"{}\" has no parameter name before '='", define);
        load.params[define.substr(0, eq)] = define.substr(eq + 1);
    }
    std::error_code exists_error; // e.g. a name over NAME_MAX
    if (!fs::exists(scene, exists_error))
        FACET_THROW("scene file \"{}\" {}", scene,
                    exists_error ? exists_error.message() : std::string("does not exist"));
    const facet::SceneInfo info = facet::scene_info(scene, load);
    if (sensor < 0 || size_t(sensor) >= info.sensors.size())
        FACET_THROW("sensor {}: the scene has {} sensor{} (valid indices 0..{})", sensor,
                    info.sensors.size(), info.sensors.size() == 1 ? "" : "s",
                    int(info.sensors.size()) - 1);
    const auto &s = info.sensors[size_t(sensor)];
    if (film_size) {
        fmt::print("{} {}\n", s.width, s.height);
        return 0;
    }
    fmt::print("scene: {}\n", scene);
    fmt::print("mode: {}\n", mode);
    fmt::print("film: {} x {} ({}, sensor {})\n", s.width, s.height, s.film, sensor);
    fmt::print("spp: {} ({})\n", s.spp, s.sampler);
    fmt::print("integrator: {}\n", info.integrator);
    fmt::print("sensors: {}\n", info.sensors.size());
    for (size_t i = 0; i < info.sensors.size(); ++i) {
        const auto &si = info.sensors[i];
        fmt::print("  {}: {}, {} {} x {}, {} {} spp\n", i, si.plugin, si.film, si.width, si.height,
                   si.sampler, si.spp);
    }
    fmt::print("plugins:\n");
    for (const auto &[kind, names] : info.plugins) {
        std::string list;
        for (const std::string &n : names) list += (list.empty() ? "" : ", ") + n;
        fmt::print("  {}: {}\n", kind, list);
    }
    return 0;
}
