#pragma once

#include <facet/color.h>
#include <facet/object.h>
#include <facet/ray.h>

#include <string>
#include <vector>

namespace facet {

class Integrator : public Object {
public:
    ObjectType type() const override { return ObjectType::Integrator; }
};

/// Integrators that estimate the radiance along camera rays independently; the core render loop
/// (render.h) drives them.
class SamplingIntegrator : public Integrator {
public:
    /// Radiance arriving along `ray`. `aovs` has room for aov_names().size() floats.
    virtual Color3f sample(const Scene &scene, Sampler &sampler, const Ray &ray,
                           float *aovs) const = 0;
    /// Extra channels this integrator writes (e.g. "albedo.R"); none by default.
    virtual std::vector<std::string> aov_names() const { return {}; }
};

} // namespace facet
