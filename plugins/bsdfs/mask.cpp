static const char *DOC = R"DOC(
# mask: opacity mask (cut-outs such as leaves or fences)

Blends a nested BSDF with a perfectly transparent surface: with probability `opacity` the light
interacts with the nested BSDF, otherwise it passes straight through (wo = −wi) as if the surface
were not there. The pass-through is a Null lobe, so integrators treat it as a continuation of the
ray rather than a scattering event. eval and pdf are the nested BSDF's scaled by the opacity;
a sampled pass-through has the discrete probability 1 − opacity and weight 1.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| opacity | float or texture | 0.5 | Fraction of light that interacts with the nested BSDF, in [0, 1] (0 = invisible, 1 = opaque) |
| (nested bsdf) | bsdf | — | The BSDF of the opaque part (exactly one) |

Components: the nested BSDF's components, then the pass-through (Null, both sides).

```xml
<bsdf type="mask">
    <texture type="bitmap" name="opacity">
        <string name="filename" value="leaf_alpha.png"/>
        <boolean name="raw" value="true"/>
    </texture>
    <bsdf type="twosided">
        <bsdf type="diffuse"/>
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

class Mask final : public ForwardingBSDF<Mask> {
    friend class ForwardingBSDF<Mask>;

public:
    explicit Mask(const Properties &props) {
        for (const auto &[name, obj] : props.objects()) {
            auto bsdf = std::dynamic_pointer_cast<BSDF>(obj);
            if (!bsdf) continue;
            if (m_nested)
                FACET_THROW_AT(props.location(),
                               "mask takes exactly one nested BSDF, found a "
                               "second (\"{}\")",
                               name);
            m_nested = bsdf;
            props.mark_queried(name);
        }
        if (!m_nested) FACET_THROW_AT(props.location(), "mask needs a nested BSDF");

        m_opacity = props.texture("opacity", 0.5f);
        if (!m_opacity->is_spatially_varying()) {
            float value = m_opacity->mean().mean();
            if (!(value >= 0.f && value <= 1.f))
                FACET_THROW_AT(props.has("opacity") ? props.location("opacity") : props.location(),
                               "mask: opacity must be in [0, 1], found {}", value);
        }

        std::vector<BSDFFlags> components;
        for (size_t i = 0; i < m_nested->component_count(); ++i)
            components.push_back(m_nested->flags(i));
        BSDFFlags null = BSDFFlags::Null | BSDFFlags::FrontSide | BSDFFlags::BackSide;
        if (m_opacity->is_spatially_varying()) null |= BSDFFlags::SpatiallyVarying;
        components.push_back(null);
        set_components(std::move(components));
        m_null_index = uint32_t(component_count() - 1);
    }

    Color3f eval(const BSDFContext &ctx, const SurfaceInteraction &si,
                 const Vector3f &wo) const override {
        if (!nested_enabled(ctx)) return Color3f(0.f);
        return m_nested->eval(ctx, si, wo) * opacity(si);
    }

    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
              const Vector3f &wo) const override {
        bool has_null = ctx.is_enabled(BSDFFlags::Null, m_null_index);
        bool has_nested = nested_enabled(ctx);
        if (!has_nested) return 0.f;
        return m_nested->pdf(ctx, si, wo) * selection_opacity(opacity(si), has_null, has_nested);
    }

    Color3f eval_null_transmission(const SurfaceInteraction &si) const override {
        return Color3f(1.f - opacity(si)) + m_nested->eval_null_transmission(si) * opacity(si);
    }

    Color3f eval_diffuse_reflectance(const SurfaceInteraction &si) const override {
        return m_nested->eval_diffuse_reflectance(si);
    }

    void parameters_changed() override { m_nested->parameters_changed(); }

    bool prefetch(const SurfaceInteraction &si) const override {
        // Every one is told, whatever the others said.
        bool started = facet::prefetch(m_opacity, si);
        started |= m_nested->prefetch(si);
        return started;
    }

    std::string to_string() const override {
        return fmt::format("Mask[opacity = {}, nested = {}]", m_opacity->to_string(),
                           m_nested->to_string());
    }

private:
    template <typename V>
    std::pair<BSDFSample, V> sample_impl(const BSDFContext &ctx, const SurfaceInteraction &si,
                                         float sample1, const Point2f &sample2) const {
        bool has_null = ctx.is_enabled(BSDFFlags::Null, m_null_index);
        bool has_nested = nested_enabled(ctx);
        BSDFSample bs;
        if (!has_null && !has_nested) return {bs, V{}};

        float alpha = opacity(si);
        // With one part disabled the other is always taken and carries its share in the weight.
        float p_nested = selection_opacity(alpha, has_null, has_nested);
        if (sample1 < p_nested) {
            // Reuse sample1 for the nested BSDF's own lobe choice.
            auto [nested_bs, weight] = sample_as<V>(
                *m_nested, ctx, si, std::min(sample1 / p_nested, OneMinusEpsilon), sample2);
            // Value and density scale by alpha and p_nested: alpha·f / (p_nested·pdf).
            nested_bs.pdf *= p_nested;
            if (p_nested != alpha) weight = weight * (alpha / p_nested);
            return {nested_bs, weight};
        }
        bs.wo = -si.wi;
        bs.pdf = 1.f - p_nested;
        bs.eta = 1.f;
        bs.sampled_type = BSDFFlags::Null;
        bs.sampled_component = m_null_index;
        // Value (1 − opacity) over its probability (1 − opacity, or 1 when alone).
        if (!(bs.pdf > 0.f) || alpha >= 1.f) return {bs, V{}};
        return {bs, null_weight<V>(Color3f((1.f - alpha) / bs.pdf))};
    }

    template <typename V> std::pair<V, float>
    eval_pdf_impl(const BSDFContext &ctx, const SurfaceInteraction &si, const Vector3f &wo) const {
        bool has_null = ctx.is_enabled(BSDFFlags::Null, m_null_index);
        bool has_nested = nested_enabled(ctx);
        if (!has_nested) return {V{}, 0.f};
        auto [value, pdf] = eval_pdf_as<V>(*m_nested, ctx, si, wo);
        float alpha = opacity(si);
        return {value * alpha, pdf * selection_opacity(alpha, has_null, has_nested)};
    }

    float opacity(const SurfaceInteraction &si) const {
        return clamp(m_opacity->eval_1(si), 0.f, 1.f);
    }

    /// True when the query may reach the nested BSDF (any component, or one of its own).
    bool nested_enabled(const BSDFContext &ctx) const {
        return ctx.component == uint32_t(-1) || ctx.component < m_null_index;
    }

    /// Probability that sample() hands the query to the nested BSDF: the opacity, or 0 / 1 when
    /// only one of the two parts is enabled.
    static float selection_opacity(float alpha, bool has_null, bool has_nested) {
        if (has_null != has_nested) return has_nested ? 1.f : 0.f;
        return alpha;
    }

    std::shared_ptr<BSDF> m_nested;
    std::shared_ptr<Texture> m_opacity;
    uint32_t m_null_index = 0;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Mask, BSDF, "mask",
                          "Opacity mask: a nested BSDF blended with a straight pass-through", DOC,
                          ::facet::AllModes)
