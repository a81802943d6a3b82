static const char *DOC = R"DOC(
# ptracer: particle tracer

Traces paths from the emitters (light tracing) and connects every surface vertex to the sensor,
splatting the contribution into the pixel it lands on. Emitters seen directly by the camera are
counted by a separate connection from a point sampled on the emitter to the sensor; for an
environment (`constant`, `envmap`) the point is far away in a direction the emitter samples from
the sensor's position, as in Mitsuba. Each sample
is one light path (plus one emitter connection); a render takes width x height x spp samples,
so the spp counts light paths per pixel as in Mitsuba. After `rr_depth` bounces, Russian roulette
ends paths whose throughput has become small.

The image does not depend on the thread count: the light paths are traced in progressive passes
(1, 1, 2, 4, ... paths per pixel, or `samples_per_pass`), each split into a fixed number of work
units that splat into their own image buffers, merged in unit order, and every path's random
numbers are seeded from (seed, path index). The film holds whole passes only: a render stopped
early (Ctrl-C, `timeout`) develops the light paths per pixel it reached. A render split into
parts (`--pass I --passes N`) traces the light paths of its samples.

The sensor must support sampling a direction towards it (perspective, thinlens, orthographic).
Every emitter emits rays: environments send them into the scene's bounding sphere from a disk
facing the sampled direction, so an environment lights the scene as it does for the path tracer.

In the spectral modes each light path draws its four wavelengths as a camera ray does and
splats its value developed through CIE XYZ; in `scalar_spectral_polarized` the light carries
its Stokes vector from the (unpolarised) emitter through every BSDF that polarises, and the
sensor records its intensity.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| max_depth | integer | -1 | Longest path, in segments: -1 is unbounded, 1 shows only directly visible emitters, 2 adds direct illumination, ... |
| rr_depth | integer | 5 | Depth from which Russian roulette may end a path (at least 1) |
| hide_emitters | boolean | false | Do not count emitters seen directly by the camera |
| samples_per_pass | integer | (progressive) | Trace the light paths in passes of this many per pixel (must divide the sample count) |
| timeout | float | -1 | Stop after this many seconds and develop what is done; <= 0: no limit |

```xml
<integrator type="ptracer">
    <integer name="max_depth" value="8"/>
</integrator>
```
)DOC";

#include <facet/bsdf.h>
#include <facet/emitter.h>
#include <facet/film.h>
#include <facet/integrator.h>
#include <facet/mode.h>
#include <facet/mueller.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/sampler.h>
#include <facet/scene.h>
#include <facet/sensor.h>
#include <facet/shape.h>
#include <facet/spectrum.h>

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <tuple>

namespace facet {

class ParticleTracer final : public LightTracer {
public:
    explicit ParticleTracer(const Properties &props) : LightTracer(props) {
        m_max_depth = read_max_depth(props, "ptracer");
        m_rr_depth = read_rr_depth(props, "ptracer");
        m_hide_emitters = props.get_bool("hide_emitters", false);
        m_spectral = is_spectral(props.mode());
        m_polarized = is_polarized(props.mode());
    }

    std::string to_string() const override {
        return fmt::format("ParticleTracer[max_depth = {}, rr_depth = {}, hide_emitters = {}]",
                           m_max_depth == std::numeric_limits<uint32_t>::max()
                               ? std::string("-1")
                               : std::to_string(m_max_depth),
                           m_rr_depth, m_hide_emitters);
    }

    /// One sample: the emitter connection (directly visible emitters) and one light path.
    void trace(const Scene &scene, const Sensor &sensor, Sampler &sampler,
               SplatTarget &film) const override {
        if (m_polarized)
            trace_path<true>(scene, sensor, sampler, film);
        else
            trace_path<false>(scene, sensor, sampler, film);
    }

private:
    /// The path's wavelengths (the spectral modes) and what a value at them adds to the film.
    struct Spectral {
        bool on = false;
        Wavelengths lambda;
        Color3f weight;
        /// Splats `value` (at the wavelengths, or RGB) at `uv`.
        void splat(SplatTarget &film, const Point2f &uv, const Color3f &value) const {
            if (value.is_black() || !value.is_finite()) return;
            film.splat(uv, on ? spectral_to_srgb(value, lambda, weight) : value);
        }
    };

    /// The light path. In the polarized mode (Polarized) the light carries a Stokes vector in
    /// the implicit frame of its direction of travel (mueller.h), which each BSDF's matrix
    /// (importance mode: light from −wi to wo) turns into the next one; the sensor records S0.
    template <bool Polarized> void trace_path(const Scene &scene, const Sensor &sensor,
                                              Sampler &sampler, SplatTarget &film) const {
        if (scene.emitters().empty()) return;
        Spectral spectral;
        if (m_spectral) {
            spectral.on = true;
            std::tie(spectral.lambda, spectral.weight) = sample_wavelengths(sampler.next_1d());
        }
        // The emitter as the scene picks light samples' emitters (by power where it can), and
        // the inverse of the probability it had.
        auto pick = [&](float u) {
            const auto [emitter, pmf] = scene.sample_emitter(u);
            return std::pair<const Emitter *, float>(emitter, pmf > 0.f ? 1.f / pmf : 0.f);
        };
        if (m_max_depth != 0 && !m_hide_emitters) {
            const auto [emitter, inv_pmf] = pick(sampler.next_1d());
            connect_emitter(scene, sensor, *emitter, inv_pmf, sampler, spectral, film);
        }

        const auto [emitter, inv_pmf] = pick(sampler.next_1d());
        const Point2f u_dir = sampler.next_2d(), u_pos = sampler.next_2d();
        auto [ray, power] = emitter->sample_ray(u_pos, u_dir, spectral.lambda);
        Color3f throughput = power * inv_pmf;
        if (throughput.is_black() || !throughput.is_finite()) return;
        // The polarized mode's light: unpolarised as it leaves the emitter (`throughput` is
        // then its S0).
        Stokes light = Stokes::unpolarized(throughput);

        const BSDFContext ctx(TransportMode::Importance);
        SurfaceInteraction si;
        if (!scene.ray_intersect(ray, si)) return;
        float eta = 1.f;
        for (uint32_t depth = 1; depth < m_max_depth;) {
            const BSDF *bsdf = si.bsdf();
            if (!bsdf) return;
            const bool polarizing = Polarized && has_flag(bsdf->flags(), BSDFFlags::Polarizing);
            // ---- Connect this vertex to the sensor ----
            {
                auto [ds, importance] = sensor.sample_direction(si, sampler.next_2d());
                if (!importance.is_black()) {
                    const Vector3f wo = si.to_local(ds.d);
                    const float correction = shading_correction(si, ds.d, wo);
                    if (correction > 0.f && !scene.ray_test(si.spawn_ray_to(ds.p))) {
                        Color3f arriving; // S0 of the light leaving towards the sensor
                        if (polarizing) {
                            const Mueller M = bsdf->eval_pdf_polarized(ctx, si, wo).first;
                            arriving = (mueller::to_world(si.sh_frame, M, -si.wi, wo) * light).s[0];
                        } else {
                            arriving = throughput * bsdf->eval(ctx, si, wo);
                        }
                        spectral.splat(film, ds.uv, arriving * importance * correction);
                    }
                }
            }

            // ---- BSDF sampling: the next segment of the light path ----
            const float sample1 = sampler.next_1d();
            const Point2f sample2 = sampler.next_2d();
            BSDFSample bs;
            Color3f weight;
            Mueller M;
            if (polarizing) {
                std::tie(bs, M) = bsdf->sample_polarized(ctx, si, sample1, sample2);
                weight = M.unpolarized();
            } else {
                std::tie(bs, weight) = bsdf->sample(ctx, si, sample1, sample2);
            }
            if (weight.is_black()) return;
            const Vector3f wo_world = si.to_world(bs.wo);
            const float correction = shading_correction(si, wo_world, bs.wo);
            if (!(correction > 0.f)) return;
            if constexpr (Polarized) {
                if (polarizing)
                    light = mueller::to_world(si.sh_frame, M, -si.wi, bs.wo) * light;
                else if (has_flag(bs.sampled_type, BSDFFlags::Null))
                    light = light * weight; // passed through unchanged
                else
                    light = Stokes::unpolarized(light.s[0] * weight);
                light = light * Color3f(correction);
                throughput = light.s[0];
            } else {
                throughput *= weight * correction;
            }
            eta *= bs.eta;
            const float throughput_max = throughput.max();
            if (!(throughput_max > 0.f) || !std::isfinite(throughput_max)) return;

            Ray next = si.spawn_ray(wo_world);
            if (!scene.ray_intersect(next, si)) return;
            ++depth;
            // A stop (Ctrl-C, timeout) ends even a path that would bounce for hours (a closed
            // mirror without Russian roulette); the render drops the unit of this path.
            if (render_should_stop(depth)) return;
            // ---- Russian roulette (on the power the path carries, as Mitsuba does) ----
            if (depth > m_rr_depth) {
                const float q = std::min(throughput.max() * eta * eta, 0.95f);
                if (!(sampler.next_1d() < q)) return;
                throughput /= q;
                if constexpr (Polarized) light = light * Color3f(1.f / q);
            }
        }
    }

    /// Adjoint shading-normal correction |cos_sh(wi) (wo . n_g)| / |cos_sh(wo) (wi . n_g)|
    /// (Veach 1997, eq. 5.19), or 0 when wi or wo lies on different sides for the geometric and
    /// the shading normal (light leaks).
    static float shading_correction(const SurfaceInteraction &si, const Vector3f &wo_world,
                                    const Vector3f &wo_local) {
        const float wi_dot_ng = dot(si.n, si.to_world(si.wi));
        const float wo_dot_ng = dot(si.n, wo_world);
        const float cos_wi = Frame::cos_theta(si.wi), cos_wo = Frame::cos_theta(wo_local);
        if (!(wi_dot_ng * cos_wi > 0.f) || !(wo_dot_ng * cos_wo > 0.f)) return 0.f;
        return std::abs((cos_wi * wo_dot_ng) / (cos_wo * wi_dot_ng));
    }

    /// Emitters seen directly: a point on the emitter's shape connected to the sensor, weighted
    /// by the emitted radiance towards the sensor and the emitter's cosine.
    void connect_emitter(const Scene &scene, const Sensor &sensor, const Emitter &emitter,
                         float inv_pmf, Sampler &sampler, const Spectral &spectral,
                         SplatTarget &film) const {
        const Point2f u_pos = sampler.next_2d(), u_sensor = sampler.next_2d();
        if (emitter.is_infinite()) {
            if (!emitter.is_delta())
                connect_environment(scene, sensor, emitter, inv_pmf, u_pos, u_sensor, spectral,
                                    film);
            return;
        }
        // Point and spot lights are invisible to a camera; only emitters on shapes are seen.
        const Shape *shape = emitter.shape();
        if (emitter.is_delta() || !shape) return;
        PositionSample ps = shape->sample_position(u_pos);
        if (!(ps.pdf > 0.f)) return;
        SurfaceInteraction si;
        si.p = ps.p;
        si.n = ps.n;
        si.uv = ps.uv;
        si.sh_frame = Frame(ps.n);
        si.shape = shape;
        si.t = 0.f;
        si.wavelengths = spectral.lambda;
        auto [ds, importance] = sensor.sample_direction(si, u_sensor);
        if (importance.is_black()) return;
        si.wi = si.to_local(ds.d);
        const float cos_theta = Frame::cos_theta(si.wi);
        if (!(cos_theta > 0.f)) return;
        Color3f L = emitter.eval(si);
        if (L.is_black()) return;
        if (scene.ray_test(si.spawn_ray_to(ds.p))) return;
        spectral.splat(film, ds.uv, L * (cos_theta * inv_pmf / ps.pdf) * importance);
    }

    /// An environment seen directly: a direction sampled by the emitter from the sensor's
    /// position gives a far point (on a sphere around that position, facing it, beyond the
    /// scene's bounding sphere), which is
    /// connected to the sensor like a point of a surface, with the area density pdf / dist² of
    /// that sphere and no cosine. The radiance is the environment's along the connection.
    void connect_environment(const Scene &scene, const Sensor &sensor, const Emitter &emitter,
                             float inv_pmf, const Point2f &u_pos, const Point2f &u_sensor,
                             const Spectral &spectral, SplatTarget &film) const {
        Interaction ref;
        ref.p = sensor.to_world().apply_point(Point3f(0.f));
        ref.n = Normal3f(0.f);
        ref.t = 0.f;
        ref.wavelengths = spectral.lambda;
        auto [eds, eweight] = emitter.sample_direction(ref, u_pos);
        if (!(eds.pdf > 0.f) || eweight.is_black()) return;
        // The far point, outside the scene's bounding sphere wherever the sensor is (the
        // emitter's own point assumes a reference point inside it).
        const BoundingBox3f &bbox = scene.bbox();
        const Point3f centre = bbox.valid() ? bbox.center() : Point3f(0.f);
        const float radius = bbox.valid() ? bbox.bounding_sphere_radius() : 0.f;
        const float dist = 2.f * std::max(radius, 1.f) + norm(ref.p - centre);
        const float dist2 = dist * dist;
        if (!std::isfinite(dist2)) return;
        SurfaceInteraction si;
        si.p = ref.p + eds.d * dist;
        si.n = -eds.d;
        si.sh_frame = Frame(si.n);
        si.t = 0.f;
        auto [ds, importance] = sensor.sample_direction(si, u_sensor);
        if (importance.is_black() || !(dot(ds.d, si.n) > 0.f)) return;
        if (scene.ray_test(si.spawn_ray_to(ds.p))) return;
        // The radiance a camera ray from the sensor point along -ds.d would find.
        SurfaceInteraction miss;
        Ray camera_ray(ds.p, -ds.d);
        camera_ray.wavelengths = spectral.lambda;
        Scene::escaped(camera_ray, miss);
        const Color3f L = emitter.eval(miss);
        spectral.splat(film, ds.uv, L * (dist2 * inv_pmf / eds.pdf) * importance);
    }

    uint32_t m_max_depth;
    uint32_t m_rr_depth;
    bool m_hide_emitters;
    bool m_spectral, m_polarized;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::ParticleTracer, Integrator, "ptracer",
                          "Particle tracer: light paths connected to the sensor", DOC,
                          ::facet::AllModes)
