static const char *DOC = R"DOC(
# direct: direct illumination

Computes the light that reaches the camera after at most one reflection: emitters seen directly,
plus the light of the emitters reflected once by the first surface hit. At that surface it takes
`emitter_samples` emitter samples and `bsdf_samples` BSDF samples and combines them with multiple
importance sampling (power heuristic, weighted by the sample counts). Interreflections are
ignored.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| shading_samples | integer | 1 | Sets both emitter_samples and bsdf_samples |
| emitter_samples | integer | shading_samples | Emitter samples per camera sample |
| bsdf_samples | integer | shading_samples | BSDF samples per camera sample |
| hide_emitters | boolean | false | Hide emitters (area lights and the environment) seen directly by the camera |
| timeout | float | -1 | Stop after this many seconds and develop what is done (like Ctrl-C); <= 0: no limit |
| samples_per_pass | integer | (all) | Render in passes over the image of this many samples per pixel (must divide the sample count) |
| block_size | integer | 0 | Side of the square image blocks, in pixels; 0 chooses 32 |

`shading_samples` is only the default of the other two: with `shading_samples` 4 and
`bsdf_samples` 1, the integrator takes 4 emitter samples and 1 BSDF sample. At least one sample
of either kind is needed.

```xml
<integrator type="direct">
    <integer name="emitter_samples" value="4"/>
    <integer name="bsdf_samples" value="1"/>
</integrator>
```
)DOC";

#include <facet/bsdf.h>
#include <facet/emitter.h>
#include <facet/integrator.h>
#include <facet/mis.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/sampler.h>
#include <facet/scene.h>

#include <fmt/format.h>

namespace facet {

namespace {

uint32_t read_count(const Properties &props, const char *name, int64_t def) {
    int64_t v = props.get_int(name, def);
    if (v < 0 || v > 0xffff)
        FACET_THROW_AT(props.location(name), "direct: {} must be in [0, 65535], got {}", name, v);
    return uint32_t(v);
}

} // namespace

class DirectIntegrator final : public SamplingIntegrator {
public:
    explicit DirectIntegrator(const Properties &props) : SamplingIntegrator(props) {
        // As in Mitsuba 3, shading_samples is only the default of the two counts: a scene may
        // give it together with either of them (the one given wins).
        uint32_t shading = read_count(props, "shading_samples", 1);
        m_emitter_samples = read_count(props, "emitter_samples", shading);
        m_bsdf_samples = read_count(props, "bsdf_samples", shading);
        if (m_emitter_samples + m_bsdf_samples == 0)
            FACET_THROW_AT(props.location(),
                           "direct: at least one emitter or BSDF sample is needed");
        m_hide_emitters = props.get_bool("hide_emitters", false);

        float total = float(m_emitter_samples + m_bsdf_samples);
        m_frac_emitter = m_emitter_samples / total;
        m_frac_bsdf = m_bsdf_samples / total;
        m_weight_emitter = m_emitter_samples > 0 ? 1.f / m_emitter_samples : 0.f;
        m_weight_bsdf = m_bsdf_samples > 0 ? 1.f / m_bsdf_samples : 0.f;
        // Without BSDF samples the light samples stand alone; with them, MIS weighs the two.
        m_light_sampling = m_bsdf_samples > 0 ? LightSampling::MIS : LightSampling::Alone;
    }

    Color3f sample(const Scene &scene, Sampler &sampler, const Ray &ray,
                   float * /*aovs*/) const override {
        Color3f result(0.f);
        SurfaceInteraction si;
        bool hit = scene.ray_intersect(ray, si);

        // ---- Emitters seen directly ----
        if (!m_hide_emitters) {
            if (!hit) return environment_mis(scene, si, si, 0.f, true);
            if (const Emitter *emitter = si.emitter()) result += emitter->eval(si);
        }
        if (!hit) return result;

        const BSDFContext ctx;
        const BSDF *bsdf = si.bsdf();
        if (!bsdf) return result;

        // Light samples weighted by MIS are told the side the BSDF reflects to (if it does
        // only to one), and so are the densities BSDF samples are weighted with.
        const Vector3f side =
            m_light_sampling == LightSampling::MIS ? light_side(*bsdf, si) : Vector3f(0.f);

        // ---- Emitter sampling ----
        if (has_flag(bsdf->flags(), BSDFFlags::Smooth)) {
            for (uint32_t i = 0; i < m_emitter_samples; ++i) {
                // Up to 65535 samples: a stop (Ctrl-C, timeout) need not wait for them all.
                if (render_should_stop(i)) return result;
                // The shadow ray last: a sample the BSDF gives no weight costs none.
                auto [ds, em_weight] = scene.sample_emitter_direction(si, sampler.next_2d(), false,
                                                                      m_light_sampling, side);
                if (ds.pdf == 0.f || em_weight.is_black()) continue;
                Vector3f wo = si.to_local(ds.d);
                auto [f, bsdf_pdf] = bsdf->eval_pdf(ctx, si, wo);
                if (f.is_black() || !scene.emitter_visible(si, ds)) continue;
                // Densities of the two strategies scaled by their share of the samples.
                float w =
                    ds.delta ? 1.f : mis_weight(ds.pdf * m_frac_emitter, bsdf_pdf * m_frac_bsdf);
                result += f * em_weight * (w * m_weight_emitter);
            }
        }

        // ---- BSDF sampling ----
        for (uint32_t i = 0; i < m_bsdf_samples; ++i) {
            if (render_should_stop(i)) return result;
            float sample1 = sampler.next_1d();
            Point2f sample2 = sampler.next_2d();
            auto [bs, bsdf_weight] = bsdf->sample(ctx, si, sample1, sample2);
            if (bsdf_weight.is_black()) continue;
            bool delta = has_flag(bs.sampled_type, BSDFFlags::Delta);

            Ray bsdf_ray = si.spawn_ray(si.to_world(bs.wo));
            SurfaceInteraction si_bsdf;
            if (!scene.ray_intersect(bsdf_ray, si_bsdf)) {
                result += bsdf_weight *
                          environment_mis(scene, si_bsdf, si, bs.pdf * m_frac_bsdf, delta,
                                          m_frac_emitter, side) *
                          m_weight_bsdf;
                continue;
            }
            const Emitter *emitter = si_bsdf.emitter();
            if (!emitter) continue;
            Color3f L = emitter->eval(si_bsdf);
            if (L.is_black()) continue;
            float w = 1.f;
            if (!delta) {
                float em_pdf = scene.pdf_emitter_direction(si, direction_to(si_bsdf, si),
                                                           LightSampling::MIS, side);
                w = mis_weight(bs.pdf * m_frac_bsdf, em_pdf * m_frac_emitter);
            }
            result += bsdf_weight * L * (w * m_weight_bsdf);
        }
        return result;
    }

    std::string to_string() const override {
        return fmt::format("DirectIntegrator[emitter_samples = {}, bsdf_samples = {}, "
                           "hide_emitters = {}]",
                           m_emitter_samples, m_bsdf_samples, m_hide_emitters);
    }

private:
    uint32_t m_emitter_samples, m_bsdf_samples;
    float m_frac_emitter, m_frac_bsdf, m_weight_emitter, m_weight_bsdf;
    bool m_hide_emitters;
    LightSampling m_light_sampling;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::DirectIntegrator, Integrator, "direct",
                          "Direct illumination with emitter and BSDF sampling combined by MIS", DOC,
                          ::facet::AllModes)
