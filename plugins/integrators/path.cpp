static const char *DOC = R"DOC(
# path: unidirectional path tracer

Traces paths from the camera. At every non-specular vertex it samples an emitter (next event
estimation) and the BSDF, and weights both with multiple importance sampling (power heuristic).
Emitters found by BSDF sampling after a specular bounce get full weight. After `rr_depth`
bounces, Russian roulette ends paths whose throughput has become small.

On a BSDF with a delta lobe beside smooth ones (a plastic's coat over its diffuse base), the light
the delta lobe's one direction sees directly (the sky, an area light) is counted in every sample,
with the lobe's whole weight, whichever lobe the sample then follows; a path that follows the
lobe does not count it again. Mitsuba counts it only in the samples that follow the lobe: the
expected image is the same, with less noise where such a coat mirrors something bright (the
material preview: 0.74x the squared error at equal samples), for one more ray per vertex that
does not follow the coat (a visibility test where the scene's only emitters are at infinity).
BSDFs opt in with `SeparableDelta` on their delta lobes (the SDK's bsdf.h); glass, whose lobes
are all delta, keeps its one random lobe.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| max_depth | integer | -1 | Longest path, in segments: -1 is unbounded, 1 shows only directly visible emitters, 2 adds direct illumination, 3 one indirect bounce, ... |
| rr_depth | integer | 5 | Depth from which Russian roulette may end a path (at least 1) |
| hide_emitters | boolean | false | Hide emitters (area lights and the environment) seen directly by the camera |
| timeout | float | -1 | Stop after this many seconds and develop what is done (like Ctrl-C); <= 0: no limit |
| samples_per_pass | integer | (all) | Render in passes over the image of this many samples per pixel (must divide the sample count) |
| block_size | integer | 0 | Side of the square image blocks, in pixels; 0 chooses 32 |

```xml
<integrator type="path">
    <integer name="max_depth" value="8"/>
</integrator>
```
)DOC";

#include <facet/assert.h>
#include <facet/bsdf.h>
#include <facet/emitter.h>
#include <facet/frame.h>
#include <facet/integrator.h>
#include <facet/mis.h>
#include <facet/mode.h>
#include <facet/mueller.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/sampler.h>
#include <facet/scene.h>
#include <facet/shape.h>

#include <fmt/format.h>

#include <limits>
#include <new>
#include <tuple>
#include <type_traits>

namespace facet {

class PathIntegrator final : public SamplingIntegrator {
public:
    explicit PathIntegrator(const Properties &props) : SamplingIntegrator(props) {
        m_max_depth = read_max_depth(props, "path");
        m_rr_depth = read_rr_depth(props, "path");
        m_hide_emitters = props.get_bool("hide_emitters", false);
        m_polarized = is_polarized(props.mode());
    }

    Color3f sample(const Scene &scene, Sampler &sampler, const Ray &camera_ray,
                   float * /*aovs*/) const override {
        if (m_polarized) return trace<true>(scene, sampler, camera_ray).s[0];
        return trace<false>(scene, sampler, camera_ray);
    }

    Color3f sample_from_hit(const Scene &scene, Sampler &sampler, const Ray &camera_ray,
                            const SurfaceInteraction &si, bool hit,
                            float * /*aovs*/) const override {
        const FirstHit first{&si, hit};
        if (m_polarized) return trace<true>(scene, sampler, camera_ray, first).s[0];
        return trace<false>(scene, sampler, camera_ray, first);
    }
    bool takes_first_hit() const override { return true; }

    Stokes sample_stokes(const Scene &scene, Sampler &sampler, const Ray &camera_ray,
                         float * /*aovs*/) const override {
        if (m_polarized) return trace<true>(scene, sampler, camera_ray);
        return Stokes::unpolarized(trace<false>(scene, sampler, camera_ray));
    }
    bool has_stokes() const override { return true; }

    std::string to_string() const override {
        return fmt::format("PathIntegrator[max_depth = {}, rr_depth = {}, hide_emitters = {}]",
                           m_max_depth == std::numeric_limits<uint32_t>::max()
                               ? std::string("-1")
                               : std::to_string(m_max_depth),
                           m_rr_depth, m_hide_emitters);
    }

private:
    static constexpr BSDFFlags DeltaLobes =
        BSDFFlags::DeltaReflection | BSDFFlags::DeltaTransmission;

    /// True when every delta lobe of `bsdf` is flagged SeparableDelta.
    static bool separable(const BSDF &bsdf) {
        if (!has_flag(bsdf.flags(), BSDFFlags::SeparableDelta)) return false;
        for (size_t k = 0; k < bsdf.component_count(); ++k)
            if (has_flag(bsdf.flags(k), DeltaLobes) &&
                !has_flag(bsdf.flags(k), BSDFFlags::SeparableDelta))
                return false;
        return true;
    }

    /// A plastic's coat (or any BSDF with a delta lobe and a smooth one) is followed only as
    /// often as the path's sample picks it, so the bright sky its mirror direction shows arrives
    /// in a few samples with a large weight. Instead, the light each delta lobe's one direction
    /// sees directly is added here to `result` (through `throughput`), with the lobe's whole
    /// weight, whichever lobe the path's sample `bs` follows; the path then does not count it
    /// again when it follows the lobe (`follows`). The lobe's ray is the next segment's when
    /// the path follows it: its hit is written to `next_si` and `next_hit`, and the function
    /// returns true. Otherwise one more ray (a visibility test where the scene's emitters are
    /// all at infinity). Only where every delta lobe is separable (BSDFFlags::SeparableDelta):
    /// sampled alone, it carries what the BSDF's own samples bring through it on average. Glass
    /// (delta lobes only) keeps its one random lobe: its second ray cost more than it saved.
    template <bool Polarized, typename Value, typename Throughput>
    bool count_delta_lobes(const Scene &scene, const BSDF &bsdf, const SurfaceInteraction &si,
                           const BSDFSample &bs, bool follows, float sample1,
                           const Point2f &sample2, bool polarizing, const Throughput &throughput,
                           Value &result, SurfaceInteraction &next_si, bool &next_hit) const {
        // Emitters that are neither at infinity nor surfaces (points, spots) count as surfaces
        // here: a lobe that is not followed then needs its closest hit.
        const bool surface_emitters = scene.emitters().size() > scene.environment_emitters().size();
        BSDFContext lobe_ctx;
        bool next_known = false;
        SurfaceInteraction lobe_si;
        for (uint32_t k = 0; k < uint32_t(bsdf.component_count()); ++k) {
            if (!has_flag(bsdf.flags(k), DeltaLobes)) continue;
            lobe_ctx.component = k;
            BSDFSample lobe;
            Color3f lobe_weight;
            Mueller lobe_mueller;
            if (polarizing) {
                std::tie(lobe, lobe_mueller) =
                    bsdf.sample_polarized(lobe_ctx, si, sample1, sample2);
                lobe_weight = lobe_mueller.unpolarized();
            } else {
                std::tie(lobe, lobe_weight) = bsdf.sample(lobe_ctx, si, sample1, sample2);
            }
            FACET_ASSERT(lobe_weight.is_finite());
            if (lobe_weight.is_black()) continue;
            // The same ray as the path's next segment: the same hit.
            const bool next = follows && !next_known && lobe.wo == bs.wo;
            const Ray lobe_ray = si.spawn_ray(si.to_world(lobe.wo));
            SurfaceInteraction &seen = next ? next_si : lobe_si;
            bool hit;
            if (next || surface_emitters) {
                hit = scene.ray_intersect(lobe_ray, seen);
            } else {
                // Only the sky can give light here: whether the ray leaves is enough.
                if (scene.ray_test(lobe_ray)) continue;
                hit = false;
                Scene::escaped(lobe_ray, seen);
            }
            if (next) {
                next_known = true;
                next_hit = hit;
            }
            Color3f L(0.f);
            if (!hit)
                L = environment_mis(scene, seen, si, 1.f, true);
            else if (const Emitter *emitter = seen.shape ? seen.shape->emitter() : nullptr)
                L = emitter->eval(seen);
            if (L.is_black()) continue;
            if constexpr (Polarized) {
                if (polarizing)
                    result +=
                        throughput *
                        (mueller::to_world(si.sh_frame, lobe_mueller, -lobe.wo, si.wi).column(0) *
                         L);
                else
                    result += throughput.column(0) * (lobe_weight * L);
            } else {
                result += throughput * lobe_weight * L;
            }
        }
        return next_known;
    }

    /// A record made when it is first asked for: trace()'s next_si, which only delta lobes
    /// beside smooth ones need (a SurfaceInteraction's member initialisers zero it, for every
    /// sample).
    class LazyRecord {
    public:
        LazyRecord() {}
        SurfaceInteraction &get() {
            if (!m_made) {
                new (&m_storage.si) SurfaceInteraction();
                m_made = true;
            }
            return m_storage.si;
        }

    private:
        union Storage {
            Storage() {}
            SurfaceInteraction si;
        } m_storage;
        bool m_made = false;
    };

    /// The camera ray's closest hit when the caller has found it (sample_from_hit()); {} (null)
    /// when it has not. (No member initialisers: clang refuses them in a default argument of
    /// the enclosing class.)
    struct FirstHit {
        const SurfaceInteraction *si;
        bool hit;
    };

    /// The path's radiance: a colour, or in the polarized mode (Polarized) the Stokes vector of
    /// the light arriving along the camera ray. The polarized path's throughput is a Mueller
    /// matrix in the world's implicit frames (mueller.h): the product of the BSDF matrices along
    /// the path, each turned from its local frame (mueller::to_world()); unpolarised emitted
    /// light adds its first column times the radiance.
    template <bool Polarized>
    std::conditional_t<Polarized, Stokes, Color3f> trace(const Scene &scene, Sampler &sampler,
                                                         const Ray &camera_ray,
                                                         const FirstHit &first = {}) const {
        using Value = std::conditional_t<Polarized, Stokes, Color3f>;
        using Throughput = std::conditional_t<Polarized, Mueller, Color3f>;
        if (m_max_depth == 0) return Value{};

        const BSDFContext ctx;
        Ray ray = camera_ray;
        Value result{};
        Throughput throughput;
        if constexpr (Polarized)
            throughput = Mueller::identity();
        else
            throughput = Color3f(1.f);
        float eta = 1.f;
        uint32_t depth = 0;
        // The camera ray's hit when the caller found it (else filled by the first query).
        SurfaceInteraction si = first.si ? *first.si : SurfaceInteraction();
        Interaction prev_si;     // the previous vertex: MIS only needs its position and normal
        Vector3f prev_side(0.f); // and the side its light samples were given (light_side())
        // The camera ray behaves like a delta bounce: whatever it hits is counted in full.
        float prev_bsdf_pdf = 1.f;
        bool prev_bsdf_delta = true;

        // The light a delta lobe sees may be counted already (count_delta_lobes()): the next
        // vertex, found by the lobe's ray, is then known (next_si), and its emission is not
        // counted again.
        // The camera ray's hit, when given, is known the same way.
        bool next_known = first.si != nullptr, next_hit = first.hit, emission_counted = false;
        LazyRecord next_si;

        for (;;) {
            bool hit;
            if (next_known) {
                hit = next_hit;
                next_known = false;
            } else {
                hit = scene.ray_intersect(ray, si);
            }
            bool count_emission = !(m_hide_emitters && depth == 0) && !emission_counted;
            emission_counted = false;

            // ---- Emission found by the previous BSDF sample (or by the camera ray) ----
            if (!hit) {
                if (count_emission)
                    add_emission(result, throughput,
                                 environment_mis(scene, si, prev_si, prev_bsdf_pdf, prev_bsdf_delta,
                                                 1.f, prev_side));
                break;
            }
            // The emitter and BSDF of the shape hit, read inline (si.emitter() and si.bsdf()
            // are calls into the library).
            const Shape *shape = si.shape;
            if (count_emission) {
                if (const Emitter *emitter = shape ? shape->emitter() : nullptr) {
                    Color3f L = emitter->eval(si);
                    if (!L.is_black()) {
                        float w = 1.f;
                        if (!prev_bsdf_delta) {
                            float em_pdf = scene.pdf_emitter_direction(
                                prev_si, direction_to(si, prev_si), LightSampling::MIS, prev_side);
                            w = mis_weight(prev_bsdf_pdf, em_pdf);
                        }
                        add_emission(result, throughput, L * w);
                    }
                }
            }

            if (depth + 1 >= m_max_depth) break;
            const BSDF *bsdf = shape ? shape->bsdf() : nullptr;
            if (!bsdf) break;

            // The samples are drawn in the dimension order emitter (2D), BSDF (1D, 2D), but the
            // BSDF is sampled first: its result is needed only for the next ray, so its chain of
            // dependent arithmetic runs while the emitter sample is built and traced. A BSDF
            // that varies over the surface is told to start loading what it will read (an image
            // texture's texels); when it did, it is sampled last, so that the light sample
            // overlaps the wait.
            const bool sample_emitter = has_flag(bsdf->flags(), BSDFFlags::Smooth);
            const bool loading =
                has_flag(bsdf->flags(), BSDFFlags::SpatiallyVarying) && bsdf->prefetch(si);
            const Vector3f side = light_side(*bsdf, si);
            const Point2f emitter_sample = sample_emitter ? sampler.draw_2d() : Point2f();
            float sample1 = sampler.draw_1d();
            Point2f sample2 = sampler.draw_2d();
            FACET_ASSERT(Frame::is_unit(si.wi));
            // In the polarized mode a BSDF that polarises gives Mueller matrices; the others'
            // colours depolarise (or pass the light unchanged, through a Null lobe).
            const bool polarizing = Polarized && has_flag(bsdf->flags(), BSDFFlags::Polarizing);
            BSDFSample bs;
            Color3f bsdf_weight;
            Mueller bsdf_mueller;
            auto sample_bsdf = [&] {
                if (polarizing) {
                    std::tie(bs, bsdf_mueller) = bsdf->sample_polarized(ctx, si, sample1, sample2);
                    FACET_ASSERT(bsdf_mueller.is_finite());
                    bsdf_weight = bsdf_mueller.unpolarized();
                } else {
                    std::tie(bs, bsdf_weight) = bsdf->sample(ctx, si, sample1, sample2);
                }
                FACET_ASSERT(bsdf_weight.is_finite());
            };
            if (!loading) sample_bsdf();

            // ---- Emitter sampling (pointless for purely specular BSDFs) ----
            // The shadow ray comes last: a sample the BSDF gives no weight (an emitter behind
            // the surface) costs none.
            if (sample_emitter) {
                auto [ds, em_weight] = scene.sample_emitter_direction(si, emitter_sample, false,
                                                                      LightSampling::MIS, side);
                FACET_ASSERT(ds.pdf >= 0.f && em_weight.is_finite());
                if (ds.pdf != 0.f && !em_weight.is_black()) {
                    Vector3f wo = si.to_local(ds.d);
                    FACET_ASSERT(Frame::is_unit(wo) && Frame::is_unit(si.wi));
                    Color3f f;
                    float bsdf_pdf;
                    Mueller f_mueller;
                    if (polarizing) {
                        std::tie(f_mueller, bsdf_pdf) = bsdf->eval_pdf_polarized(ctx, si, wo);
                        f = f_mueller.unpolarized();
                    } else {
                        std::tie(f, bsdf_pdf) = bsdf->eval_pdf(ctx, si, wo);
                    }
                    FACET_ASSERT(bsdf_pdf >= 0.f && f.is_finite());
                    if (!f.is_black() && scene.emitter_visible(si, ds)) {
                        float w = ds.delta ? 1.f : mis_weight(ds.pdf, bsdf_pdf);
                        if constexpr (Polarized) {
                            // The emitter's light is unpolarised: the first column of the
                            // BSDF's matrix, in the world's frames, is what leaves towards wi.
                            if (polarizing)
                                result += throughput *
                                          (mueller::to_world(si.sh_frame, f_mueller, -wo, si.wi)
                                               .column(0) *
                                           (em_weight * w));
                            else
                                result += throughput.column(0) * (f * em_weight * w);
                        } else {
                            result += throughput * f * em_weight * w;
                        }
                    }
                }
            }

            if (loading) sample_bsdf();

            // ---- Light seen through a delta lobe beside smooth ones (count_delta_lobes()) ----
            if (sample_emitter && has_flag(bsdf->flags(), DeltaLobes) && separable(*bsdf)) {
                // Every delta lobe is counted: if the path follows one, its light is.
                emission_counted = !bsdf_weight.is_black() && has_flag(bs.sampled_type, DeltaLobes);
                next_known = count_delta_lobes<Polarized>(scene, *bsdf, si, bs, emission_counted,
                                                          sample1, sample2, polarizing, throughput,
                                                          result, next_si.get(), next_hit);
            }

            // ---- BSDF sampling: the next segment of the path ----
            if (bsdf_weight.is_black()) break;
            FACET_ASSERT(bs.pdf >= 0.f && Frame::is_unit(bs.wo));

            if constexpr (Polarized) {
                if (polarizing)
                    throughput =
                        throughput * mueller::to_world(si.sh_frame, bsdf_mueller, -bs.wo, si.wi);
                else if (has_flag(bs.sampled_type, BSDFFlags::Null))
                    throughput = throughput * bsdf_weight; // passed through unchanged
                else
                    depolarize(throughput, bsdf_weight);
            } else {
                throughput *= bsdf_weight;
            }
            eta *= bs.eta;
            prev_si = si;
            prev_side = side;
            prev_bsdf_pdf = bs.pdf;
            prev_bsdf_delta = has_flag(bs.sampled_type, BSDFFlags::Delta);
            ray = si.spawn_ray(si.to_world(bs.wo));
            if (next_known) si = next_si.get(); // what `ray` hits, found above
            ++depth;
            // A stop (Ctrl-C, timeout) ends even a path that would bounce for hours (a closed
            // mirror without Russian roulette); the render drops the unit of this sample.
            if (render_should_stop(depth)) break;

            // ---- Russian roulette; eta² undoes the radiance scaling of refraction ----
            float throughput_max = intensity(throughput).max();
            if (!(throughput_max > 0.f) || !std::isfinite(throughput_max)) break;
            if (depth >= m_rr_depth) {
                float q = std::min(throughput_max * eta * eta, 0.95f);
                if (!(sampler.draw_1d() < q)) break;
                if constexpr (Polarized)
                    throughput = throughput * Color3f(1.f / q);
                else
                    throughput /= q;
            }
        }
        return result;
    }

    /// Light `L` (unpolarised) reaching the camera through `throughput`.
    static void add_emission(Color3f &result, const Color3f &throughput, const Color3f &L) {
        result += throughput * L;
    }
    static void add_emission(Stokes &result, const Mueller &throughput, const Color3f &L) {
        result += throughput.column(0) * L;
    }
    /// throughput·depolarizer(weight): a BSDF that does not polarise keeps the first column.
    static void depolarize(Mueller &throughput, const Color3f &weight) {
        for (int i = 0; i < 4; ++i) {
            throughput.m[i][0] *= weight;
            for (int j = 1; j < 4; ++j) throughput.m[i][j] = Color3f(0.f);
        }
    }
    /// What Russian roulette weighs: the throughput of unpolarised light.
    static const Color3f &intensity(const Color3f &throughput) { return throughput; }
    static const Color3f &intensity(const Mueller &throughput) { return throughput.unpolarized(); }

    uint32_t m_max_depth;
    uint32_t m_rr_depth;
    bool m_hide_emitters;
    bool m_polarized;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::PathIntegrator, Integrator, "path",
                          "Path tracer with next event estimation and multiple importance sampling",
                          DOC, ::facet::AllModes)
