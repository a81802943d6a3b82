#pragma once

#include <facet/color.h>
#include <facet/texture.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

/// Measured complex IORs (η + i·k) of conductors, by the names of Mitsuba's data/ior files
/// ("Cu", "Au", "Al", "Cu_palik", ...). The spectra are embedded (generated from the measured
/// data by core/scripts/gen_conductor_table.py) and converted to RGB on request.
namespace facet {

/// Names of all embedded materials, sorted, plus "none" (the ideal mirror: η = 0, k = 1).
std::vector<std::string> conductor_names();

/// RGB η and k of a material, integrated against the CIE curves without D65 (as Mitsuba converts
/// its data/ior files), clamped to >= 0 only.
/// Exact names first, then a case-insensitive match; unknown names throw facet::Error listing
/// the valid names and the closest one.
std::pair<Color3f, Color3f> conductor_eta_k(const std::string &material);

/// The measured η and k of a material per wavelength (the spectral mode's form; "none" gives the
/// uniform 0 and 1). Names as conductor_eta_k().
std::pair<SpectrumData, SpectrumData> conductor_eta_k_spectra(const std::string &material);

/// The conductor parameters of a BSDF: `material` (default "none") or `eta` and `k` (numbers,
/// rgb, spectra or textures; defaults 0 and 1). Giving a material together with eta or k throws.
struct ConductorIOR {
    std::string material;
    std::shared_ptr<Texture> eta, k;
};
ConductorIOR read_conductor_ior(const Properties &props);

} // namespace facet
