static const char *DOC = R"DOC(
# blendbsdf: linear blend of two BSDFs

Mixes two nested BSDFs with a weight that may vary over the surface:
f = (1 − weight)·f_first + weight·f_second. A weight of 0 gives the first BSDF, 1 the second.
Sampling picks one of the two with probability 1 − weight and weight and reuses the lobe choice
number for the picked BSDF. As in Mitsuba 3, every sample, a delta one included, is weighted by
the blend on its direction: the picked BSDF brings its sampled value and density (for a delta
lobe its discrete weight and probability, counted as if they were a value and a density), the
other BSDF its eval and pdf there, and the weight is the blended value over the blended density.
A mirror blended with a diffuse at weight w therefore returns (w + (1 − w)·ρ·cos/π) / (w +
(1 − w)·cos/π) rather than 1: Mitsuba's mirror share looks darker and tinted by the diffuse where
w is small. Renders depend on it; the sample stays flagged delta.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| weight | float or texture | (required) | Blend weight in [0, 1]: 0 = the first BSDF, 1 = the second (textures are clamped to [0, 1]) |
| (nested bsdf) | bsdf | — | Exactly two nested BSDFs, in order: first, second |

Components: the first BSDF's components, then the second's; the flags are their union.

```xml
<bsdf type="blendbsdf">
    <float name="weight" value="0.3"/>
    <bsdf type="diffuse"/>
    <bsdf type="roughconductor">
        <float name="alpha" value="0.2"/>
    </bsdf>
</bsdf>
```
)DOC";

#include "forwarding_bsdf.h"

#include <facet/bsdf.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

class BlendBSDF final : public ForwardingBSDF<BlendBSDF> {
    friend class ForwardingBSDF<BlendBSDF>;

public:
    explicit BlendBSDF(const Properties &props) {
        size_t count = 0;
        for (const auto &[name, obj] : props.objects()) {
            auto bsdf = std::dynamic_pointer_cast<BSDF>(obj);
            if (!bsdf) continue;
            if (count == 2)
                FACET_THROW_AT(props.location(),
                               "blendbsdf takes exactly two nested BSDFs, found "
                               "a third (\"{}\")",
                               name);
            m_nested[count++] = bsdf;
            props.mark_queried(name);
        }
        if (count != 2)
            FACET_THROW_AT(props.location(), "blendbsdf takes exactly two nested BSDFs, found {}",
                           count);

        // Required, as in Mitsuba 3 (it has no default blend).
        if (!props.has("weight"))
            FACET_THROW_AT(props.location(),
                           "blendbsdf needs a \"weight\" (a float or texture in [0, 1]: 0 gives "
                           "the first nested BSDF, 1 the second)");
        m_weight = props.texture("weight");
        if (!m_weight->is_spatially_varying()) {
            float value = m_weight->mean().mean();
            if (!(value >= 0.f && value <= 1.f))
                FACET_THROW_AT(props.location("weight"),
                               "blendbsdf: weight must be in [0, 1], found {}", value);
        }

        std::vector<BSDFFlags> components;
        for (const auto &b : m_nested)
            for (size_t i = 0; i < b->component_count(); ++i) {
                // A delta sample here carries the other BSDF's value too (as in Mitsuba), not
                // its lobe's weight alone: not separable.
                BSDFFlags f = b->flags(i) & ~BSDFFlags::SeparableDelta;
                if (m_weight->is_spatially_varying()) f |= BSDFFlags::SpatiallyVarying;
                components.push_back(f);
            }
        set_components(std::move(components));
        m_first_count = uint32_t(m_nested[0]->component_count());
    }

    Color3f eval(const BSDFContext &ctx, const SurfaceInteraction &si,
                 const Vector3f &wo) const override {
        float w = weight(si);
        if (ctx.component != uint32_t(-1)) {
            BSDFContext sub;
            int which = route(ctx, sub);
            return m_nested[which]->eval(sub, si, wo) * (which == 0 ? 1.f - w : w);
        }
        Color3f result(0.f);
        if (w < 1.f) result += m_nested[0]->eval(ctx, si, wo) * (1.f - w);
        if (w > 0.f) result += m_nested[1]->eval(ctx, si, wo) * w;
        return result;
    }

    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
              const Vector3f &wo) const override {
        float w = weight(si);
        if (ctx.component != uint32_t(-1)) {
            BSDFContext sub;
            int which = route(ctx, sub);
            return m_nested[which]->pdf(sub, si, wo);
        }
        float result = 0.f;
        if (w < 1.f) result += m_nested[0]->pdf(ctx, si, wo) * (1.f - w);
        if (w > 0.f) result += m_nested[1]->pdf(ctx, si, wo) * w;
        return result;
    }

    Color3f eval_null_transmission(const SurfaceInteraction &si) const override {
        float w = weight(si);
        return m_nested[0]->eval_null_transmission(si) * (1.f - w) +
               m_nested[1]->eval_null_transmission(si) * w;
    }

    Color3f eval_diffuse_reflectance(const SurfaceInteraction &si) const override {
        float w = weight(si);
        return m_nested[0]->eval_diffuse_reflectance(si) * (1.f - w) +
               m_nested[1]->eval_diffuse_reflectance(si) * w;
    }

    void parameters_changed() override {
        m_nested[0]->parameters_changed();
        m_nested[1]->parameters_changed();
    }

    bool prefetch(const SurfaceInteraction &si) const override {
        // Every one is told, whatever the others said.
        bool started = facet::prefetch(m_weight, si);
        started |= m_nested[0]->prefetch(si);
        started |= m_nested[1]->prefetch(si);
        return started;
    }

    std::string to_string() const override {
        return fmt::format("BlendBSDF[weight = {}, first = {}, second = {}]", m_weight->to_string(),
                           m_nested[0]->to_string(), m_nested[1]->to_string());
    }

private:
    template <typename V>
    std::pair<BSDFSample, V> sample_impl(const BSDFContext &ctx, const SurfaceInteraction &si,
                                         float sample1, const Point2f &sample2) const {
        float w = weight(si);
        if (ctx.component != uint32_t(-1)) {
            // One component: only its BSDF is sampled, and carries its blend factor.
            BSDFContext sub;
            int which = route(ctx, sub);
            auto [bs, value] = sample_as<V>(*m_nested[which], sub, si, sample1, sample2);
            if (which == 1 && bs.sampled_component != uint32_t(-1))
                bs.sampled_component += m_first_count;
            return {bs, value * (which == 0 ? 1.f - w : w)};
        }

        // Pick the second BSDF with probability w and rescale sample1 for its own lobe choice.
        int which;
        float u;
        if (sample1 < w) {
            which = 1;
            u = sample1 / w;
        } else {
            which = 0;
            u = (sample1 - w) / (1.f - w);
        }
        u = clamp(u, 0.f, OneMinusEpsilon);
        float p_which = which == 1 ? w : 1.f - w;
        auto [bs, value] = sample_as<V>(*m_nested[which], ctx, si, u, sample2);
        if (which == 1 && bs.sampled_component != uint32_t(-1))
            bs.sampled_component += m_first_count;
        if (value.is_black() || !(p_which > 0.f)) return {bs, V{}};

        // As in Mitsuba 3, the sample is weighted by the blend on the sampled direction: the
        // picked BSDF contributes its own value and density (for a delta lobe, its discrete
        // weight and probability, treated like a value and a density), the other BSDF its eval
        // and pdf there. A delta sample thus picks up the other BSDF's smooth value too.
        float pdf_picked = bs.pdf;
        V f_picked = value * pdf_picked;
        auto [f_other, pdf_other] = eval_pdf_as<V>(*m_nested[1 - which], ctx, si, bs.wo);
        float blend_pdf = p_which * pdf_picked + (1.f - p_which) * pdf_other;
        V blend_value = f_picked * p_which + f_other * (1.f - p_which);
        if (!(blend_pdf > 0.f) || blend_value.is_black()) return {bs, V{}};
        bs.pdf = blend_pdf;
        return {bs, blend_value / blend_pdf};
    }

    template <typename V> std::pair<V, float>
    eval_pdf_impl(const BSDFContext &ctx, const SurfaceInteraction &si, const Vector3f &wo) const {
        float w = weight(si);
        if (ctx.component != uint32_t(-1)) {
            BSDFContext sub;
            int which = route(ctx, sub);
            auto [value, pdf] = eval_pdf_as<V>(*m_nested[which], sub, si, wo);
            return {value * (which == 0 ? 1.f - w : w), pdf};
        }
        V value{};
        float pdf = 0.f;
        if (w < 1.f) {
            auto [v0, p0] = eval_pdf_as<V>(*m_nested[0], ctx, si, wo);
            value += v0 * (1.f - w);
            pdf += p0 * (1.f - w);
        }
        if (w > 0.f) {
            auto [v1, p1] = eval_pdf_as<V>(*m_nested[1], ctx, si, wo);
            value += v1 * w;
            pdf += p1 * w;
        }
        return {value, pdf};
    }

    float weight(const SurfaceInteraction &si) const {
        return clamp(m_weight->eval_1(si), 0.f, 1.f);
    }

    /// The nested BSDF that owns ctx.component, and the context with the component renumbered
    /// for it.
    int route(const BSDFContext &ctx, BSDFContext &sub) const {
        sub = ctx;
        if (ctx.component < m_first_count) return 0;
        sub.component = ctx.component - m_first_count;
        return 1;
    }

    std::shared_ptr<BSDF> m_nested[2];
    std::shared_ptr<Texture> m_weight;
    uint32_t m_first_count = 0;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::BlendBSDF, BSDF, "blendbsdf",
                          "Linear blend of two BSDFs with a constant or textured weight", DOC,
                          ::facet::AllModes)
