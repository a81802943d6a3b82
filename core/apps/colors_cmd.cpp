// `facet colors`: the OpenColorIO displays, views and looks 8-bit outputs can use.

#include "commands.h"

#include <facet/image.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <string>

int colors_main(int argc, char **argv) {
    std::string ocio_config;
    CLI::App app("List the OpenColorIO displays, views and looks for 8-bit outputs (the "
                 "choices of `facet render --display/--view/--look`)",
                 "facet colors");
    app.add_option("--ocio-config", ocio_config,
                   "OpenColorIO config (default: $OCIO, else facet's own)");
    if (int code = facet::cli::parse(app, argc, argv); code >= 0) return code;

    const facet::OcioDisplays cfg = facet::ocio_displays(ocio_config);
    fmt::print("OpenColorIO config: {}\n", cfg.config);
    if (!cfg.description.empty()) fmt::print("  {}\n", cfg.description);
    fmt::print("\nDisplays and their views (* = default):\n");
    for (const auto &d : cfg.displays) {
        fmt::print("  {}{}\n", d.name, d.name == cfg.default_display ? " *" : "");
        for (const auto &v : d.views)
            fmt::print("      {}{}\n", v, v == d.default_view ? " *" : "");
    }
    fmt::print("\nLooks:\n");
    if (cfg.looks.empty()) fmt::print("  (none)\n");
    for (const auto &l : cfg.looks) fmt::print("  {}\n", l);
    return 0;
}
