#include <facet/ior.h>
#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/properties.h>

#include <fmt/format.h>

#include <cctype>

namespace facet {

const std::vector<std::pair<std::string, float>> &ior_table() {
    // clang-format off
    static const std::vector<std::pair<std::string, float>> table = {
        {"vacuum", 1.0f},
        {"helium", 1.000036f},
        {"hydrogen", 1.000132f},
        {"air", 1.000277f},
        {"carbon dioxide", 1.00045f},
        {"water", 1.3330f},
        {"acetone", 1.36f},
        {"ethanol", 1.361f},
        {"carbon tetrachloride", 1.461f},
        {"glycerol", 1.4729f},
        {"benzene", 1.501f},
        {"silicone oil", 1.52045f},
        {"bromine", 1.661f},
        {"water ice", 1.31f},
        {"fused quartz", 1.458f},
        {"pyrex", 1.470f},
        {"acrylic glass", 1.49f},
        {"polypropylene", 1.49f},
        {"bk7", 1.5046f},
        {"sodium chloride", 1.544f},
        {"amber", 1.55f},
        {"pet", 1.5750f},
        {"diamond", 2.419f},
    };
    // clang-format on
    return table;
}

float lookup_ior(const std::string &name) {
    std::string lower = name;
    for (char &c : lower) c = char(std::tolower((unsigned char)c));
    std::vector<std::string> names;
    for (const auto &[n, value] : ior_table()) {
        if (n == lower) return value;
        names.push_back(n);
    }
    std::string closest = closest_name(lower, names);
    FACET_THROW("unknown IOR name \"{}\"{}; expected a number or one of: {}", name,
                closest.empty() ? "" : fmt::format(" (did you mean \"{}\"?)", closest),
                fmt::join(names, ", "));
}

float read_ior(const Properties &props, const std::string &param, const std::string &default_name) {
    if (!props.has(param)) return lookup_ior(default_name);
    float value;
    Properties::Type type = props.type(param);
    try {
        if (type == Properties::Type::String)
            value = lookup_ior(props.get_string(param));
        else
            value = float(props.get_float(param));
    } catch (const Error &e) {
        // Add the scene location of the entry to messages from lookup_ior().
        if (e.location().valid()) throw;
        throw Error(props.location(param), fmt::format("{}: {}", param, e.message()));
    }
    if (!(value > 0.f) || !std::isfinite(value))
        FACET_THROW_AT(props.location(param), "{} must be a positive index of refraction, found {}",
                       param, value);
    return value;
}

} // namespace facet
