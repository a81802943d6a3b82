// `facet chi2 bsdf|emitter|sensor|microfacet ...`: the chi-square test of facet/chi2.h on any
// plugin.

#include "commands.h"

#include <facet/checked.h>
#include <facet/chi2.h>
#include <facet/logger.h>
#include <facet/mode.h>
#include <facet/plugin.h>
#include <facet/render.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace {

using namespace facet;

/// Options every subcommand shares.
struct CommonOptions {
    int res = 32;
    uint64_t samples = 1000000;
    uint32_t seed = 0;
    uint32_t tests = 1;
    double significance = 0.01;
    int ires = 7;
    bool adaptive = false, fixed = false;
    std::string out;
    std::vector<std::string> plugin_dirs;
    bool quiet = false;
};

void add_common(CLI::App &app, CommonOptions &o) {
    app.add_option("--res", o.res, "Cells along cos theta; phi gets twice as many (default 32)");
    app.add_option("--samples", o.samples, "Number of samples (default 1000000)");
    app.add_option("--seed", o.seed, "Seed; sample i uses a PCG32 seeded from tea_hash(i, seed)");
    app.add_option("--tests", o.tests,
                   "Number of tests run together: the level is Sidak-corrected (default 1)");
    app.add_option("--significance", o.significance,
                   "Family-wise significance level (default 0.01)");
    app.add_option("--ires", o.ires,
                   "Simpson points per axis and cell of the fixed rule (default 7)");
    app.add_flag("--adaptive", o.adaptive, "Integrate the pdf with adaptive Simpson (the default)");
    app.add_flag("--fixed", o.fixed,
                 "Integrate the pdf with the fixed Simpson rule on --ires points (faster, but "
                 "misses lobes narrower than its spacing)");
    app.add_option("--out", o.out,
                   "Write the heat map (PNG) and tables here, also when the test passes "
                   "(failures always go to ./chi2-failures)");
    app.add_option("-a", o.plugin_dirs,
                   "Add folders to the plugin search path (';' separates several)");
    app.add_flag("-q,--quiet", o.quiet, "Print only the verdict line");
}

std::vector<float> parse_floats(const std::string &text, size_t count, const char *what) {
    std::vector<float> values;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        try {
            size_t used = 0;
            values.push_back(std::stof(item, &used));
            if (item.find_first_not_of(" \t", used) != std::string::npos)
                throw std::invalid_argument("");
        } catch (const std::exception &) {
            FACET_THROW("{} \"{}\": expected {} comma-separated numbers", what, text, count);
        }
    }
    if (values.size() != count)
        FACET_THROW("{} \"{}\": expected {} comma-separated numbers", what, text, count);
    return values;
}

bool parse_bool(const std::string &text, const char *what) {
    if (text == "true" || text == "1" || text == "yes") return true;
    if (text == "false" || text == "0" || text == "no") return false;
    FACET_THROW("{} \"{}\": expected true or false", what, text);
}

void add_plugin_dirs(const std::vector<std::string> &values) {
    for (const std::string &value : values) {
        size_t start = 0;
        while (start <= value.size()) {
            size_t end = std::min(value.find(';', start), value.size());
            if (end > start)
                PluginRegistry::instance().add_search_dir(value.substr(start, end - start));
            start = end + 1;
        }
    }
}

/// A file name made of the test's words: "bsdf-roughconductor-1a2b3c4d".
std::string slug(const std::string &kind, const std::string &name, const std::string &everything) {
    uint32_t h = 2166136261u; // FNV-1a of the whole configuration
    for (unsigned char c : everything) h = (h ^ c) * 16777619u;
    std::string base = kind + "-" + name;
    for (char &c : base)
        if (!std::isalnum((unsigned char)c) && c != '-' && c != '_') c = '_';
    return fmt::format("{}-{:08x}", base.substr(0, 48), h);
}

/// Refuses, naming the option, a test whose tables would not fit in memory: before anything
/// is allocated, rather than as a bare "out of memory" (or a swapping machine) later.
void check_sizes(const CommonOptions &o) {
    if (o.samples == 0 || o.samples > uint64_t(UINT32_MAX))
        FACET_THROW("--samples {}: expected 1 to {} samples", o.samples, UINT32_MAX);
    if (o.res < 2) FACET_THROW("--res {}: expected at least 2 cells along cos theta", o.res);
    // Per cell: the observed and expected counts, the integral of the pdf with its checks, the
    // pooling order, three heat-map pixels of three colours, 64 bytes for the text table and
    // the image writer's copy, and one counter per thread.
    const size_t res = size_t(o.res) + 1, per_cell = 8 + 8 + 48 + 8 + 3 * 3 * 4 + 64;
    size_t cells, bytes;
    if (!checked_mul(res, 2 * res, cells) ||
        !checked_mul(size_t(4), size_t(hardware_threads()), bytes) ||
        !checked_add(bytes, per_cell, bytes))
        FACET_THROW("--res {}: too many cells", o.res);
    allocation_bytes(cells, bytes, fmt::format("--res {}", o.res),
                     "the cells of the chi-square tables (2 x res x res)");
}

/// Runs the test, prints the result and writes pictures when asked or on failure.
int run(const Chi2Adapter &adapter, const CommonOptions &o, const std::string &file_base) {
    check_sizes(o);
    // What an out-of-memory error names (main() adds it), should the estimate above fall short.
    cli::set_activity(
        fmt::format("running the chi-square test (--res {}, --samples {})", o.res, o.samples));
    Chi2Options opts;
    opts.res = o.res;
    opts.samples = o.samples;
    opts.seed = o.seed;
    opts.test_count = std::max(1u, o.tests);
    opts.significance = o.significance;
    opts.ires = o.ires;
    if (o.adaptive && o.fixed) FACET_THROW("give either --adaptive or --fixed");
    opts.adaptive = !o.fixed;
    if (!(o.significance > 0.0 && o.significance < 1.0))
        FACET_THROW("--significance {} must be in (0, 1)", o.significance);

    Chi2Result result = run_chi2(adapter, opts);
    if (o.quiet)
        fmt::print("chi2: {} ({}, p-value {:.6g})\n", result.passed ? "accepted" : "REJECTED",
                   result.description, result.p_value);
    else
        fmt::print("{}", result.summary());

    std::string dir = !o.out.empty() ? o.out : (result.passed ? std::string() : "chi2-failures");
    if (!dir.empty()) {
        fs::create_directories(dir);
        std::string base = (fs::path(dir) / file_base).string();
        write_chi2_heatmap(base + ".png", result);
        write_chi2_tables(base + ".txt", result);
        fmt::print("  wrote {}.png (observed | expected | (o-e)/sqrt(e)) and {}.txt\n", base, base);
    }
    std::fflush(stdout);
    return result.passed ? 0 : 1;
}

/// XML text given on the command line, or the contents of the file it names.
std::string read_xml_argument(const std::string &text) {
    if (!text.empty() && text[0] == '<') return text;
    std::ifstream in(text);
    if (!in) FACET_THROW("cannot read \"{}\"", text);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::string join_args(int argc, char **argv) {
    std::string s;
    for (int i = 0; i < argc; ++i) s += std::string(argv[i]) + "\n";
    return s;
}

// -- facet chi2 bsdf ------------------------------------------------------------------------------

/// -m, the colour mode the plugin is built in (Mitsuba's variant names, as `facet render -m`):
/// what a BSDF samples can depend on its colours (a plastic's lobe weights), so each mode is a
/// test of its own. (`--mode` of `chi2 bsdf` is the transport mode.)
void add_colour_mode(CLI::App &app, std::string &mode) {
    mode = default_mode();
    app.add_option("-m,--colour-mode", mode,
                   fmt::format("Colour mode the plugin is built in: {} (default {})",
                               fmt::join(modes(), ", "), default_mode()));
}

struct BsdfCommand {
    CommonOptions common;
    std::string name, xml, wi_text, mode = "radiance", colour_mode;
    std::vector<std::string> params;
    float theta = 30.f, phi = 0.f;
    int component = -1;
    CLI::Option *theta_opt = nullptr;
};

CLI::App *add_bsdf_command(CLI::App &app, BsdfCommand &c) {
    CLI::App *bsdf =
        app.add_subcommand("bsdf", "Test a BSDF: facet chi2 bsdf <name> [key=value ...]");
    bsdf->add_option("name", c.name, "BSDF plugin name");
    bsdf->add_option("params", c.params,
                     "Parameters key=value (type inferred: number -> float, true/false -> boolean, "
                     "r,g,b -> rgb, else string) or type:key=value (e.g. integer:n=3)");
    bsdf->add_option("--xml", c.xml, "The BSDF as XML text or an .xml file (instead of a name)");
    bsdf->add_option("--wi", c.wi_text, "Incident direction x,y,z in the local frame (normalised)");
    c.theta_opt =
        bsdf->add_option("--theta", c.theta, "Incident polar angle in degrees (default 30)");
    bsdf->add_option("--phi", c.phi, "Incident azimuth in degrees (default 0)");
    bsdf->add_option("--component", c.component, "Test only this component (lobe) index");
    bsdf->add_option("--mode", c.mode, "Transport mode: radiance (default) or importance");
    add_colour_mode(*bsdf, c.colour_mode);
    add_common(*bsdf, c.common);
    return bsdf;
}

int run_bsdf(BsdfCommand &c, const std::string &everything) {
    add_plugin_dirs(c.common.plugin_dirs);
    if (!c.wi_text.empty() && c.theta_opt->count() > 0)
        FACET_THROW("give the incident direction either with --wi or with --theta/--phi");
    Vector3f wi;
    if (!c.wi_text.empty()) {
        auto v = parse_floats(c.wi_text, 3, "--wi");
        wi = Vector3f(v[0], v[1], v[2]);
    } else {
        wi = direction_from_angles(c.theta, c.phi);
    }
    BSDFContext ctx;
    if (c.mode == "importance")
        ctx.mode = TransportMode::Importance;
    else if (c.mode != "radiance")
        FACET_THROW("--mode \"{}\": expected radiance or importance", c.mode);
    if (c.component >= 0) ctx.component = uint32_t(c.component);

    std::string text;
    if (!c.xml.empty() || (!c.name.empty() && c.name[0] == '<')) {
        if (!c.params.empty()) FACET_THROW("key=value parameters cannot be added to --xml");
        text = read_xml_argument(c.xml.empty() ? c.name : c.xml);
        if (c.name.empty() || c.name[0] == '<') c.name = "xml";
    } else {
        if (c.name.empty()) FACET_THROW("name the BSDF plugin to test (or give --xml)");
        text = chi2_object_xml(ObjectType::BSDF, c.name, c.params);
    }
    BSDFAdapter adapter(text, wi, ctx, resolve_mode(c.colour_mode));
    return run(adapter, c.common, slug("bsdf", c.name, everything));
}

// -- facet chi2 emitter ---------------------------------------------------------------------------

struct EmitterCommand {
    CommonOptions common;
    std::string name, xml, ref_text = "0.25,-0.5,1.5", shape = "rectangle", colour_mode, side_text;
    std::vector<std::string> params;
    bool emission = false, mis = false;
};

CLI::App *add_emitter_command(CLI::App &app, EmitterCommand &c) {
    CLI::App *emitter = app.add_subcommand(
        "emitter",
        "Test an emitter's direction sampling: facet chi2 emitter <name> [key=value ...]");
    emitter->add_option("name", c.name, "Emitter plugin name");
    emitter->add_option("params", c.params, "Parameters, as for bsdf");
    emitter->add_option("--xml", c.xml,
                        "The emitter as XML text or an .xml file, an <emitter> or a whole <scene> "
                        "(its first emitter is tested), instead of a name");
    emitter->add_flag("--emission", c.emission,
                      "Test the directions of emitted rays (sample_ray against "
                      "pdf_ray_direction; emitters with one origin, e.g. spot) instead of "
                      "direction sampling from --ref");
    emitter->add_flag("--mis", c.mis,
                      "Test the light samples an integrator weights by MIS against BSDF samples "
                      "(sample_direction_mis against pdf_direction_mis) instead of those that "
                      "stand alone");
    emitter->add_option("--side", c.side_text,
                        "With --mis: the side x,y,z the light samples are told no light counts "
                        "beyond (directions d with dot(d, side) <= 0; a reflecting BSDF's side)");
    emitter->add_option("--ref", c.ref_text, "Reference point x,y,z (default 0.25,-0.5,1.5)");
    emitter->add_option(
        "--shape", c.shape,
        "Shape an area emitter sits on (default rectangle: 2x2 at z = 0, facing +z)");
    add_colour_mode(*emitter, c.colour_mode);
    add_common(*emitter, c.common);
    return emitter;
}

int run_emitter(EmitterCommand &c, const std::string &everything) {
    add_plugin_dirs(c.common.plugin_dirs);
    auto r = parse_floats(c.ref_text, 3, "--ref");
    std::string scene;
    if (!c.xml.empty()) {
        if (!c.name.empty() || !c.params.empty())
            FACET_THROW("give the emitter either by name and key=value parameters or --xml");
        scene = read_xml_argument(c.xml);
        if (scene.find("<scene") == std::string::npos)
            scene = "<scene version=\"3.0.0\">" + scene + "</scene>";
        c.name = "xml";
    } else {
        if (c.name.empty()) FACET_THROW("name the emitter plugin to test (or give --xml)");
        scene = EmitterAdapter::scene_xml(c.name, c.params, c.shape);
    }
    if (c.emission) {
        if (c.mis) FACET_THROW("--mis tests light samples, --emission emitted rays: give one");
        EmissionAdapter adapter(scene, 0, resolve_mode(c.colour_mode));
        return run(adapter, c.common, slug("emission", c.name, everything));
    }
    EmitterAdapter adapter(scene, Point3f(r[0], r[1], r[2]), 0, resolve_mode(c.colour_mode));
    if (c.mis) adapter.set_light_sampling(LightSampling::MIS);
    if (!c.side_text.empty()) {
        if (!c.mis) FACET_THROW("--side is the side of the light samples --mis tests: give both");
        auto s = parse_floats(c.side_text, 3, "--side");
        if (!(s[0] * s[0] + s[1] * s[1] + s[2] * s[2] > 0.f))
            FACET_THROW("--side must not be the zero vector");
        adapter.set_side(Vector3f(s[0], s[1], s[2]));
    }
    return run(adapter, c.common, slug("emitter", c.name, everything));
}

// -- facet chi2 sensor ----------------------------------------------------------------------------

struct SensorCommand {
    CommonOptions common;
    std::string name, xml, ref, ref_local, aperture_text = "0.5,0.5", film_text;
    std::vector<std::string> params;
};

CLI::App *add_sensor_command(CLI::App &app, SensorCommand &c) {
    CLI::App *sensor = app.add_subcommand(
        "sensor", "Test a sensor's importance (light tracing): facet chi2 sensor <name> "
                  "[key=value ...]; its camera rays, or its aperture seen from --ref");
    sensor->add_option("name", c.name, "Sensor plugin name");
    sensor->add_option("params", c.params, "Parameters, as for bsdf");
    sensor->add_option("--xml", c.xml,
                       "The sensor as XML text or an .xml file, a <sensor> or a whole <scene> "
                       "(its first sensor is tested), instead of a name");
    sensor->add_option("--film", c.film_text,
                       "Film size width,height in pixels for a sensor given by name (default: "
                       "the plugin's default film)");
    sensor->add_option("--aperture", c.aperture_text,
                       "Aperture sample u,v in [0,1) of the camera rays (default 0.5,0.5: the "
                       "lens centre)");
    sensor->add_option("--ref", c.ref,
                       "Test the aperture sampling of sample_direction() from this world point "
                       "x,y,z against pdf_direction() (thin lens), instead of the camera rays");
    sensor->add_option("--ref-local", c.ref_local,
                       "As --ref, with the point in the camera's frame (before to_world)");
    add_common(*sensor, c.common);
    return sensor;
}

/// The sensor's XML (a <scene> around it), from --xml or from its name and parameters.
std::string sensor_text(SensorCommand &c) {
    if (!c.xml.empty()) {
        if (!c.name.empty() || !c.params.empty() || !c.film_text.empty())
            FACET_THROW("give the sensor either by name and key=value parameters (and "
                        "--film) or --xml");
        std::string text = read_xml_argument(c.xml);
        if (text.find("<scene") == std::string::npos && text.find("version=") == std::string::npos)
            text = "<scene version=\"3.0.0\">" + text + "</scene>";
        c.name = "xml";
        return text;
    }
    if (c.name.empty()) FACET_THROW("name the sensor plugin to test (or give --xml)");
    Point2i film(0, 0);
    if (!c.film_text.empty()) {
        auto f = parse_floats(c.film_text, 2, "--film");
        if (!(f[0] >= 1.f && f[1] >= 1.f) || f[0] != std::floor(f[0]) || f[1] != std::floor(f[1]))
            FACET_THROW("--film \"{}\": expected two positive whole numbers", c.film_text);
        film = Point2i(int(f[0]), int(f[1]));
    }
    return SensorAdapter::sensor_xml(c.name, c.params, film);
}

int run_sensor(SensorCommand &c, const std::string &everything) {
    add_plugin_dirs(c.common.plugin_dirs);
    std::shared_ptr<Sensor> camera = SensorAdapter::load(sensor_text(c));
    if (!c.ref.empty() && !c.ref_local.empty())
        FACET_THROW("give the reference point either with --ref or with --ref-local");
    if (!c.ref.empty() || !c.ref_local.empty()) {
        auto r = parse_floats(c.ref.empty() ? c.ref_local : c.ref, 3,
                              c.ref.empty() ? "--ref-local" : "--ref");
        Point3f ref(r[0], r[1], r[2]);
        if (!c.ref_local.empty()) ref = camera->to_world().apply_point(ref);
        SensorAdapter adapter(camera, ref);
        return run(adapter, c.common, slug("sensor", c.name, everything));
    }
    auto a = parse_floats(c.aperture_text, 2, "--aperture");
    SensorAdapter adapter(camera, Point2f(a[0], a[1]));
    return run(adapter, c.common, slug("sensor", c.name, everything));
}

// -- facet chi2 microfacet ------------------------------------------------------------------------

struct MicrofacetCommand {
    CommonOptions common;
    std::string distribution, visible_text = "true";
    float alpha = 0.1f, alpha_v = -1.f, theta = 30.f, phi = 0.f;
};

CLI::App *add_microfacet_command(CLI::App &app, MicrofacetCommand &c) {
    CLI::App *micro = app.add_subcommand(
        "microfacet",
        "Test microfacet normal sampling: facet chi2 microfacet beckmann|ggx --alpha a");
    micro->add_option("type", c.distribution, "beckmann or ggx")->required();
    micro->add_option("--alpha", c.alpha,
                      "Roughness (alpha_u when --alpha-v is given; default 0.1)");
    micro->add_option("--alpha-v", c.alpha_v, "Roughness along v (default: --alpha)");
    micro->add_option("--visible", c.visible_text,
                      "Sample visible normals: true (default) or false");
    micro->add_option("--theta", c.theta, "Incident polar angle in degrees (default 30)");
    micro->add_option("--phi", c.phi, "Incident azimuth in degrees (default 0)");
    add_common(*micro, c.common);
    return micro;
}

int run_microfacet(const MicrofacetCommand &c, const std::string &everything) {
    add_plugin_dirs(c.common.plugin_dirs);
    MicrofacetAdapter adapter(c.distribution, c.alpha, c.alpha_v > 0.f ? c.alpha_v : c.alpha,
                              parse_bool(c.visible_text, "--visible"),
                              direction_from_angles(c.theta, c.phi));
    return run(adapter, c.common, slug("microfacet", c.distribution, everything));
}

} // namespace

int chi2_main(int argc, char **argv) {
    CLI::App app("Chi-square test of a plugin's sampling routine against its pdf.\n"
                 "Prints the statistic, dof, p-value and verdict; exits with 1 on rejection.",
                 "facet chi2");
    app.require_subcommand(1);
    BsdfCommand bsdf;
    EmitterCommand emitter;
    SensorCommand sensor;
    MicrofacetCommand microfacet;
    const CLI::App *bsdf_app = add_bsdf_command(app, bsdf);
    const CLI::App *emitter_app = add_emitter_command(app, emitter);
    const CLI::App *sensor_app = add_sensor_command(app, sensor);
    add_microfacet_command(app, microfacet);
    if (int code = cli::parse(app, argc, argv); code >= 0) return code;

    const std::string everything = join_args(argc, argv);
    if (bsdf_app->parsed()) return run_bsdf(bsdf, everything);
    if (emitter_app->parsed()) return run_emitter(emitter, everything);
    if (sensor_app->parsed()) return run_sensor(sensor, everything);
    return run_microfacet(microfacet, everything);
}
