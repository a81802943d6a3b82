// The `facet` command: picks the subcommand and turns every error into one line on stderr.

#include "commands.h"

#include <facet/logger.h>
#include <facet/plugin.h>

#include <CLI/CLI.hpp>
#include <OpenImageIO/oiioversion.h>
#include <embree3/rtcore_config.h>
#include <fmt/format.h>
#include <tbb/version.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <string>

namespace {

std::string g_activity; ///< see facet::cli::set_activity()

/// " while loading \"scene.xml\"", or nothing.
std::string while_activity() { return g_activity.empty() ? "" : " while " + g_activity; }

const char *USAGE = R"(facet: a physically based renderer for Mitsuba 3 scenes

Usage:
  facet render <scene.xml> [options]   render a scene (see `facet render --help`)
  facet <scene.xml> [options]          the same
  facet plugins [kind|name]            list the plugins, or print one plugin's parameters
  facet bench <scene.xml> [options]    samples/s, rays/s and Embree's share of the CPU
  facet merge parts... -o out.exr      merge the parts of a render split by --crop and --pass
  facet compare ours.exr ref_mean.exr ref_var_xyz.exr --spp N
                                       statistical comparison with a reference render
  facet chi2 bsdf|emitter|microfacet ...
                                       chi-square test of a plugin's sampling against its pdf
  facet new-plugin ...                 start a plugin of your own from the template
  facet colors                         the OpenColorIO displays, views and looks for 8-bit outputs
  facet info <scene.xml>               film size, spp, sensors, plugins (parses, does not load)

Run `facet <command> --help` for the options of a command; `facet --version` prints the
version.
)";

struct Command {
    const char *name;
    int (*run)(int, char **);
};

/// One line: a multi-line message (a list of unused properties, say) is joined with "; " (just
/// a space after a line that ends in ':', and list dashes dropped).
std::string one_line(const std::string &msg) {
    std::string out;
    bool pending_separator = false;
    for (size_t i = 0; i < msg.size(); ++i) {
        char c = msg[i];
        if (c == '\n' || c == '\r') {
            pending_separator = !out.empty();
            continue;
        }
        if (pending_separator) {
            if (c == ' ' || c == '\t') continue;
            if (c == '-' && i + 1 < msg.size() && msg[i + 1] == ' ') {
                ++i; // "  - item" list lines
                continue;
            }
            out += out.back() == ':' ? " " : "; ";
            pending_separator = false;
        }
        out += c;
    }
    return out;
}

int run(int argc, char **argv) {
    if (argc < 2) {
        std::fputs(USAGE, stderr);
        return 2;
    }
    std::string first = argv[1];
    if (first == "-h" || first == "--help" || first == "help") {
        std::fputs(USAGE, stdout);
        return 0;
    }
    if (first == "--version" || first == "-V") {
        std::printf("facet %s (Embree %s, OpenImageIO %s, oneTBB %d.%d)\n", FACET_VERSION,
                    RTC_VERSION_STRING, OIIO_VERSION_STRING, TBB_VERSION_MAJOR, TBB_VERSION_MINOR);
        return 0;
    }

    const Command commands[] = {
        {"render", render_main},   {"plugins", plugins_main}, {"bench", bench_main},
        {"compare", compare_main}, {"chi2", chi2_main},       {"new-plugin", new_plugin_main},
        {"merge", merge_main},     {"colors", colors_main},   {"info", info_main},
    };
    for (const Command &cmd : commands) {
        if (first == cmd.name) return cmd.run(argc - 1, argv + 1);
    }

    // `facet scene.xml ...` and `facet -D spp=4 scene.xml` are short for `facet render ...`.
    bool looks_like_scene = first.size() > 4 && first.compare(first.size() - 4, 4, ".xml") == 0;
    if (looks_like_scene || first[0] == '-') {
        argv[0] = const_cast<char *>("render");
        return render_main(argc, argv);
    }
    throw facet::Error(
        fmt::format("unknown command '{}' (expected render, plugins, bench, "
                    "merge, compare, chi2, new-plugin, colors, info or a scene file; see "
                    "facet --help)",
                    first));
}

} // namespace

namespace facet::cli {

void set_activity(const std::string &what) { g_activity = what; }

int parse(CLI::App &app, int argc, char **argv) {
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp &) {
        std::fputs(app.help().c_str(), stdout);
        return 0;
    } catch (const CLI::CallForAllHelp &) {
        std::fputs(app.help("", CLI::AppFormatMode::All).c_str(), stdout);
        return 0;
    } catch (const CLI::ParseError &e) {
        // A misspelt option: the nearest one the command has.
        std::vector<std::string> names;
        for (const CLI::Option *opt : app.get_options()) {
            for (const std::string &l : opt->get_lnames()) names.push_back("--" + l);
            for (const std::string &n : opt->get_snames()) names.push_back("-" + n);
        }
        std::string hint;
        for (int i = 1; i < argc && hint.empty(); ++i) {
            std::string arg = argv[i];
            if (arg.size() < 3 || arg.compare(0, 2, "--") != 0) continue;
            arg = arg.substr(0, arg.find('='));
            if (std::find(names.begin(), names.end(), arg) != names.end()) continue;
            std::string close = facet::closest_name(arg, names);
            if (!close.empty()) hint = fmt::format("; did you mean \"{}\"?", close);
        }
        throw facet::Error(fmt::format("{}{} (see {} --help)", e.what(), hint, app.get_name()));
    }
    return -1;
}

} // namespace facet::cli

/// A listing that did not reach its destination (a full disk, `facet colors > /dev/full`) is a
/// failure, not a success.
static int check_stdout(int code) {
    if (std::fflush(stdout) == 0 && !std::ferror(stdout)) return code;
    std::fprintf(stderr, "facet: error: cannot write to standard output: %s\n",
                 std::strerror(errno));
    return code != 0 ? code : 1;
}

int main(int argc, char **argv) {
    try {
        return check_stdout(run(argc, argv));
    } catch (const std::bad_alloc &) {
        std::fflush(stdout);
        std::fprintf(stderr, "facet: error: out of memory (std::bad_alloc)%s\n",
                     while_activity().c_str());
        return 1;
    } catch (const std::exception &e) {
        // facet::Error derives from std::exception; its what() carries the scene location.
        std::fflush(stdout);
        // A plugin's allocation failure arrives wrapped (located, naming the plugin).
        std::string msg = one_line(e.what());
        if (size_t at = msg.find("std::bad_alloc"); at != std::string::npos)
            msg.replace(at, 14, "out of memory (std::bad_alloc)" + while_activity());
        std::fprintf(stderr, "facet: error: %s\n", msg.c_str());
        return 1;
    } catch (...) {
        std::fprintf(stderr, "facet: error: unknown exception\n");
        return 1;
    }
}
