// `facet bench --suite FILE`: the per-scene bench of every scene a suite file lists, one table.
//
// Each scene is benched by the facet executable itself in a child process (`facet bench <scene>
// --machine ...`), so that a scene's peak memory (the child's ru_maxrss, from wait4()) is its own
// and a scene that fails, even by crashing, does not stop the others. The child's figures are
// read from its "machine:" line.
//
// With --references DIR, each scene is also measured at equal error: DIR/<name>.exr is a render of
// the scene at many samples per pixel (rendered first, by `facet render` in a child, when it is
// missing, and kept for later runs), the child bench gives its render's RMSE against it, and the
// table prints the CPU time the render would need to reach an RMSE of 0.01 (RMSE² · CPU-s · 10⁴,
// as the error of an unbiased estimator falls with 1/√time). Two builds' figures then compare
// their estimators as well as their speed: one that reaches the same error sooner is faster even
// if each sample costs more. The reference's own error adds about spp/reference-spp to RMSE²
// (1/64 at the defaults below), the same for both builds.

#include "commands.h"

#include <facet/logger.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

namespace {

namespace fs = std::filesystem;

/// One line of a suite file: `name | scene file | -D key=value ...`.
struct SuiteEntry {
    std::string name;
    std::string scene;                ///< resolved against the suite's folder or --root
    std::vector<std::string> defines; ///< key=value
    std::string spp;                  ///< the value of -D spp, if given
};

std::string trim(const std::string &s) {
    size_t b = s.find_first_not_of(" \t\r");
    if (b == std::string::npos) return {};
    size_t e = s.find_last_not_of(" \t\r");
    return s.substr(b, e - b + 1);
}

/// Reads the suite file: `#` starts a comment line, blank lines are skipped; scene paths are
/// relative to `root`.
std::vector<SuiteEntry> read_suite(const std::string &file, const fs::path &root) {
    std::ifstream in(file);
    if (!in) FACET_THROW("--suite {}: cannot open it ({})", file, std::strerror(errno));
    std::vector<SuiteEntry> entries;
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        line = trim(line);
        if (line.empty() || line[0] == '#') continue;
        std::vector<std::string> fields;
        std::stringstream ss(line);
        for (std::string field; std::getline(ss, field, '|');) fields.push_back(trim(field));
        if (fields.size() < 2 || fields.size() > 3 || fields[0].empty() || fields[1].empty())
            FACET_THROW("{}:{}: expected `name | scene file | -D key=value ...`, got \"{}\"", file,
                        number, line);
        SuiteEntry e;
        e.name = fields[0];
        fs::path scene(fields[1]);
        e.scene = (scene.is_absolute() ? scene : root / scene).lexically_normal().string();
        std::stringstream args(fields.size() == 3 ? fields[2] : std::string());
        for (std::string arg; args >> arg;) {
            std::string define;
            if (arg == "-D") {
                if (!(args >> define)) FACET_THROW("{}:{}: -D without key=value", file, number);
            } else if (arg.rfind("-D", 0) == 0) {
                define = arg.substr(2);
            } else {
                FACET_THROW("{}:{}: \"{}\": only -D key=value arguments are allowed", file, number,
                            arg);
            }
            size_t eq = define.find('=');
            if (eq == 0 || eq == std::string::npos)
                FACET_THROW("{}:{}: -D {}: expected key=value", file, number, define);
            if (define.substr(0, eq) == "spp") e.spp = define.substr(eq + 1);
            e.defines.push_back(define);
        }
        for (const SuiteEntry &other : entries)
            if (other.name == e.name) FACET_THROW("{}:{}: a second \"{}\"", file, number, e.name);
        entries.push_back(std::move(e));
    }
    return entries;
}

/// What one child run gave: its output, how it ended and its peak memory.
struct ChildRun {
    std::string output; ///< stdout and stderr together
    int status = 0;     ///< from wait4()
    long maxrss_kib = 0;
};

/// Runs the facet executable with `args` (args[0] is the program name) and waits for it.
ChildRun run_child(const std::vector<std::string> &args) {
    int fds[2];
    if (pipe(fds) != 0) FACET_THROW("pipe: {}", std::strerror(errno));
    std::vector<char *> argv;
    for (const std::string &a : args) argv.push_back(const_cast<char *>(a.c_str()));
    argv.push_back(nullptr);
    std::fflush(stdout);
    std::fflush(stderr);
    pid_t pid = fork();
    if (pid < 0) FACET_THROW("fork: {}", std::strerror(errno));
    if (pid == 0) {
        close(fds[0]);
        dup2(fds[1], STDOUT_FILENO);
        dup2(fds[1], STDERR_FILENO);
        close(fds[1]);
        execv("/proc/self/exe", argv.data());
        std::string msg = fmt::format("facet: error: cannot run facet: {}\n", std::strerror(errno));
        ssize_t ignored = write(STDERR_FILENO, msg.data(), msg.size());
        (void)ignored;
        _exit(127);
    }
    close(fds[1]);
    ChildRun run;
    char buffer[4096];
    for (;;) {
        ssize_t n = read(fds[0], buffer, sizeof(buffer));
        if (n > 0)
            run.output.append(buffer, size_t(n));
        else if (n == 0 || errno != EINTR)
            break;
    }
    close(fds[0]);
    rusage usage{};
    while (wait4(pid, &run.status, 0, &usage) < 0)
        if (errno != EINTR) FACET_THROW("wait4: {}", std::strerror(errno));
    run.maxrss_kib = usage.ru_maxrss;
    return run;
}

/// The figures of one run of a scene, or its error.
struct Figures {
    double ns_per_sample = 0.0, rays_per_sample = 0.0, embree_share = -1.0, peak_mib = 0.0;
    double equal_error_seconds = -1.0; ///< CPU-s to an RMSE of 0.01; -1 without a reference
    std::string error;
};

/// The key=value pairs of the child's "machine:" line (empty when there is none).
std::map<std::string, std::string> machine_values(const std::string &output) {
    std::map<std::string, std::string> values;
    std::stringstream ss(output);
    for (std::string line; std::getline(ss, line);) {
        if (line.rfind("machine: ", 0) != 0) continue;
        std::stringstream pairs(line.substr(9));
        for (std::string pair; pairs >> pair;)
            if (size_t eq = pair.find('='); eq != std::string::npos)
                values[pair.substr(0, eq)] = pair.substr(eq + 1);
    }
    return values;
}

/// Why the child failed: its "facet: error:" line, else its last line and how it ended.
std::string child_error(const ChildRun &run) {
    std::string error, last;
    std::stringstream ss(run.output);
    for (std::string line; std::getline(ss, line);) {
        if (line.rfind("facet: error: ", 0) == 0) error = line.substr(14);
        if (!trim(line).empty()) last = trim(line);
    }
    if (!error.empty()) return error;
    std::string how = WIFSIGNALED(run.status)
                          ? fmt::format("killed by signal {} ({})", WTERMSIG(run.status),
                                        strsignal(WTERMSIG(run.status)))
                          : fmt::format("exit status {}", WEXITSTATUS(run.status));
    return last.empty() ? how : fmt::format("{} ({})", how, last);
}

/// The scene's arguments for a child `facet` command: its -D defines, and -t when given.
void add_scene_arguments(std::vector<std::string> &args, const SuiteEntry &e, int threads,
                         bool threads_given) {
    for (const std::string &d : e.defines) {
        args.push_back("-D");
        args.push_back(d);
    }
    if (threads_given) {
        args.push_back("-t");
        args.push_back(std::to_string(threads));
    }
}

/// Renders the reference `path` of `e` at `spp` in a child `facet render`; returns its error
/// ("" when it rendered).
std::string render_reference(const SuiteEntry &e, const std::string &path, int spp, int threads,
                             bool threads_given) {
    std::vector<std::string> args = {"facet", "render", e.scene, "-o", path, "-q"};
    add_scene_arguments(args, e, threads, threads_given);
    args.push_back("--spp");
    args.push_back(std::to_string(spp));
    fmt::print("reference {}: rendering {} at {} spp\n", e.name, path, spp);
    std::fflush(stdout);
    const ChildRun run = run_child(args);
    if (!WIFEXITED(run.status) || WEXITSTATUS(run.status) != 0)
        return "reference: " + child_error(run);
    return {};
}

Figures bench_once(const SuiteEntry &e, int threads, bool threads_given,
                   const std::string &reference) {
    std::vector<std::string> args = {"facet", "bench", e.scene, "--machine"};
    if (!reference.empty()) {
        args.insert(args.end(), {"--reference", reference, "--rounds", "1"});
    }
    add_scene_arguments(args, e, threads, threads_given);
    if (!e.spp.empty()) {
        args.push_back("--spp");
        args.push_back(e.spp);
    }
    const ChildRun run = run_child(args);
    Figures f;
    f.peak_mib = double(run.maxrss_kib) / 1024.0;
    const bool ok = WIFEXITED(run.status) && WEXITSTATUS(run.status) == 0;
    const auto values = machine_values(run.output);
    if (!ok || values.count("cpu_ns_per_sample") == 0 || values.count("rays_per_sample") == 0) {
        f.error = ok ? std::string("no machine: line in the bench's output") : child_error(run);
        return f;
    }
    try {
        f.ns_per_sample = std::stod(values.at("cpu_ns_per_sample"));
        f.rays_per_sample = std::stod(values.at("rays_per_sample"));
        auto share = values.find("embree_share");
        if (share != values.end() && share->second != "-")
            f.embree_share = std::stod(share->second);
        if (!reference.empty()) {
            const double rmse = std::stod(values.at("rmse"));
            f.equal_error_seconds = rmse * rmse * std::stod(values.at("cpu_seconds")) * 1e4;
        }
    } catch (const std::exception &) {
        f.error = "unreadable machine: line in the bench's output";
    }
    return f;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// The medians of the runs, figure by figure (the first error if a run failed).
Figures medians(const std::vector<Figures> &runs) {
    Figures m;
    std::vector<double> ns, rays, share, mib, equal;
    for (const Figures &f : runs) {
        if (!f.error.empty()) return f;
        ns.push_back(f.ns_per_sample);
        rays.push_back(f.rays_per_sample);
        mib.push_back(f.peak_mib);
        if (f.embree_share >= 0.0) share.push_back(f.embree_share);
        if (f.equal_error_seconds >= 0.0) equal.push_back(f.equal_error_seconds);
    }
    m.ns_per_sample = median(ns);
    m.rays_per_sample = median(rays);
    m.peak_mib = median(mib);
    m.embree_share = share.empty() ? -1.0 : median(share);
    m.equal_error_seconds = equal.empty() ? -1.0 : median(equal);
    return m;
}

} // namespace

int bench_suite_main(int argc, char **argv) {
    std::string suite, root, references;
    int runs = 1, threads = 0, reference_spp = 1024;
    CLI::App app("Bench every scene of a suite file, each in a process of its own, and print one "
                 "table: CPU-ns per camera sample (pixel sample), rays per sample, Embree's share "
                 "of the CPU time and the process's peak memory; with --runs N, the medians of N "
                 "runs. Each line of FILE is `name | scene file | -D key=value ...` (# starts a "
                 "comment line); -D spp=N is also the bench's --spp. With --references DIR, "
                 "also the CPU-s each render would need to reach an RMSE of 0.01 against "
                 "DIR/<name>.exr (rendered at --reference-spp when missing)",
                 "facet bench --suite");
    app.add_option("--suite", suite, "The suite file")->required();
    app.add_option("--runs", runs, "Runs of each scene (default 1); the table has their medians")
        ->check(CLI::Range(1, 100));
    CLI::Option *threads_opt =
        app.add_option("-t,--threads", threads, "Render threads (default: all cores)");
    app.add_option("--root", root,
                   "Folder the scene paths are relative to (default: the suite file's)");
    app.add_option("--references", references,
                   "Folder of the equal-error references, DIR/<name>.exr: a missing one is "
                   "rendered first and kept");
    app.add_option("--reference-spp", reference_spp,
                   "Samples per pixel of a reference rendered by --references (default 1024)")
        ->check(CLI::PositiveNumber);
    if (int code = facet::cli::parse(app, argc, argv); code >= 0) return code;

    const fs::path base = root.empty() ? fs::path(suite).parent_path() : fs::path(root);
    const std::vector<SuiteEntry> entries = read_suite(suite, base);
    if (entries.empty()) FACET_THROW("--suite {}: no scene in it", suite);

    // The references first, so that the table is printed in one piece. A scene whose reference
    // fails prints that error in its row, as a scene that fails its bench does.
    std::vector<std::string> reference_of(entries.size()), reference_error(entries.size());
    if (!references.empty()) {
        std::error_code ec;
        fs::create_directories(references, ec);
        if (!fs::is_directory(references, ec))
            FACET_THROW("--references {}: not a folder and cannot be made one", references);
        for (size_t i = 0; i < entries.size(); ++i) {
            reference_of[i] = (fs::path(references) / (entries[i].name + ".exr")).string();
            if (!fs::exists(reference_of[i], ec))
                reference_error[i] = render_reference(entries[i], reference_of[i], reference_spp,
                                                      threads, threads_opt->count() > 0);
        }
    }

    size_t width = 5;
    for (const SuiteEntry &e : entries) width = std::max(width, e.name.size());
    fmt::print("suite {}: {} scene{}, {} run{} each{}, {}\n", suite, entries.size(),
               entries.size() == 1 ? "" : "s", runs, runs == 1 ? "" : "s",
               runs == 1 ? "" : " (medians)",
               threads_opt->count()
                   ? fmt::format("{} thread{}", std::max(threads, 1), threads > 1 ? "s" : "")
                   : std::string("all cores"));
    fmt::print("{:<{}}  {:>14}  {:>11}  {:>8}  {:>8}{}\n", "scene", width, "CPU-ns/sample",
               "rays/sample", "Embree %", "peak MiB",
               references.empty() ? "" : fmt::format("  {:>13}", "s to RMSE .01"));
    int failed = 0;
    for (size_t i = 0; i < entries.size(); ++i) {
        const SuiteEntry &e = entries[i];
        std::vector<Figures> all;
        if (!reference_error[i].empty()) {
            all.emplace_back();
            all.back().error = reference_error[i];
        }
        for (int r = 0; r < runs && reference_error[i].empty(); ++r) {
            all.push_back(bench_once(e, threads, threads_opt->count() > 0, reference_of[i]));
            if (!all.back().error.empty()) break;
        }
        const Figures m = medians(all);
        if (!m.error.empty()) {
            ++failed;
            fmt::print("{:<{}}  error: {}\n", e.name, width, m.error);
        } else {
            fmt::print("{:<{}}  {:>14.1f}  {:>11.2f}  {:>8}  {:>8.1f}{}\n", e.name, width,
                       m.ns_per_sample, m.rays_per_sample,
                       m.embree_share < 0.0 ? std::string("-")
                                            : fmt::format("{:.1f}", 100.0 * m.embree_share),
                       m.peak_mib,
                       m.equal_error_seconds < 0.0
                           ? std::string()
                           : fmt::format("  {:>13.4g}", m.equal_error_seconds));
        }
        std::fflush(stdout);
    }
    if (failed) {
        fmt::print(stderr, "facet: error: {} of {} scene{} failed\n", failed, entries.size(),
                   entries.size() == 1 ? "" : "s");
        return 1;
    }
    return 0;
}
