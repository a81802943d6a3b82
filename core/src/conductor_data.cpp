#include <facet/conductor_data.h>
#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/spectrum.h>

#include <fmt/format.h>

#include <algorithm>
#include <cctype>

namespace facet {

namespace {

// The grid of the CIE tables, which the generator resamples to.
constexpr int GridSize = 95;
constexpr double GridFirstNm = 360.0, GridStepNm = 5.0;

struct ConductorEntry {
    const char *name;
    float eta[GridSize];
    float k[GridSize];
};

const ConductorEntry CONDUCTORS[] = {
#include "conductor_table.inc"
};

SpectrumData grid_spectrum(const float *values) {
    SpectrumData s;
    s.uniform = false;
    for (int i = 0; i < GridSize; ++i) {
        s.wavelengths.push_back(GridFirstNm + GridStepNm * i);
        s.values.push_back(values[i]);
    }
    return s;
}

std::string lowercase(std::string s) {
    for (char &c : s) c = char(std::tolower((unsigned char)c));
    return s;
}

} // namespace

std::vector<std::string> conductor_names() {
    std::vector<std::string> names;
    for (const ConductorEntry &e : CONDUCTORS) names.emplace_back(e.name);
    names.emplace_back("none");
    std::sort(names.begin(), names.end());
    return names;
}

namespace {

const ConductorEntry &find_conductor(const std::string &material) {
    const ConductorEntry *found = nullptr;
    for (const ConductorEntry &e : CONDUCTORS)
        if (material == e.name) found = &e;
    if (!found)
        for (const ConductorEntry &e : CONDUCTORS)
            if (lowercase(material) == lowercase(e.name)) found = &e;
    if (!found) {
        std::vector<std::string> names = conductor_names();
        std::string closest = closest_name(material, names);
        FACET_THROW("unknown conductor material \"{}\"{}; valid materials: {}", material,
                    closest.empty() ? "" : fmt::format(" (did you mean \"{}\"?)", closest),
                    fmt::join(names, ", "));
    }
    return *found;
}

} // namespace

std::pair<Color3f, Color3f> conductor_eta_k(const std::string &material) {
    if (material == "none") return {Color3f(0.f), Color3f(1.f)};
    const ConductorEntry &found = find_conductor(material);
    return {spectrum_to_rgb(grid_spectrum(found.eta), SpectrumKind::Measured),
            spectrum_to_rgb(grid_spectrum(found.k), SpectrumKind::Measured)};
}

std::pair<SpectrumData, SpectrumData> conductor_eta_k_spectra(const std::string &material) {
    if (material == "none") return {SpectrumData::constant(0.0), SpectrumData::constant(1.0)};
    const ConductorEntry &found = find_conductor(material);
    return {grid_spectrum(found.eta), grid_spectrum(found.k)};
}

ConductorIOR read_conductor_ior(const Properties &props) {
    ConductorIOR result;
    result.material = props.get_string("material", "none");
    bool has_eta = props.has("eta"), has_k = props.has("k");
    if (result.material != "none" && (has_eta || has_k))
        FACET_THROW_AT(props.location(),
                       "give either material=\"{}\" or eta/k, not both (material = \"none\" "
                       "uses eta and k)",
                       result.material);
    if (result.material == "none") {
        result.eta = props.texture("eta", 0.f, SpectrumKind::Unbounded);
        result.k = props.texture("k", 1.f, SpectrumKind::Unbounded);
    } else {
        std::pair<Color3f, Color3f> eta_k;
        try {
            eta_k = conductor_eta_k(result.material);
        } catch (const Error &e) {
            throw Error(props.location("material"), e.message());
        }
        if (is_spectral(props.mode())) {
            // The measured data per wavelength.
            auto spectra = conductor_eta_k_spectra(result.material);
            result.eta = data_spectrum_texture(spectra.first, SpectrumKind::Measured);
            result.k = data_spectrum_texture(spectra.second, SpectrumKind::Measured);
        } else {
            result.eta = std::make_shared<ConstantTexture>(in_mode(eta_k.first, props.mode()));
            result.k = std::make_shared<ConstantTexture>(in_mode(eta_k.second, props.mode()));
        }
    }
    return result;
}

} // namespace facet
