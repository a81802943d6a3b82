#pragma once

#include <facet/interaction.h>

#include <cmath>

/// Helpers shared by integrators that combine BSDF and emitter sampling.
namespace facet {

/// Power heuristic (β = 2, Veach 1997 eq. 9.13) for the strategy with density `a` against one
/// with density `b`; 0 where both vanish.
inline float mis_weight(float a, float b) {
    a *= a;
    b *= b;
    float w = a / (a + b);
    return std::isfinite(w) ? w : 0.f;
}

/// Record of the emitter point hit at `si` as seen from `ref`, for Scene::pdf_emitter_direction.
inline DirectionSample direction_to(const SurfaceInteraction &si, const Interaction &ref) {
    DirectionSample ds;
    ds.p = si.p;
    ds.n = si.n;
    ds.uv = si.uv;
    Vector3f d = si.p - ref.p;
    ds.dist = norm(d);
    ds.d = ds.dist > 0.f ? d / ds.dist : Vector3f(0.f);
    ds.emitter = si.emitter();
    return ds;
}

} // namespace facet
