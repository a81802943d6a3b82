static const char *DOC = R"DOC(
# roughconductor: rough conductor (brushed or frosted metal)

A metal surface made of tiny mirror facets whose normals follow a Beckmann or GGX distribution
(Walter et al. 2007, "Microfacet models for refraction through rough surfaces"):
f = F(wi·h)·D(h)·G(wi, wo, h) / (4·cos θi·cos θo). The roughness α is the RMS slope of the facets
(0.01 is nearly smooth, 0.1 is glossy, 0.3 and above is rough); separate `alpha_u`/`alpha_v`
give anisotropic highlights stretched along the tangent directions. Only the front side
reflects (wrap the BSDF in `twosided` for two-sided surfaces).

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| distribution | string | beckmann | Microfacet distribution: beckmann or ggx |
| alpha | float or texture | 0.1 | Isotropic roughness (not together with alpha_u/alpha_v) |
| alpha_u | float or texture | 0.1 | Roughness along the tangent (anisotropic; requires alpha_v) |
| alpha_v | float or texture | 0.1 | Roughness along the bitangent (anisotropic; requires alpha_u) |
| sample_visible | boolean | true | Sample only the normals visible from wi (Heitz & d'Eon 2014), which lowers variance |
| material | string | none | Measured material (Ag, Al, Au, Cr, Cu, ..., as for `conductor`); none = ideal mirror |
| eta | spectrum or texture | 0.0 | Real part of the IOR (only without material; unbounded spectrum) |
| k | spectrum or texture | 1.0 | Imaginary part of the IOR (only without material; unbounded spectrum) |
| specular_reflectance | spectrum or texture | 1.0 | Tint of the reflection (for artistic control only) |

```xml
<bsdf type="roughconductor">
    <string name="material" value="Al"/>
    <string name="distribution" value="ggx"/>
    <float name="alpha_u" value="0.05"/>
    <float name="alpha_v" value="0.3"/>
</bsdf>
```
)DOC";

#include <facet/bsdf.h>
#include <facet/conductor_data.h>
#include <facet/fresnel.h>
#include <facet/microfacet.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

class RoughConductor final : public BSDF {
public:
    explicit RoughConductor(const Properties &props) {
        m_microfacet = read_microfacet(props);
        ConductorIOR ior = read_conductor_ior(props);
        m_material = ior.material;
        m_eta = ior.eta;
        m_k = ior.k;
        m_specular_reflectance = props.texture("specular_reflectance", 1.f);

        BSDFFlags flags = BSDFFlags::GlossyReflection | BSDFFlags::FrontSide |
                          BSDFFlags::Polarizing | BSDFFlags::WiSideOnly;
        if (m_microfacet.is_anisotropic()) flags |= BSDFFlags::Anisotropic;
        if (m_microfacet.is_spatially_varying() || varies(m_eta) || varies(m_k) ||
            varies(m_specular_reflectance))
            flags |= BSDFFlags::SpatiallyVarying;
        set_components({flags});
    }

    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float /*sample1*/,
                                          const Point2f &sample2) const override {
        BSDFSample bs;
        if (!sample_direction(ctx, si, sample2, bs)) return {bs, Color3f(0.f)};
        // The weight F·G1(wo, m) (visible normals) or F·G·(wi·m)/(cos θi·cos θm) (all normals)
        // is evaluated as eval/pdf at wo: near grazing back-scattering, recovering m from
        // (wi, wo) is ill-conditioned in float, and this way bs.pdf is exactly what pdf() and
        // MIS see for the same direction.
        auto [value, pdf] = eval_pdf(ctx, si, bs.wo);
        if (!(pdf > 0.f) || value.is_black()) return {bs, Color3f(0.f)};
        bs.pdf = pdf;
        return {bs, value / pdf};
    }

    std::pair<BSDFSample, Mueller> sample_polarized(const BSDFContext &ctx,
                                                    const SurfaceInteraction &si, float /*sample1*/,
                                                    const Point2f &sample2) const override {
        BSDFSample bs;
        if (!sample_direction(ctx, si, sample2, bs)) return {bs, Mueller{}};
        auto [value, pdf] = eval_pdf_polarized(ctx, si, bs.wo);
        if (!(pdf > 0.f) || value.unpolarized().is_black()) return {bs, Mueller{}};
        bs.pdf = pdf;
        return {bs, value * Color3f(1.f / pdf)};
    }

    Color3f eval(const BSDFContext &ctx, const SurfaceInteraction &si,
                 const Vector3f &wo) const override {
        return eval_pdf(ctx, si, wo).first;
    }

    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
              const Vector3f &wo) const override {
        float cos_i = Frame::cos_theta(si.wi), cos_o = Frame::cos_theta(wo);
        if (!ctx.is_enabled(BSDFFlags::GlossyReflection, 0) || cos_i <= 0.f || cos_o <= 0.f)
            return 0.f;
        Vector3f h = normalize(si.wi + wo);
        return m_microfacet.at(si).pdf(si.wi, h) / (4.f * dot(wo, h));
    }

    std::pair<Color3f, float> eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
                                       const Vector3f &wo) const override {
        Vector3f h;
        float value, pdf;
        if (!lobe(ctx, si, wo, h, value, pdf)) return {Color3f(0.f), 0.f};
        Color3f F = fresnel_conductor(dot(si.wi, h), m_eta->eval(si), m_k->eval(si));
        return {F * m_specular_reflectance->eval(si) * value, pdf};
    }

    /// The polarized mode: each microfacet reflects as the smooth conductor does, in the frames
    /// of its own plane of incidence.
    std::pair<Mueller, float> eval_pdf_polarized(const BSDFContext &ctx,
                                                 const SurfaceInteraction &si,
                                                 const Vector3f &wo) const override {
        Vector3f h;
        float value, pdf;
        if (!lobe(ctx, si, wo, h, value, pdf)) return {Mueller{}, 0.f};
        const bool radiance = ctx.mode == TransportMode::Radiance;
        const Vector3f wo_hat = radiance ? wo : si.wi, wi_hat = radiance ? si.wi : wo;
        Mueller F = mueller::specular_reflection(dot(wo_hat, h), m_eta->eval(si), m_k->eval(si));
        F = mueller::reflection_to_implicit(F, h, wo_hat, wi_hat);
        return {F * (m_specular_reflectance->eval(si) * value), pdf};
    }

    bool prefetch(const SurfaceInteraction &si) const override {
        // Every one is told, whatever the others said.
        bool started = facet::prefetch(m_eta, si);
        started |= facet::prefetch(m_k, si);
        started |= facet::prefetch(m_specular_reflectance, si);
        started |= m_microfacet.prefetch(si);
        return started;
    }

    std::string to_string() const override {
        return fmt::format("RoughConductor[{}, material = {}, eta = {}, k = {}, "
                           "specular_reflectance = {}]",
                           m_microfacet.to_string(), m_material, m_eta->to_string(),
                           m_k->to_string(), m_specular_reflectance->to_string());
    }

private:
    /// The lobe at wo without its Fresnel term and tint: the half vector h, f·cos θo / F =
    /// D·G / (4 cos θi), and the density; false where it is zero.
    bool lobe(const BSDFContext &ctx, const SurfaceInteraction &si, const Vector3f &wo, Vector3f &h,
              float &value, float &pdf) const {
        const float cos_i = Frame::cos_theta(si.wi), cos_o = Frame::cos_theta(wo);
        if (!ctx.is_enabled(BSDFFlags::GlossyReflection, 0) || cos_i <= 0.f || cos_o <= 0.f)
            return false;
        const MicrofacetDistribution distr = m_microfacet.at(si);
        h = normalize(si.wi + wo);
        const float D = distr.eval(h);
        if (D == 0.f) return false;
        value = D * distr.G(si.wi, wo, h) / (4.f * cos_i);
        pdf = distr.pdf(si.wi, h) / (4.f * dot(wo, h));
        return true;
    }

    /// Draws a microfacet normal and reflects wi about it into bs (all but the pdf); false when
    /// the sample fails.
    bool sample_direction(const BSDFContext &ctx, const SurfaceInteraction &si,
                          const Point2f &sample2, BSDFSample &bs) const {
        if (!ctx.is_enabled(BSDFFlags::GlossyReflection, 0) || Frame::cos_theta(si.wi) <= 0.f)
            return false;
        MicrofacetDistribution distr = m_microfacet.at(si);
        auto [m, pdf_m] = distr.sample(si.wi, sample2);
        if (!(pdf_m > 0.f) || dot(si.wi, m) <= 0.f) return false;
        bs.wo = facet::reflect(si.wi, m);
        bs.eta = 1.f;
        bs.sampled_type = BSDFFlags::GlossyReflection;
        bs.sampled_component = 0;
        return Frame::cos_theta(bs.wo) > 0.f;
    }

    MicrofacetParameters m_microfacet;
    std::string m_material;
    std::shared_ptr<Texture> m_eta, m_k, m_specular_reflectance;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::RoughConductor, BSDF, "roughconductor",
                          "Rough conductor with a Beckmann or GGX microfacet distribution", DOC,
                          ::facet::AllModes)
