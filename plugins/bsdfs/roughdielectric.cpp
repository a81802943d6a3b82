static const char *DOC = R"DOC(
# roughdielectric: rough dielectric interface (frosted or etched glass)

A boundary between two dielectrics made of tiny smooth facets whose normals follow a Beckmann
or GGX distribution (Walter et al. 2007): each facet reflects or refracts with its own Fresnel
term, which blurs both the reflection and the transmission. Both sides of the surface are
supported; the side the normal points to is the exterior.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| int_ior | float or string | bk7 (1.5046) | Interior index of refraction, a number or a material name (water, diamond, ...) |
| ext_ior | float or string | air (1.000277) | Exterior index of refraction, a number or a material name |
| distribution | string | beckmann | Microfacet distribution: beckmann or ggx |
| alpha | float or texture | 0.1 | Isotropic roughness (not together with alpha_u/alpha_v) |
| alpha_u | float or texture | 0.1 | Roughness along the tangent (anisotropic; requires alpha_v) |
| alpha_v | float or texture | 0.1 | Roughness along the bitangent (anisotropic; requires alpha_u) |
| sample_visible | boolean | true | Sample only the normals visible from wi (Heitz & d'Eon 2014), which lowers variance |
| specular_reflectance | spectrum or texture | 1.0 | Tint of the reflected light (for artistic control only) |
| specular_transmittance | spectrum or texture | 1.0 | Tint of the transmitted light (for artistic control only) |

Refracted radiance is scaled by (η_i/η_t)² in radiance transport; importance transport is not
scaled. Without visible-normal sampling, normals are drawn from a distribution widened by
1.2 − 0.2·√|cos θi| (Walter et al.), which reduces variance at grazing angles.

```xml
<bsdf type="roughdielectric">
    <string name="distribution" value="ggx"/>
    <float name="alpha" value="0.2"/>
    <string name="int_ior" value="bk7"/>
</bsdf>
```
)DOC";

#include <facet/bsdf.h>
#include <facet/fresnel.h>
#include <facet/ior.h>
#include <facet/microfacet.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

class RoughDielectric final : public BSDF {
public:
    explicit RoughDielectric(const Properties &props) {
        float int_ior = read_ior(props, "int_ior", "bk7");
        float ext_ior = read_ior(props, "ext_ior", "air");
        m_eta = int_ior / ext_ior;
        m_inv_eta = 1.f / m_eta;
        m_microfacet = read_microfacet(props);
        if (props.has("specular_reflectance"))
            m_specular_reflectance = props.texture("specular_reflectance", 1.f);
        if (props.has("specular_transmittance"))
            m_specular_transmittance = props.texture("specular_transmittance", 1.f);

        BSDFFlags common = BSDFFlags::FrontSide | BSDFFlags::BackSide;
        if (m_microfacet.is_anisotropic()) common |= BSDFFlags::Anisotropic;
        if (m_microfacet.is_spatially_varying() || varies(m_specular_reflectance) ||
            varies(m_specular_transmittance))
            common |= BSDFFlags::SpatiallyVarying;
        set_components({BSDFFlags::GlossyReflection | common,
                        BSDFFlags::GlossyTransmission | common | BSDFFlags::NonSymmetric});
    }

    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float sample1, const Point2f &sample2) const override {
        bool has_reflection = ctx.is_enabled(BSDFFlags::GlossyReflection, 0);
        bool has_transmission = ctx.is_enabled(BSDFFlags::GlossyTransmission, 1);
        BSDFSample bs;
        float cos_i = Frame::cos_theta(si.wi);
        if ((!has_reflection && !has_transmission) || cos_i == 0.f) return {bs, Color3f(0.f)};

        MicrofacetDistribution sample_distr = sampling_distribution(m_microfacet.at(si), cos_i);

        // Sample a normal as seen from wi mirrored into the upper hemisphere.
        Vector3f wi_up = si.wi * sign(cos_i);
        auto [m, pdf_m] = sample_distr.sample(wi_up, sample2);
        float wi_dot_m = dot(si.wi, m);
        // Facets facing away from wi cannot be hit (and would flip the Fresnel side).
        if (!(pdf_m > 0.f) || wi_dot_m * cos_i <= 0.f) return {bs, Color3f(0.f)};

        auto [F, cos_t, eta_it, eta_ti] = fresnel_dielectric(wi_dot_m, m_eta);

        // Lobe choice by the facet's Fresnel term; with one lobe enabled it is always taken.
        bool reflect_lobe = has_reflection && has_transmission ? sample1 < F : has_reflection;
        if (reflect_lobe) {
            bs.wo = facet::reflect(si.wi, m);
            bs.eta = 1.f;
            bs.sampled_type = BSDFFlags::GlossyReflection;
            bs.sampled_component = 0;
            if (Frame::cos_theta(bs.wo) * cos_i <= 0.f) return {bs, Color3f(0.f)};
        } else {
            bs.wo = refract(si.wi, m, cos_t, eta_ti);
            bs.eta = eta_it;
            bs.sampled_type = BSDFFlags::GlossyTransmission;
            bs.sampled_component = 1;
            if (Frame::cos_theta(bs.wo) * cos_i >= 0.f) return {bs, Color3f(0.f)};
        }

        // The weight (lobe factor · G1(wo, m) for visible normals, D·G·|wi·m| /
        // (D_s·|cos θi|·cos θm) for all normals, times η_ti² for radiance refraction) is evaluated
        // as eval/pdf at wo: recovering m from (wi, wo) is ill-conditioned in float near grazing
        // back-scattering, and this way bs.pdf is exactly what pdf() and MIS see.
        auto [value, pdf] = eval_pdf_impl<true, true>(ctx, si, bs.wo);
        if (!(pdf > 0.f) || value.is_black()) return {bs, Color3f(0.f)};
        bs.pdf = pdf;
        return {bs, value / pdf};
    }

    Color3f eval(const BSDFContext &ctx, const SurfaceInteraction &si,
                 const Vector3f &wo) const override {
        return eval_pdf_impl<true, false>(ctx, si, wo).first;
    }

    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
              const Vector3f &wo) const override {
        return eval_pdf_impl<false, true>(ctx, si, wo).second;
    }

    std::pair<Color3f, float> eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
                                       const Vector3f &wo) const override {
        return eval_pdf_impl<true, true>(ctx, si, wo);
    }

    float eta() const { return m_eta; }

    bool prefetch(const SurfaceInteraction &si) const override {
        // Every one is told, whatever the others said.
        bool started = facet::prefetch(m_specular_reflectance, si);
        started |= facet::prefetch(m_specular_transmittance, si);
        started |= m_microfacet.prefetch(si);
        return started;
    }

    std::string to_string() const override {
        return fmt::format("RoughDielectric[eta = {}, {}, specular_reflectance = {}, "
                           "specular_transmittance = {}]",
                           m_eta, m_microfacet.to_string(),
                           m_specular_reflectance ? m_specular_reflectance->to_string() : "1",
                           m_specular_transmittance ? m_specular_transmittance->to_string() : "1");
    }

private:
    /// Without visible-normal sampling, sample from a distribution widened towards grazing
    /// incidence (Walter et al. 2007, section 5.3); eval always uses the true roughness.
    static MicrofacetDistribution sampling_distribution(MicrofacetDistribution distr, float cos_i) {
        if (!distr.sample_visible()) distr.scale_alpha(1.2f - 0.2f * std::sqrt(std::abs(cos_i)));
        return distr;
    }

    template <bool Eval, bool Pdf> std::pair<Color3f, float>
    eval_pdf_impl(const BSDFContext &ctx, const SurfaceInteraction &si, const Vector3f &wo) const {
        float cos_i = Frame::cos_theta(si.wi), cos_o = Frame::cos_theta(wo);
        if (cos_i == 0.f || cos_o == 0.f) return {Color3f(0.f), 0.f};
        bool reflect_lobe = cos_i * cos_o > 0.f;
        bool has_reflection = ctx.is_enabled(BSDFFlags::GlossyReflection, 0);
        bool has_transmission = ctx.is_enabled(BSDFFlags::GlossyTransmission, 1);
        if (reflect_lobe ? !has_reflection : !has_transmission) return {Color3f(0.f), 0.f};

        // Relative IOR across the interface as seen from wi, and the generalised half vector
        // (Walter eq. 13 and 16), oriented towards the exterior.
        float eta = cos_i > 0.f ? m_eta : m_inv_eta;
        Vector3f m = normalize(si.wi + wo * (reflect_lobe ? 1.f : eta));
        m = m * sign(m.z);

        float wi_dot_m = dot(si.wi, m), wo_dot_m = dot(wo, m);
        // The microsurface and the macrosurface must agree on the side of both directions.
        if (wi_dot_m * cos_i <= 0.f || wo_dot_m * cos_o <= 0.f) return {Color3f(0.f), 0.f};

        MicrofacetDistribution distr = m_microfacet.at(si);
        float F = fresnel_dielectric(wi_dot_m, m_eta).F;

        Color3f value(0.f);
        if (Eval) {
            float D = distr.eval(m);
            if (D > 0.f) {
                float G = distr.G(si.wi, wo, m);
                if (reflect_lobe) {
                    // F·D·G / (4|cos θi|)  (already multiplied by |cos θo|)
                    value = Color3f(F * D * G / (4.f * std::abs(cos_i)));
                    if (m_specular_reflectance) value *= m_specular_reflectance->eval(si);
                } else {
                    // Walter eq. 21 times |cos θo|, with the η² radiance compression.
                    float scale = ctx.mode == TransportMode::Radiance ? sqr(1.f / eta) : 1.f;
                    value = Color3f(std::abs(scale * (1.f - F) * D * G * eta * eta * wi_dot_m *
                                             wo_dot_m / (cos_i * sqr(wi_dot_m + eta * wo_dot_m))));
                    if (m_specular_transmittance) value *= m_specular_transmittance->eval(si);
                }
            }
        }

        float pdf = 0.f;
        if (Pdf) {
            float dm_dwo = reflect_lobe ? 1.f / (4.f * wo_dot_m)
                                        : eta * eta * wo_dot_m / sqr(wi_dot_m + eta * wo_dot_m);
            MicrofacetDistribution sample_distr = sampling_distribution(distr, cos_i);
            pdf = sample_distr.pdf(si.wi * sign(cos_i), m);
            if (has_reflection && has_transmission) pdf *= reflect_lobe ? F : 1.f - F;
            pdf *= std::abs(dm_dwo);
        }
        return {value, pdf};
    }

    float m_eta, m_inv_eta;
    MicrofacetParameters m_microfacet;
    std::shared_ptr<Texture> m_specular_reflectance, m_specular_transmittance;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(
    facet::RoughDielectric, BSDF, "roughdielectric",
    "Rough dielectric interface with a Beckmann or GGX microfacet distribution", DOC,
    ::facet::AllModes)
