// `facet plugins [kind|name]`: what the plugin search path offers.

#include "commands.h"

#include <facet/logger.h>
#include <facet/mode.h>
#include <facet/plugin.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace {

using namespace facet;

/// The kinds in the order a scene usually introduces them.
const ObjectType KINDS[] = {
    ObjectType::Integrator,
    ObjectType::Sensor,
    ObjectType::Film,
    ObjectType::Sampler,
    ObjectType::ReconstructionFilter,
    ObjectType::Shape,
    ObjectType::BSDF,
    ObjectType::Texture,
    ObjectType::Emitter,
    ObjectType::Medium,
    ObjectType::PhaseFunction,
    ObjectType::Volume,
};

/// "bsdf" or "bsdfs" (also "BSDF") names a kind.
ObjectType kind_from_word(std::string word) {
    std::transform(word.begin(), word.end(), word.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    for (ObjectType kind : KINDS)
        if (word == object_type_name(kind) || word == object_type_folder(kind)) return kind;
    return ObjectType::Unknown;
}

struct Entry {
    std::string name, description, file; ///< file: set when not one of facet's own plugins
    std::string modes;                   ///< the modes it renders in, when not all of them
};

/// plugin_modes(desc) when the plugin does not render in every mode, else "".
std::string partial_modes(const PluginDescriptor &desc) {
    for (const std::string &mode : modes())
        if (!(desc.modes & mode_bit(colour_mode(mode)))) return plugin_modes(desc);
    return "";
}

/// The library that serves `name` (the first on the search path) when it is not in facet's own
/// plugin folder (the search path's last), with " (shadows the built-in)" when that has one too.
std::string user_file(const std::string &name) {
    const std::vector<std::string> path = PluginRegistry::instance().search_path();
    if (path.empty()) return "";
    std::error_code ec;
    for (size_t i = 0; i + 1 < path.size(); ++i) {
        const std::filesystem::path p = std::filesystem::path(path[i]) / (name + ".so");
        if (!std::filesystem::is_regular_file(p, ec)) continue;
        const bool shadows = std::filesystem::is_regular_file(
            std::filesystem::path(path.back()) / (name + ".so"), ec);
        return p.string() + (shadows ? " (shadows the built-in)" : "");
    }
    return "";
}

/// Loads every plugin on the search path once; one that fails is listed with its error.
std::map<ObjectType, std::vector<Entry>> collect(std::vector<std::string> &broken) {
    PluginRegistry &registry = PluginRegistry::instance();
    std::map<ObjectType, std::vector<Entry>> by_kind;
    for (const std::string &name : registry.available()) {
        try {
            const PluginDescriptor &desc = registry.descriptor(name);
            by_kind[desc.kind].push_back({name, desc.description ? desc.description : "",
                                          user_file(name), partial_modes(desc)});
        } catch (const std::exception &e) {
            broken.push_back(fmt::format("{}: {}", name, e.what()));
        }
    }
    return by_kind;
}

void print_kind(ObjectType kind, const std::vector<Entry> &entries) {
    size_t width = 0;
    for (const Entry &e : entries) width = std::max(width, e.name.size());
    fmt::print("{} ({}):\n", object_type_folder(kind), object_type_name(kind));
    for (const Entry &e : entries)
        fmt::print("  {:<{}}  {}{}{}\n", e.name, width, e.description,
                   e.modes.empty() ? "" : " (only " + e.modes + ")",
                   e.file.empty() ? "" : " [" + e.file + "]");
}

} // namespace

int plugins_main(int argc, char **argv) {
    std::string what;
    std::vector<std::string> dirs;
    CLI::App app("List the plugins found on the search path, or show one plugin's parameters",
                 "facet plugins");
    app.add_option("what", what, "A kind (bsdf, emitter, ...) or a plugin name");
    app.add_option("-a", dirs, "Add folders to the plugin search path (';' separates several)");
    if (int code = cli::parse(app, argc, argv); code >= 0) return code;

    PluginRegistry &registry = PluginRegistry::instance();
    for (const std::string &value : dirs) {
        size_t start = 0;
        while (start <= value.size()) {
            size_t end = std::min(value.find(';', start), value.size());
            if (end > start) registry.add_search_dir(value.substr(start, end - start));
            start = end + 1;
        }
    }

    ObjectType only = what.empty() ? ObjectType::Unknown : kind_from_word(what);
    if (!what.empty() && only == ObjectType::Unknown) {
        // A plugin name: print its documentation.
        std::vector<std::string> names = registry.available();
        if (std::find(names.begin(), names.end(), what) == names.end()) {
            std::string hint = closest_name(what, names);
            FACET_THROW("no plugin or plugin kind named \"{}\"{} (`facet plugins` lists them)",
                        what, hint.empty() ? "" : fmt::format("; did you mean \"{}\"?", hint));
        }
        const PluginDescriptor &desc = registry.descriptor(what);
        std::string doc = desc.doc ? desc.doc : "";
        doc.erase(0, doc.find_first_not_of("\n"));
        doc.erase(doc.find_last_not_of("\n") + 1);
        const std::string file = user_file(what);
        fmt::print("{} ({}): {}\nmodes: {}\n{}\n{}\n", desc.name, object_type_name(desc.kind),
                   desc.description ? desc.description : "", plugin_modes(desc),
                   file.empty() ? "" : fmt::format("from {}\n", file), doc);
        return 0;
    }

    std::vector<std::string> broken;
    auto by_kind = collect(broken);
    bool first = true;
    for (ObjectType kind : KINDS) {
        if (only != ObjectType::Unknown && kind != only) continue;
        auto it = by_kind.find(kind);
        if (it == by_kind.end()) continue;
        if (!first) fmt::print("\n");
        print_kind(kind, it->second);
        first = false;
    }
    if (first) {
        std::string where;
        for (const std::string &dir : registry.search_path())
            where += (where.empty() ? "" : ", ") + dir;
        fmt::print("No {}plugins found (search path: {})\n",
                   only == ObjectType::Unknown ? "" : fmt::format("{} ", object_type_name(only)),
                   where.empty() ? "empty" : where);
    }
    for (const std::string &line : broken) FACET_LOG(Warn, "could not load plugin {}", line);
    return 0;
}
