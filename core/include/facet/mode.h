#pragma once

#include <facet/color.h>

#include <cstdint>
#include <string>
#include <vector>

/// The colour modes facet renders in, by Mitsuba's variant names (`mitsuba -m scalar_rgb`), and
/// the one place a name a user typed (`facet render -m`, Python's `mode=`) becomes a mode.
namespace facet {

/// The modes facet renders in, the default first: {"scalar_rgb", "scalar_mono", "scalar_spectral",
/// "scalar_spectral_polarized"}.
/// The one list: a mode added here is accepted by every resolve_mode() caller, with its vectorised
/// names.
const std::vector<std::string> &modes();

/// The mode of a render that names none: modes().front().
const std::string &default_mode();

/**
 * The mode facet renders for `name`:
 * - one of modes(): that mode;
 * - a vectorised name of one of them (`llvm_rgb`, `cuda_rgb`, `llvm_ad_rgb`, `cuda_ad_rgb`): its
 *   scalar mode, with a one-line note (log level Info) that facet renders it as that;
 * - another Mitsuba variant (`scalar_spectral`, `scalar_rgb_polarized`, `llvm_mono_double`, ...):
 *   throws facet::Error saying facet does not render that mode, listing modes();
 * - anything else: throws facet::Error listing modes(), with the nearest valid name.
 */
std::string resolve_mode(const std::string &name);

/**
 * The colour of a render, fixed when its scene is loaded (LoadOptions::mode): every plugin reads
 * it from Properties::mode() and turns the colours it is given into what the mode renders.
 * - `RGB`: linear Rec.709 RGB.
 * - `Mono`: luminance. facet renders it with the RGB value type holding three equal values: every
 *   colour a scene gives (rgb, spectrum, image texel, vertex colour) becomes its luminance
 *   (Rec.709 Y, which is CIE Y) when it is read, so every channel of every value along a path is
 *   the same and the image's R = G = B is the mono image.
 * - `Spectral`: each channel of a value along a path is the quantity at one of the path's four
 *   wavelengths (Interaction::wavelengths, sampled with the camera ray); the render loop turns
 *   the path's radiance into CIE XYZ and then the film's RGB. Colours a scene gives become
 *   spectra (RGB by the sigmoid-polynomial model, spectra and measured data per wavelength), which
 *   textures evaluate at the interaction's wavelengths (see Properties::texture()).
 * - `SpectralPolarized`: the spectral mode whose light carries its polarisation: a path's
 *   radiance is a Stokes vector and a BSDF's value a Mueller matrix at each wavelength
 *   (facet/mueller.h gives the conventions). Colours are read as in `Spectral`; BSDFs that do not
 *   polarise depolarise (BSDF::sample_polarized()), emitters are unpolarised, and the film
 *   records the intensity S0 (the `stokes` integrator records all four components).
 */
enum class ColourMode : uint8_t { RGB, Mono, Spectral, SpectralPolarized };

/// True in the modes whose values hold the quantity at the path's wavelengths.
constexpr bool is_spectral(ColourMode mode) {
    return mode == ColourMode::Spectral || mode == ColourMode::SpectralPolarized;
}
/// True in the mode whose light carries its polarisation.
constexpr bool is_polarized(ColourMode mode) { return mode == ColourMode::SpectralPolarized; }

/// The bit of `mode` in PluginDescriptor::modes.
constexpr uint32_t mode_bit(ColourMode mode) { return 1u << uint32_t(mode); }
/// The modes of a plugin that reads its colours through Properties and never looks at
/// wavelengths: rgb and mono.
constexpr uint32_t RGBAndMono = mode_bit(ColourMode::RGB) | mode_bit(ColourMode::Mono);
/// The modes without polarisation: a plugin that evaluates its colours at
/// Interaction::wavelengths in the spectral mode but would be wrong where light is polarised (a
/// BSDF that polarises without BSDF::sample_polarized() and its siblings; an integrator that
/// chains BSDF values as colours).
constexpr uint32_t UnpolarizedModes = RGBAndMono | mode_bit(ColourMode::Spectral);
/// Every mode: a plugin without colours (a shape, a sensor, a filter, a sampler), or one that
/// evaluates its colours at Interaction::wavelengths in the spectral modes, and in the polarized
/// mode is unpolarised (an emitter), depolarises (a BSDF through the default
/// BSDF::sample_polarized()) or carries the polarisation (the path integrator).
constexpr uint32_t AllModes = UnpolarizedModes | mode_bit(ColourMode::SpectralPolarized);

/// The ColourMode of one of modes() (a name resolve_mode() returned); throws facet::Error for any
/// other name.
ColourMode colour_mode(const std::string &mode);
/// The name of a ColourMode in modes(): "scalar_rgb", "scalar_mono", "scalar_spectral",
/// "scalar_spectral_polarized".
const char *mode_name(ColourMode mode);

/// A colour a scene gives (linear Rec.709) as `mode` renders it at load: in Mono its luminance in
/// every channel, otherwise unchanged (the spectral mode upsamples it where it is evaluated).
inline Color3f in_mode(const Color3f &c, ColourMode mode) {
    return mode == ColourMode::Mono ? Color3f(c.luminance()) : c;
}

} // namespace facet
