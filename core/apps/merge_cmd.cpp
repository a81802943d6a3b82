// `facet merge parts... -o out.exr`: puts the parts of a render split by crop windows and
// passes (`facet render --crop ... --pass I --passes N`) back together (facet/merge.h).

#include "commands.h"

#include <facet/logger.h>
#include <facet/merge.h>
#include <facet/render.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <atomic>
#include <csignal>
#include <cstdio>

int merge_main(int argc, char **argv) {
    std::vector<std::string> inputs;
    std::string output;
    bool quiet = false;
    CLI::App app("Merge the parts of a render split into crop windows and passes: crops are "
                 "placed by their data windows, passes averaged by their sample counts",
                 "facet merge");
    app.add_option("parts", inputs, "The part images (EXR)")->required();
    app.add_option("-o,--output", output, "The merged image")->required();
    app.add_flag("-q,--quiet", quiet, "No summary line");
    if (int code = facet::cli::parse(app, argc, argv); code >= 0) return code;

    std::vector<facet::merge::Part> parts;
    parts.reserve(inputs.size());
    // Running out of memory names the step (the part, the merge, the output).
    for (const std::string &path : inputs) {
        facet::cli::set_activity(fmt::format("reading the part \"{}\"", path));
        parts.push_back(facet::merge::read_part(path));
    }
    facet::cli::set_activity(fmt::format("merging {} parts", parts.size()));
    facet::merge::Merged merged = facet::merge::merge_parts(parts);
    facet::cli::set_activity(fmt::format("writing \"{}\"", output));
    // A merge is the last step of a long render: a signal during the write (a Slurm time limit,
    // a Ctrl-C) lets it finish, then facet exits 128 + the signal, as `facet render` does.
    std::atomic<bool> interrupted{false};
    facet::install_interrupt_handler(&interrupted);
    facet::defer_interrupts();
    struct HandlerGuard {
        ~HandlerGuard() { facet::uninstall_interrupt_handler(); }
    } handler_guard;
    std::string write_error;
    try {
        facet::merge::write_merged(merged, output);
    } catch (const std::exception &e) {
        if (facet::interrupt_signal() == 0) throw;
        write_error = e.what(); // said with the signal, below
    }
    if (const int sig = facet::interrupt_signal(); sig != 0) {
        const char *verb = sig == SIGTERM  ? "terminated"
                           : sig == SIGHUP ? "hung up"
                                           : "interrupted";
        if (write_error.empty())
            std::fprintf(stderr, "facet: %s (%s) while writing: wrote the merged image to %s\n",
                         verb, facet::interrupt_signal_name(sig), output.c_str());
        else
            std::fprintf(stderr,
                         "facet: %s (%s) while writing: the merged image was not written: "
                         "%s\n",
                         verb, facet::interrupt_signal_name(sig), write_error.c_str());
        return 128 + sig;
    }
    if (!quiet)
        fmt::print("Merged {} part{} ({} pass{}) into {} ({}x{})\n", parts.size(),
                   parts.size() == 1 ? "" : "s", merged.passes, merged.passes == 1 ? "" : "es",
                   output, merged.image.width, merged.image.height);
    return 0;
}
