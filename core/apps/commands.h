#pragma once

#include <facet/xml.h>

#include <memory>
#include <string>
#include <vector>

namespace CLI {
class App;
}

/// Entry points of the `facet` subcommands. Each takes the arguments that follow the subcommand
/// name (argv[0] is the subcommand itself), returns the process exit code and lets facet::Error
/// and std::exception escape: main() turns them into one "facet: error: ..." line.
int render_main(int argc, char **argv);
int plugins_main(int argc, char **argv);
int bench_main(int argc, char **argv);
/// `facet bench --suite FILE` (bench_suite.cpp): bench_main() hands its arguments over.
int bench_suite_main(int argc, char **argv);
int compare_main(int argc, char **argv);
/// `facet merge` (merge_cmd.cpp): puts the parts of a split render back together.
int merge_main(int argc, char **argv);
/// `facet colors` (colors_cmd.cpp): the OpenColorIO displays, views and looks.
int colors_main(int argc, char **argv);
/// `facet info` (info_cmd.cpp): what a scene declares, from parsing it alone.
int info_main(int argc, char **argv);

/// `facet chi2` (chi2_cmd.cpp) and `facet new-plugin` (new_plugin_cmd.cpp).
int chi2_main(int argc, char **argv);
int new_plugin_main(int argc, char **argv);

namespace facet::cli {

/// Parses with CLI11. Returns -1 when the command should run; otherwise the exit code to return
/// (0 after --help). Parse errors are thrown as facet::Error, so they print as one line.
int parse(CLI::App &app, int argc, char **argv);

/// The options `render` and `bench` share: the scene and how to load it.
struct SceneOptions {
    std::string scene;
    std::vector<std::string> defines;     ///< -D key=value
    std::vector<std::string> plugin_dirs; ///< -a (';' separates several folders in one value)
    int threads = 0;                      ///< -t; 0 = all cores
    bool threads_given = false;           ///< -t was on the command line (values < 1 become 1)
    int sensor = 0;                       ///< -s
    int verbose = 0;                      ///< number of -v
    bool quiet = false;                   ///< -q
    bool lenient = false;                 ///< --lenient
    std::string mode;                     ///< the colour mode (-m, resolved); empty: the default
};

/// Adds -D, -a, -t, -s, -v, -q, --lenient and the scene argument to `app`.
void add_scene_options(CLI::App &app, SceneOptions &opts);

/// Applies -v/-q to the logger (load_scene() does too; a command calls it first when it logs
/// before loading).
void set_log_level(const SceneOptions &opts);

/// Adds -m/--mode, the colour mode (Mitsuba's `-m` variant names), to `app`; its value is
/// default_mode() unless given, for resolve_mode().
void add_mode_option(CLI::App &app, std::string &mode);

/// Applies -v/-q to the logger, -a to the plugin registry, fixes the thread count (warning for
/// -t < 1) and the Embree device, then loads the scene with the -D values.
std::shared_ptr<Scene> load_scene(SceneOptions &opts);

/// Names what the command is doing ("loading \"scene.xml\""): main() adds it to the error when
/// memory runs out, which std::bad_alloc itself does not say.
void set_activity(const std::string &what);

/// Threads a render will use: `threads` but at most the hardware threads, or all of those when
/// it is 0.
int effective_threads(int threads);

} // namespace facet::cli
