// `facet merge parts... -o out.exr`: puts the parts of a render split by crop windows and
// passes (`facet render --crop ... --pass I --passes N`) back together (merge.h).

#include "commands.h"
#include "merge.h"

#include <facet/logger.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

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
    facet::merge::write_merged(merged, output);
    if (!quiet)
        fmt::print("Merged {} part{} ({} pass{}) into {} ({}x{})\n", parts.size(),
                   parts.size() == 1 ? "" : "s", merged.passes, merged.passes == 1 ? "" : "es",
                   output, merged.image.width, merged.image.height);
    return 0;
}
