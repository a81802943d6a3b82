static const char *DOC = R"DOC(
# twosided: two-sided adapter for one-sided BSDFs

Most reflection models only scatter on the front side of a surface (the side the shading normal
points to) and are black from behind. `twosided` makes a surface reflect on both sides: with one
nested BSDF both sides look the same; with two, the first is used on the front side and the
second on the back side. The back side is evaluated by mirroring wi and wo through the surface
(z → −z), so the nested BSDF sees the back as its own front side.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| (nested bsdf) | bsdf | — | One or two nested BSDFs: the front side's, then (optionally) the back side's |
| allow_transmission | boolean | false | Accept nested BSDFs with transmission (whose back side is then defined by twosided, not by the nested BSDF) |

Components: the front BSDF's components (FrontSide), then the back BSDF's components
(BackSide); with a single nested BSDF, its components appear twice. A component index of the
back side is shifted down by the front BSDF's component count before it reaches the back BSDF.

```xml
<bsdf type="twosided">
    <bsdf type="diffuse">
        <rgb name="reflectance" value="0.8, 0.2, 0.2"/>
    </bsdf>
</bsdf>
```
)DOC";

#include "forwarding_bsdf.h"

#include <facet/bsdf.h>
#include <facet/plugin.h>
#include <facet/properties.h>

#include <fmt/format.h>

namespace facet {

class TwoSided final : public ForwardingBSDF<TwoSided> {
    friend class ForwardingBSDF<TwoSided>;

public:
    explicit TwoSided(const Properties &props) {
        std::vector<std::shared_ptr<BSDF>> nested;
        for (const auto &[name, obj] : props.objects()) {
            auto bsdf = std::dynamic_pointer_cast<BSDF>(obj);
            if (!bsdf) continue;
            if (nested.size() == 2)
                FACET_THROW_AT(props.location(),
                               "twosided takes at most two nested BSDFs (front "
                               "and back side), found a third (\"{}\")",
                               name);
            nested.push_back(bsdf);
            props.mark_queried(name);
        }
        if (nested.empty())
            FACET_THROW_AT(props.location(), "twosided needs a nested BSDF (one for both sides, or "
                                             "two: front then back)");
        m_front = nested[0];
        m_back = nested.size() == 2 ? nested[1] : nested[0];
        m_allow_transmission = props.get_bool("allow_transmission", false);

        std::vector<BSDFFlags> components;
        for (size_t i = 0; i < m_front->component_count(); ++i)
            components.push_back((m_front->flags(i) & ~BSDFFlags::BackSide) | BSDFFlags::FrontSide);
        for (size_t i = 0; i < m_back->component_count(); ++i)
            components.push_back((m_back->flags(i) & ~BSDFFlags::FrontSide) | BSDFFlags::BackSide);
        set_components(std::move(components));
        if (has_flag(m_flags, BSDFFlags::Transmission) && !m_allow_transmission)
            FACET_THROW_AT(props.location(),
                           "twosided: the nested BSDF transmits light ({}); only "
                           "reflecting BSDFs can be nested unless allow_transmission is true",
                           has_flag(m_front->flags(), BSDFFlags::Transmission)
                               ? m_front->to_string()
                               : m_back->to_string());
        m_front_count = uint32_t(m_front->component_count());
    }

    Color3f eval(const BSDFContext &ctx, const SurfaceInteraction &si,
                 const Vector3f &wo) const override {
        float cos_i = Frame::cos_theta(si.wi);
        if (cos_i > 0.f) {
            if (!front_enabled(ctx)) return Color3f(0.f);
            return m_front->eval(ctx, si, wo);
        }
        BSDFContext back_ctx;
        if (cos_i == 0.f || !back_context(ctx, back_ctx)) return Color3f(0.f);
        return m_back->eval(back_ctx, mirrored(si), mirror(wo));
    }

    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
              const Vector3f &wo) const override {
        float cos_i = Frame::cos_theta(si.wi);
        if (cos_i > 0.f) {
            if (!front_enabled(ctx)) return 0.f;
            return m_front->pdf(ctx, si, wo);
        }
        BSDFContext back_ctx;
        if (cos_i == 0.f || !back_context(ctx, back_ctx)) return 0.f;
        return m_back->pdf(back_ctx, mirrored(si), mirror(wo));
    }

    Color3f eval_null_transmission(const SurfaceInteraction &si) const override {
        float cos_i = Frame::cos_theta(si.wi);
        if (cos_i > 0.f) return m_front->eval_null_transmission(si);
        return cos_i < 0.f ? m_back->eval_null_transmission(mirrored(si)) : Color3f(0.f);
    }

    Color3f eval_diffuse_reflectance(const SurfaceInteraction &si) const override {
        float cos_i = Frame::cos_theta(si.wi);
        if (cos_i >= 0.f) return m_front->eval_diffuse_reflectance(si);
        return m_back->eval_diffuse_reflectance(mirrored(si));
    }

    void parameters_changed() override {
        m_front->parameters_changed();
        if (m_back != m_front) m_back->parameters_changed();
    }

    bool prefetch(const SurfaceInteraction &si) const override {
        // The side eval() and sample() will query (the back one at the mirrored si, same uv).
        return (Frame::cos_theta(si.wi) > 0.f ? m_front : m_back)->prefetch(si);
    }

    std::string to_string() const override {
        if (m_back == m_front)
            return fmt::format("TwoSided[{}, allow_transmission = {}]", m_front->to_string(),
                               m_allow_transmission);
        return fmt::format("TwoSided[front = {}, back = {}, allow_transmission = {}]",
                           m_front->to_string(), m_back->to_string(), m_allow_transmission);
    }

private:
    /// sample() and sample_polarized() (ForwardingBSDF): the side's BSDF; in the polarized mode
    /// the back side's matrix is passed on in the mirrored frame, as Mitsuba 3 does.
    template <typename V>
    std::pair<BSDFSample, V> sample_impl(const BSDFContext &ctx, const SurfaceInteraction &si,
                                         float sample1, const Point2f &sample2) const {
        float cos_i = Frame::cos_theta(si.wi);
        if (cos_i > 0.f) {
            if (!front_enabled(ctx)) return {BSDFSample(), V{}};
            return sample_as<V>(*m_front, ctx, si, sample1, sample2);
        }
        BSDFContext back_ctx;
        if (cos_i == 0.f || !back_context(ctx, back_ctx)) return {BSDFSample(), V{}};
        auto [bs, weight] = sample_as<V>(*m_back, back_ctx, mirrored(si), sample1, sample2);
        bs.wo.z = -bs.wo.z;
        if (bs.sampled_component != uint32_t(-1)) bs.sampled_component += m_front_count;
        return {bs, weight};
    }

    template <typename V> std::pair<V, float>
    eval_pdf_impl(const BSDFContext &ctx, const SurfaceInteraction &si, const Vector3f &wo) const {
        float cos_i = Frame::cos_theta(si.wi);
        if (cos_i > 0.f) {
            if (!front_enabled(ctx)) return {V{}, 0.f};
            return eval_pdf_as<V>(*m_front, ctx, si, wo);
        }
        BSDFContext back_ctx;
        if (cos_i == 0.f || !back_context(ctx, back_ctx)) return {V{}, 0.f};
        return eval_pdf_as<V>(*m_back, back_ctx, mirrored(si), mirror(wo));
    }

    static Vector3f mirror(const Vector3f &v) { return {v.x, v.y, -v.z}; }
    static SurfaceInteraction mirrored(const SurfaceInteraction &si) {
        SurfaceInteraction back = si;
        back.wi = mirror(si.wi);
        return back;
    }

    /// False when the requested component belongs to the back side.
    bool front_enabled(const BSDFContext &ctx) const {
        return ctx.component == uint32_t(-1) || ctx.component < m_front_count;
    }

    /// The context for the back BSDF: component indices of the back side start after the front
    /// BSDF's. False when the requested component belongs to the front side.
    bool back_context(const BSDFContext &ctx, BSDFContext &back) const {
        back = ctx;
        if (ctx.component == uint32_t(-1)) return true;
        if (ctx.component < m_front_count) return false;
        back.component = ctx.component - m_front_count;
        return true;
    }

    std::shared_ptr<BSDF> m_front, m_back;
    uint32_t m_front_count = 0;
    bool m_allow_transmission = false;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::TwoSided, BSDF, "twosided",
                          "Two-sided adapter: the same or a second BSDF on the back side", DOC,
                          ::facet::AllModes)
