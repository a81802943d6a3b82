#pragma once

#include <facet/color.h>
#include <facet/film.h>
#include <facet/object.h>
#include <facet/properties.h>
#include <facet/ray.h>
#include <facet/sampler.h>
#include <facet/transform.h>

#include <memory>
#include <utility>

namespace facet {

/// Camera. The base class reads `to_world` and the nested film and sampler (creating the defaults,
/// hdrfilm and independent, when absent).
class Sensor : public Object {
public:
    explicit Sensor(const Properties &props);
    ObjectType type() const override { return ObjectType::Sensor; }

    /// Ray through the film position `film_pos` in [0,1]² of the full film (x right, y down) and
    /// the aperture sample; returns the ray (world space, unit direction) and its importance
    /// weight.
    virtual std::pair<Ray, Color3f> sample_ray(float time, const Point2f &film_pos,
                                               const Point2f &aperture_sample) const = 0;
    virtual bool needs_aperture_sample() const { return false; }

    Film &film() const { return *m_film; }
    Sampler &sampler() const { return *m_sampler; }
    std::shared_ptr<Film> film_ptr() const { return m_film; }
    std::shared_ptr<Sampler> sampler_ptr() const { return m_sampler; }
    const Transform &to_world() const { return m_to_world; }

protected:
    Transform m_to_world;
    std::shared_ptr<Film> m_film;
    std::shared_ptr<Sampler> m_sampler;
};

} // namespace facet
