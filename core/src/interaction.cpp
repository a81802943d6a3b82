#include <facet/interaction.h>
#include <facet/shape.h>

namespace facet {

const BSDF *SurfaceInteraction::bsdf() const { return shape ? shape->bsdf() : nullptr; }

const Emitter *SurfaceInteraction::emitter() const { return shape ? shape->emitter() : nullptr; }

} // namespace facet
