#pragma once

#include <facet/assert.h>
#include <facet/emitter.h>
#include <facet/interaction.h>
#include <facet/scene.h>

#include <cmath>

/// Helpers shared by integrators that combine BSDF and emitter sampling.
namespace facet {

/// Power heuristic (β = 2, Veach 1997 eq. 9.13) for the strategy with density `a` against one
/// with density `b`; 0 where both vanish.
inline float mis_weight(float a, float b) {
    FACET_ASSERT(a >= 0.f && b >= 0.f);
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

/// Radiance of the infinite emitters seen by a ray that left the scene from `ref` after a BSDF
/// sample of density `bsdf_pdf`; `escaped` is the record Scene::ray_intersect() filled on the
/// miss (Scene::escaped()). Each emitter is weighted against the density with which emitter
/// sampling picks it and this direction (times `emitter_fraction`, the share of emitter samples
/// when several strategies are mixed), since an emitter sample only ever carries its own
/// emitter's radiance. The densities are those of light samples taken for MIS
/// (LightSampling::MIS), the mode the caller's light samples must use, with their `side`
/// (Scene::sample_emitter_direction()). After a delta lobe or for a camera ray (`delta`) nothing
/// is weighted and `ref` is not read.
inline Color3f environment_mis(const Scene &scene, const SurfaceInteraction &escaped,
                               const Interaction &ref, float bsdf_pdf, bool delta,
                               float emitter_fraction = 1.f, const Vector3f &side = Vector3f(0.f)) {
    FACET_ASSERT(!escaped.is_valid() && !escaped.shape);
    const auto &emitters = scene.environment_emitters();
    if (emitters.empty()) return Color3f(0.f);
    DirectionSample ds; // the emitter-sampling record of the same direction
    ds.d = -escaped.to_world(escaped.wi);
    ds.dist = Infinity;
    ds.p = ref.p + ds.d;
    ds.n = -ds.d;
    Color3f result(0.f);
    for (const auto &emitter : emitters) {
        Color3f L = emitter->eval(escaped);
        if (L.is_black()) continue;
        float w = 1.f;
        if (!delta) {
            ds.emitter = emitter.get();
            w = mis_weight(bsdf_pdf,
                           scene.pdf_emitter_direction(ref, ds, LightSampling::MIS, side) *
                               emitter_fraction);
        }
        result += L * w;
    }
    return result;
}

} // namespace facet
