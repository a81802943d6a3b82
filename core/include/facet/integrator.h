#pragma once

#include <facet/color.h>
#include <facet/object.h>
#include <facet/ray.h>
#include <facet/render.h>

#include <string>
#include <vector>

namespace facet {

/// Renders an image of a sensor. Integrator::render() is the entry point the core (render.h) and
/// the CLI call, whatever the kind of integrator: SamplingIntegrator renders image blocks, a light
/// tracer splats into the film.
class Integrator : public Object {
public:
    ObjectType type() const override { return ObjectType::Integrator; }

    /// Renders `sensor` (its film, sampler and crop window) and returns the developed film.
    /// Same scene, seed and spp give the same image for any opts.threads; the cancel flag stops
    /// the render after the work in flight and the partial image is returned. The default
    /// throws: an integrator that renders no images (e.g. a test recorder) need not implement it.
    virtual RenderResult render(const Scene &scene, const Sensor &sensor,
                                const RenderOptions &opts) const;
};

/// Integrators that estimate the radiance along camera rays independently. render() is
/// progressive: it takes the samples in passes over the whole crop window (1, 1, 2, 4, ...
/// samples per pixel, or samples_per_pass each), each pass in square blocks on all threads, and
/// the film only receives whole passes. A stop (cancel flag, timeout) abandons the pass in
/// flight within moments and develops the passes done: every pixel has the same spp.
///
/// Determinism rule: sample i of a pixel is seeded from (seed, pixel index, i) alone, the pass
/// schedule depends only on the film size and the sample count, and blocks are merged into the
/// film in (pass, block) order, so the image does not depend on the thread count; nor, with a
/// filter whose footprint stays inside one pixel (box), on the block size.
///
/// Parameters read here (every sampling integrator lists them in its table):
/// | timeout | float | -1 | Stop after this many seconds (develop what is done); <= 0: none |
/// | samples_per_pass | integer | (all) | Samples per pixel of each pass over the image |
/// | block_size | integer | 0 | Side of the image blocks in pixels; 0: 32 |
class SamplingIntegrator : public Integrator {
public:
    SamplingIntegrator() = default;
    /// Reads timeout, samples_per_pass and block_size.
    explicit SamplingIntegrator(const Properties &props);

    /// Radiance arriving along `ray`. `aovs` has room for aov_names().size() floats.
    virtual Color3f sample(const Scene &scene, Sampler &sampler, const Ray &ray,
                           float *aovs) const = 0;
    /// Extra channels this integrator writes (e.g. "albedo.R"); none by default.
    virtual std::vector<std::string> aov_names() const { return {}; }

    RenderResult render(const Scene &scene, const Sensor &sensor,
                        const RenderOptions &opts) const override;

    double timeout() const { return m_timeout; }
    uint32_t samples_per_pass() const { return m_samples_per_pass; }
    int block_size() const { return m_block_size; }

protected:
    double m_timeout = -1.0;
    uint32_t m_samples_per_pass = 0; ///< 0: all samples in one pass
    int m_block_size = 0;            ///< 0: 32
};

/// Reads Mitsuba's `timeout` (seconds, <= 0 for none) and `samples_per_pass` (0 when absent);
/// used by SamplingIntegrator and by integrators that render otherwise (light tracers).
double read_timeout(const Properties &props);
uint32_t read_samples_per_pass(const Properties &props);
/// Reads Mitsuba's path depth parameters as `path` and `ptracer` take them: `max_depth` (-1 for
/// unbounded, returned as UINT32_MAX) and `rr_depth` (> 0, default 5); `plugin` names the
/// integrator in the error message.
uint32_t read_max_depth(const Properties &props, const char *plugin);
uint32_t read_rr_depth(const Properties &props, const char *plugin);

} // namespace facet
