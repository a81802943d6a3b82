#pragma once

#include <facet/properties.h>

namespace facet {

/// Horizontal field of view in degrees of a perspective-style camera, from `fov` with `fov_axis`
/// (x, y, diagonal, smaller, larger) or from a 35 mm equivalent `focal_length` (default "50mm",
/// a 36x24 mm film measured along its diagonal), for a film of the given aspect (width/height).
/// Giving both fov and focal_length is an error (as in Mitsuba 3).
double perspective_x_fov(const Properties &props, double aspect);

} // namespace facet
