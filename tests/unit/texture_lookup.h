#pragma once

// The surface point the texture tests look a texture up at.

#include <facet/interaction.h>

namespace facet {

/// A surface interaction at texture coordinates (u, v), seen from straight above.
inline SurfaceInteraction at_uv(float u, float v) {
    SurfaceInteraction si;
    si.uv = Point2f(u, v);
    si.wi = Vector3f(0.f, 0.f, 1.f);
    return si;
}

} // namespace facet
