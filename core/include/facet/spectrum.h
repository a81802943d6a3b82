#pragma once

#include <facet/color.h>

#include <string>
#include <utility>
#include <vector>

namespace facet {

/// How a spectrum is turned into RGB (as in Mitsuba 3's RGB variants). Every spectrum a scene
/// gives outside an emitter is weighted by D65, bounded or not; only reflectances are clamped
/// to 1.
enum class SpectrumKind {
    Reflectance, ///< weighted by D65, clamped to [0, 1]
    Emission,    ///< unweighted, clamped to >= 0; a uniform value c becomes c·xyz_to_srgb(1,1,1)
    Unbounded,   ///< weighted by D65, clamped to >= 0 (eta, k, alpha given in a scene)
    Measured,    ///< unweighted, clamped to >= 0 (a conductor `material`'s tabulated eta and k)
};

/// A spectrum as written in a scene: a uniform value or (wavelength nm, value) pairs.
struct SpectrumData {
    bool uniform = true;
    double value = 0.0;              ///< when uniform
    std::vector<double> wavelengths; ///< ascending, nm
    std::vector<double> values;

    static SpectrumData constant(double v) { return SpectrumData{true, v, {}, {}}; }
    /// Linear interpolation of the pairs; zero outside their range.
    double eval(double lambda) const;
    std::string to_string() const;
};

/// Parse "400:0.5, 500:0.7" or a single number; throws facet::Error on bad input.
SpectrumData parse_spectrum_pairs(const std::string &text);
/// Parse a list of numbers separated by commas and/or spaces ("0.1, 0.2 0.3"); `what` names
/// the list in errors. Throws facet::Error on an empty list or a bad number.
std::vector<double> parse_number_list(const std::string &text, const std::string &what);
/// Read a .spd file ("wavelength value" per line, '#' comments).
SpectrumData read_spd_file(const std::string &path);

/// Integrate against the CIE 1931 curves (1000 steps over 360-830 nm) and convert to linear sRGB.
Color3f spectrum_to_rgb(const SpectrumData &s, SpectrumKind kind);
/// CIE XYZ -> linear Rec.709 RGB and back.
Color3f xyz_to_srgb(const Color3f &xyz);
Color3f srgb_to_xyz(const Color3f &rgb);
/// CIE 1931 colour matching functions at `lambda` nm (linear interpolation of the 5 nm table).
Color3f cie1931_xyz(double lambda);
/// D65 relative power at `lambda` nm, scaled as Mitsuba's (to luminance 1 against the continuous
/// CIE curves; a white reflectance integrates to 0.99889 over spectrum_to_rgb's quadrature).
double cie_d65(double lambda);
/// cie_d65() at each of `lambda`'s wavelengths.
Color3f cie_d65(const Wavelengths &lambda);

/// The spectral mode's wavelength range, nm: the CIE tables'.
constexpr float SpectralMinNm = 360.f, SpectralMaxNm = 830.f;
/// The density (per nm) the spectral mode draws wavelengths from: proportional to
/// 1 / cosh²(0.0072 (λ - 538)) on [360, 830] nm, a curve that follows the sum of the CIE
/// matching functions (Mitsuba's choice), 0 outside.
float pdf_wavelength(float lambda);
/// The four wavelengths of a path (one per channel, Color3f::Channels) from one uniform number
/// `u`: stratified (u + i/4 modulo 1), each drawn from pdf_wavelength() by inversion, with their
/// weights 1 / pdf.
std::pair<Wavelengths, Color3f> sample_wavelengths(float u);
/// The weights sample_wavelengths() gives `lambda`: 1 / pdf_wavelength() per lane (0 where the
/// density is 0).
Color3f wavelength_weights(const Wavelengths &lambda);
/// The CIE XYZ of a path's spectral value (`L` at `lambda`, drawn with weights `weight`): the
/// mean over the channels of L·weight·(x̄, ȳ, z̄)(λ) / ∫ȳ, an unbiased estimate of the
/// spectrum's XYZ.
Color3f spectral_to_xyz(const Color3f &L, const Wavelengths &lambda, const Color3f &weight);
/// The radiance of a path of the spectral mode as linear Rec.709: xyz_to_srgb of
/// spectral_to_xyz().
Color3f spectral_to_srgb(const Color3f &L, const Wavelengths &lambda, const Color3f &weight);

} // namespace facet
