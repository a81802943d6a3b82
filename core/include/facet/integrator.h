#pragma once

#include <facet/color.h>
#include <facet/mueller.h>
#include <facet/object.h>
#include <facet/ray.h>
#include <facet/render.h>

#include <string>
#include <vector>

namespace facet {

/// What renders an image of a sensor. The render loop is core's (render() in render.h): an
/// integrator implements only the work of one sample, as a SamplingIntegrator (radiance along a
/// camera ray) or as a LightTracer (one light path splatted onto the film). Integrators of
/// neither kind (e.g. a test recorder) load but cannot render images.
///
/// Parameters read here (every integrator that renders lists them in its table):
/// | timeout | float | -1 | Stop after this many seconds (develop what is done); <= 0: none |
/// | samples_per_pass | integer | (progressive) | Samples per pixel of each pass over the image |
class Integrator : public Object {
public:
    ObjectType type() const override { return ObjectType::Integrator; }

    /// Seconds after which a render stops and develops the passes done; <= 0: none.
    double timeout() const { return m_timeout; }
    /// Samples per pixel of each pass over the image; 0: 1, 1, 2, 4, ... (see render.h).
    uint32_t samples_per_pass() const { return m_samples_per_pass; }

protected:
    Integrator() = default;
    /// Reads timeout and samples_per_pass.
    explicit Integrator(const Properties &props);

    double m_timeout = -1.0;
    uint32_t m_samples_per_pass = 0; ///< 0: progressive passes
};

/// Integrators that estimate the radiance along camera rays independently. The render loop takes
/// the samples in passes over the whole crop window (1, 1, 2, 4, ... samples per pixel, or
/// samples_per_pass each), each pass in square blocks on all threads; the image only receives
/// whole passes. A stop (cancel flag, timeout) abandons the pass in flight within moments and
/// develops the passes done: every pixel has the same spp.
///
/// Determinism rule: sample i of a pixel is seeded from (seed, pixel index, i) alone, the pass
/// schedule depends only on the film size and the sample count, and blocks are merged in
/// (pass, block) order, so the image does not depend on the thread count; nor, with a filter
/// whose footprint stays inside one pixel (box), on the block size. sample() is called from
/// many threads at once: it may not change the integrator (or anything the scene holds).
///
/// Also read here: | block_size | integer | 0 | Side of the image blocks in pixels; 0: 32 |
class SamplingIntegrator : public Integrator {
public:
    /// Radiance arriving along `ray`. `aovs` has room for aov_names().size() floats, all zero
    /// on entry. A long loop inside one sample asks render_should_stop(iteration) (render.h).
    virtual Color3f sample(const Scene &scene, Sampler &sampler, const Ray &ray,
                           float *aovs) const = 0;
    /**
     * The polarized mode's whole answer: the Stokes vector of the light arriving along `ray`, in
     * the implicit frame of its direction of travel (mueller::stokes_basis(-ray.d)); S0 is what
     * sample() returns. Only integrators whose has_stokes() is true give more than that (the
     * `stokes` integrator refuses the others); the default is sample()'s unpolarised light.
     */
    virtual Stokes sample_stokes(const Scene &scene, Sampler &sampler, const Ray &ray,
                                 float *aovs) const {
        return Stokes::unpolarized(sample(scene, sampler, ray, aovs));
    }
    /// True when sample_stokes() follows the polarisation of light in the polarized mode.
    virtual bool has_stokes() const { return false; }
    /**
     * sample() for a ray whose closest hit the caller has found already: `si` and `hit` are
     * what scene.ray_intersect(ray, si) gave. When takes_first_hit() is true the render loop
     * traces the camera rays of neighbouring pixels together (Scene::ray_intersect_packet())
     * and calls this instead of sample(), with the sampler where sample() would find it (past
     * the camera's dimensions). The default ignores the hit.
     */
    virtual Color3f sample_from_hit(const Scene &scene, Sampler &sampler, const Ray &ray,
                                    const SurfaceInteraction & /*si*/, bool /*hit*/,
                                    float *aovs) const {
        return sample(scene, sampler, ray, aovs);
    }
    /// Whether sample_from_hit() uses the hit it is given (false by default: the render loop
    /// then calls sample(), which traces the camera ray itself).
    virtual bool takes_first_hit() const { return false; }
    /// Called by the render loop before the first sample of a render from `sensor`, on one
    /// thread: an integrator that needs the sensor (the `stokes` integrator's reference frame)
    /// records it. One integrator renders from one sensor at a time.
    virtual void begin_render(const Sensor & /*sensor*/) const {}
    /// Extra channels this integrator writes (e.g. "albedo.R"); none by default.
    virtual std::vector<std::string> aov_names() const { return {}; }

    int block_size() const { return m_block_size; }

protected:
    SamplingIntegrator() = default;
    /// Reads timeout, samples_per_pass and block_size.
    explicit SamplingIntegrator(const Properties &props);

    int m_block_size = 0; ///< 0: 32
};

/// Where a light tracer's contributions go: the render's splat buffer for the current work unit,
/// through the film's reconstruction filter (normalised over its footprint, so a splat's energy
/// lands on the film whatever the filter).
class SplatTarget {
public:
    SplatTarget(ImageBlock &block, const ReconstructionFilter &filter)
        : m_block(block), m_filter(filter) {}
    /// Adds `value` at the continuous position `film_pos` of the full film, in pixels (pixel
    /// centres at .5; DirectionSample::uv of a sensor).
    void splat(const Point2f &film_pos, const Color3f &value);

private:
    ImageBlock &m_block;
    const ReconstructionFilter &m_filter;
};

/// Integrators that trace paths from the emitters and connect them to the sensor (light
/// tracing). The render loop is core's: it takes width x height x spp samples in progressive
/// passes of a fixed number of work units, seeds each sample's stream from (seed, sample index)
/// and merges the units' splats in unit order, so the image does not depend on the thread count.
/// The sensor must support sampling a direction towards it (the render refuses it otherwise).
class LightTracer : public Integrator {
public:
    /// One sample: whatever light path(s) the sampler's values give, splatted into `target`.
    /// Called from many threads at once; a long path asks render_should_stop(iteration).
    virtual void trace(const Scene &scene, const Sensor &sensor, Sampler &sampler,
                       SplatTarget &target) const = 0;

protected:
    LightTracer() = default;
    /// Reads timeout and samples_per_pass.
    explicit LightTracer(const Properties &props) : Integrator(props) {}
};

/// Reads Mitsuba's path depth parameters as `path` and `ptracer` take them: `max_depth` (-1 for
/// unbounded, returned as UINT32_MAX) and `rr_depth` (> 0, default 5); `plugin` names the
/// integrator in the error message.
uint32_t read_max_depth(const Properties &props, const char *plugin);
uint32_t read_rr_depth(const Properties &props, const char *plugin);

} // namespace facet
