#pragma once

#include <facet/color.h>
#include <facet/film.h>
#include <facet/interaction.h>
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

    /// Importance sampling of the sensor from a point in the scene (light tracing): samples a
    /// point on the sensor's aperture that sees `ref`. Returns the record (ds.p on the aperture,
    /// ds.d the unit direction from ref to ds.p, ds.dist, ds.pdf the solid-angle density seen
    /// from ref, or 1 with ds.delta for a pinhole; ds.uv the continuous position on the full film
    /// in pixels, x right, y down, pixel centres at .5) and the weight We/pdf: the importance
    /// towards ref, with the sensor's cosine and the 1/dist² of the connection, over the density.
    /// The caller multiplies by f·|cos| at ref and tests visibility. A zero weight (and pdf 0)
    /// means ref is outside the field of view or the clipping range.
    ///
    /// Not every sensor supports it: the default throws (check supports_direction_sampling()).
    virtual std::pair<DirectionSample, Color3f> sample_direction(const Interaction &ref,
                                                                 const Point2f &u) const;
    /// Solid-angle density of sample_direction() for ds (0 for delta sensors).
    virtual float pdf_direction(const Interaction &ref, const DirectionSample &ds) const;
    /// Whether sample_direction() and pdf_direction() are implemented.
    virtual bool supports_direction_sampling() const { return false; }

    /// The film and the sampler: descriptions a render reads (it takes its own copy of the
    /// sampler and its own accumulation buffers), never changes.
    const Film &film() const { return *m_film; }
    const Sampler &sampler() const { return *m_sampler; }
    const Transform &to_world() const { return m_to_world; }
    /// The sensor's spectral response function (the `srf` parameter of the spectral modes, one
    /// band named "srf"; null: none): the paths' wavelengths are drawn from it, and the radiance
    /// the film develops is weighted by it.
    const SpectralBands *srf() const { return m_srf.get(); }
    /// Whether the paths' wavelengths come from the sensor's srf or the film's bands rather
    /// than the visible range's density (integrators that develop their own RGB refuse it).
    bool draws_wavelengths() const { return m_srf || m_film->bands(); }

protected:
    Transform m_to_world;
    std::shared_ptr<Film> m_film;
    std::shared_ptr<Sampler> m_sampler;
    std::shared_ptr<const SpectralBands> m_srf;
};

} // namespace facet
