#include <facet/logger.h>
#include <facet/mode.h>
#include <facet/plugin.h>

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <iterator>

namespace facet {

namespace {

/// The prefixes of Mitsuba's vectorised variants of a scalar mode ("llvm_ad_" + "rgb").
const char *const VECTORISED[] = {"llvm_", "cuda_", "llvm_ad_", "cuda_ad_"};

/// The scalar form of a Mitsuba variant name ("llvm_ad_rgb" -> "scalar_rgb", "scalar_mono_double"
/// unchanged), or "" for a name that is no variant: a backend, then mono, rgb or spectral, then
/// optionally _polarized, then optionally _double.
std::string scalar_form(const std::string &name) {
    std::vector<std::string> backends = {"scalar_"};
    backends.insert(backends.end(), std::begin(VECTORISED), std::end(VECTORISED));
    for (const std::string &prefix : backends) {
        if (name.compare(0, prefix.size(), prefix) != 0) continue;
        const std::string rest = name.substr(prefix.size());
        for (const char *colour : {"mono", "rgb", "spectral"})
            for (const char *polarized : {"", "_polarized"})
                for (const char *precision : {"", "_double"})
                    if (rest == std::string(colour) + polarized + precision)
                        return "scalar_" + rest;
    }
    return "";
}

bool has_mode(const std::string &name) {
    const std::vector<std::string> &ours = modes();
    return std::find(ours.begin(), ours.end(), name) != ours.end();
}

} // namespace

const std::vector<std::string> &modes() {
    static const std::vector<std::string> list = {"scalar_rgb", "scalar_mono", "scalar_spectral",
                                                  "scalar_spectral_polarized"};
    return list;
}

const std::string &default_mode() { return modes().front(); }

std::string resolve_mode(const std::string &name) {
    if (has_mode(name)) return name;
    const std::string scalar = scalar_form(name);
    if (!scalar.empty() && has_mode(scalar)) {
        FACET_LOG(Info,
                  "mode \"{}\": facet renders it as {} (facet has no vectorised or "
                  "differentiable modes)",
                  name, scalar);
        return scalar;
    }
    const std::string list = fmt::format("{}", fmt::join(modes(), ", "));
    if (!scalar.empty())
        FACET_THROW("facet does not render the mode \"{}\"{}; the modes it renders: {}", name,
                    scalar == name ? "" : fmt::format(" (nor {}, its scalar form)", scalar), list);

    // The names that would have worked: the modes and their vectorised names.
    std::vector<std::string> accepted = modes();
    for (const std::string &mode : modes())
        for (const char *prefix : VECTORISED)
            accepted.push_back(prefix + mode.substr(mode.find('_') + 1));
    std::string lower = name;
    for (char &c : lower) c = char(std::tolower((unsigned char)c));
    const std::string close = closest_name(lower, accepted);
    FACET_THROW("unknown mode \"{}\"{}; the modes facet renders: {}", name,
                close.empty() ? "" : fmt::format(" (did you mean \"{}\"?)", close), list);
}

ColourMode colour_mode(const std::string &mode) {
    if (mode == "scalar_rgb") return ColourMode::RGB;
    if (mode == "scalar_mono") return ColourMode::Mono;
    if (mode == "scalar_spectral") return ColourMode::Spectral;
    if (mode == "scalar_spectral_polarized") return ColourMode::SpectralPolarized;
    FACET_THROW("\"{}\" is no mode facet renders (expected one of: {})", mode,
                fmt::join(modes(), ", "));
}

const char *mode_name(ColourMode mode) {
    switch (mode) {
    case ColourMode::Mono:
        return "scalar_mono";
    case ColourMode::Spectral:
        return "scalar_spectral";
    case ColourMode::SpectralPolarized:
        return "scalar_spectral_polarized";
    case ColourMode::RGB:
        break;
    }
    return "scalar_rgb";
}

} // namespace facet
