#pragma once

#include <string>
#include <vector>

/// The colour modes facet renders in, by Mitsuba's variant names (`mitsuba -m scalar_rgb`), and
/// the one place a name a user typed (`facet render -m`, Python's `mode=`) becomes a mode.
namespace facet {

/// The modes facet renders in, the default first: {"scalar_rgb"}. The one list: a mode added
/// here is accepted by every resolve_mode() caller, with its vectorised names.
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

} // namespace facet
