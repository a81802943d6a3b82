#pragma once

#include <facet/color.h>

#include <cstdint>
#include <string>
#include <vector>

/// The colour modes facet renders in, by Mitsuba's variant names (`mitsuba -m scalar_rgb`), and
/// the one place a name a user typed (`facet render -m`, Python's `mode=`) becomes a mode.
namespace facet {

/// The modes facet renders in, the default first: {"scalar_rgb", "scalar_mono"}. The one list: a
/// mode added here is accepted by every resolve_mode() caller, with its vectorised names.
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
 */
enum class ColourMode : uint8_t { RGB, Mono };

/// The ColourMode of one of modes() (a name resolve_mode() returned); throws facet::Error for any
/// other name.
ColourMode colour_mode(const std::string &mode);
/// The name of a ColourMode in modes(): "scalar_rgb", "scalar_mono".
const char *mode_name(ColourMode mode);

/// A colour a scene gives (linear Rec.709) as `mode` renders it: in Mono its luminance in every
/// channel, otherwise unchanged.
inline Color3f in_mode(const Color3f &c, ColourMode mode) {
    return mode == ColourMode::Mono ? Color3f(c.luminance()) : c;
}

} // namespace facet
