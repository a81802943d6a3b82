static const char *DOC = R"DOC(
# pplastic: polarized plastic (rough dielectric coating over a diffuse base)

Mitsuba 3's polarized plastic (after Baek et al. 2018): a rough dielectric interface whose
microfacets (Beckmann or GGX) reflect a glossy lobe, over a diffuse base that the light reaches
and leaves through the interface. Unlike `roughplastic` it keeps no account of light trapped
under the coating: one refraction in, one diffuse bounce, one refraction out.

f_glossy·cos θo = s·F(wi·h)·D(h)·G(wi, wo, h)/(4 cos θi),
f_diffuse·cos θo = ρ·(1 − F(cos θi))·(1 − F(cos θo))·cos θo/π,

with F the dielectric Fresnel reflectance of η = int_ior/ext_ior. In the polarized mode both
lobes polarise: the glossy lobe reflects with the Fresnel matrix of each microfacet, and the
diffuse lobe is the light's refraction into the coating (the transmission matrix at cos θo),
depolarised by the base, then refracted out (at the refracted angle of wi), so light leaving a
pplastic at a grazing angle is partly polarised. In the other modes the values are the
matrices' intensities.

Sampling picks the glossy lobe with probability s/(s + d) of the mean reflectances (a visible
normal of the distribution, reflected), else a cosine-weighted direction; the weight is eval/pdf
of the mixture. Only the front side reflects.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| diffuse_reflectance | spectrum or texture | 0.5 | Albedo ρ of the diffuse base |
| specular_reflectance | spectrum or texture | 1.0 | Tint s of the glossy reflection (for artistic control only) |
| int_ior | float or string | polypropylene (1.49) | Interior index of refraction, a number or a material name |
| ext_ior | float or string | air (1.000277) | Exterior index of refraction, a number or a material name |
| distribution | string | beckmann | Microfacet distribution of the coating: beckmann or ggx |
| alpha | float or texture | 0.1 | Roughness of the coating (RMS slope) |
| alpha_u | float or texture | — | Roughness along the tangent (anisotropic; with alpha_v) |
| alpha_v | float or texture | — | Roughness along the bitangent (anisotropic; with alpha_u) |
| sample_visible | boolean | true | Sample only the normals visible from wi (Heitz & d'Eon 2014) |

Components: 0 = the glossy reflection (GlossyReflection), 1 = the diffuse base
(DiffuseReflection); both polarise. Equal interior and exterior IORs are an error.

```xml
<bsdf type="pplastic">
    <rgb name="diffuse_reflectance" value="0.05, 0.03, 0.1"/>
    <float name="alpha" value="0.06"/>
</bsdf>
```
)DOC";

#include <facet/bsdf.h>
#include <facet/fresnel.h>
#include <facet/ior.h>
#include <facet/microfacet.h>
#include <facet/mueller.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>
#include <facet/warp.h>

#include <fmt/format.h>

namespace facet {

class PolarizedPlastic final : public BSDF {
public:
    explicit PolarizedPlastic(const Properties &props) {
        m_microfacet = read_microfacet(props);
        const float int_ior = read_ior(props, "int_ior", "polypropylene");
        const float ext_ior = read_ior(props, "ext_ior", "air");
        if (int_ior == ext_ior)
            FACET_THROW_AT(props.location(),
                           "pplastic: int_ior and ext_ior must differ (both are {}), otherwise "
                           "there is no coating; use diffuse instead",
                           int_ior);
        m_eta = int_ior / ext_ior;
        m_diffuse_reflectance = props.texture("diffuse_reflectance", 0.5f);
        if (props.has("specular_reflectance"))
            m_specular_reflectance = props.texture("specular_reflectance", 1.f);

        const float d_mean = m_diffuse_reflectance->mean().mean();
        const float s_mean = m_specular_reflectance ? m_specular_reflectance->mean().mean() : 1.f;
        m_specular_sampling_weight = d_mean + s_mean > 0.f ? s_mean / (d_mean + s_mean) : 0.5f;

        BSDFFlags spec = BSDFFlags::GlossyReflection | BSDFFlags::FrontSide |
                         BSDFFlags::Polarizing | BSDFFlags::WiSideOnly;
        BSDFFlags diff = BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide |
                         BSDFFlags::Polarizing | BSDFFlags::WiSideOnly;
        if (m_microfacet.is_anisotropic()) spec |= BSDFFlags::Anisotropic;
        if (m_microfacet.is_spatially_varying() || varies(m_specular_reflectance))
            spec |= BSDFFlags::SpatiallyVarying;
        if (varies(m_diffuse_reflectance)) diff |= BSDFFlags::SpatiallyVarying;
        set_components({spec, diff});
    }

    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float sample1, const Point2f &sample2) const override {
        BSDFSample bs;
        if (!sample_direction(ctx, si, sample1, sample2, bs)) return {bs, Color3f(0.f)};
        auto [value, pdf] = eval_pdf(ctx, si, bs.wo);
        if (!(pdf > 0.f) || value.is_black()) return {bs, Color3f(0.f)};
        bs.pdf = pdf;
        return {bs, value / pdf};
    }

    std::pair<BSDFSample, Mueller> sample_polarized(const BSDFContext &ctx,
                                                    const SurfaceInteraction &si, float sample1,
                                                    const Point2f &sample2) const override {
        BSDFSample bs;
        if (!sample_direction(ctx, si, sample1, sample2, bs)) return {bs, Mueller{}};
        auto [value, pdf] = eval_pdf_polarized(ctx, si, bs.wo);
        if (!(pdf > 0.f) || value.is_black()) return {bs, Mueller{}};
        bs.pdf = pdf;
        return {bs, value / pdf};
    }

    Color3f eval(const BSDFContext &ctx, const SurfaceInteraction &si,
                 const Vector3f &wo) const override {
        return eval_pdf(ctx, si, wo).first;
    }

    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
              const Vector3f &wo) const override {
        const float cos_i = Frame::cos_theta(si.wi), cos_o = Frame::cos_theta(wo);
        if (cos_i <= 0.f || cos_o <= 0.f) return 0.f;
        const bool has_spec = ctx.is_enabled(BSDFFlags::GlossyReflection, 0);
        const bool has_diff = ctx.is_enabled(BSDFFlags::DiffuseReflection, 1);
        const float p_spec = specular_probability(has_spec, has_diff);
        float result = 0.f;
        if (p_spec > 0.f) {
            const Vector3f h = normalize(si.wi + wo);
            if (dot(si.wi, h) > 0.f && dot(wo, h) > 0.f)
                result += p_spec * m_microfacet.at(si).pdf(si.wi, h) / (4.f * dot(wo, h));
        }
        if (p_spec < 1.f) result += (1.f - p_spec) * cos_o * InvPi;
        return result;
    }

    std::pair<Color3f, float> eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
                                       const Vector3f &wo) const override {
        const float cos_i = Frame::cos_theta(si.wi), cos_o = Frame::cos_theta(wo);
        if (cos_i <= 0.f || cos_o <= 0.f) return {Color3f(0.f), 0.f};
        Color3f value(0.f);
        if (ctx.is_enabled(BSDFFlags::GlossyReflection, 0)) {
            const Vector3f h = normalize(si.wi + wo);
            const float F = fresnel_dielectric(dot(si.wi, h), m_eta).F;
            value += specular_tint(si) * (F * glossy(si, wo, h));
        }
        if (ctx.is_enabled(BSDFFlags::DiffuseReflection, 1)) {
            const float t_i = 1.f - fresnel_dielectric(cos_i, m_eta).F,
                        t_o = 1.f - fresnel_dielectric(cos_o, m_eta).F;
            value += m_diffuse_reflectance->eval(si) * (t_i * t_o * cos_o * InvPi);
        }
        return {value, pdf(ctx, si, wo)};
    }

    /// The polarized mode (BSDF's conventions: light from −wo_hat to wi_hat).
    std::pair<Mueller, float> eval_pdf_polarized(const BSDFContext &ctx,
                                                 const SurfaceInteraction &si,
                                                 const Vector3f &wo) const override {
        const float cos_i = Frame::cos_theta(si.wi), cos_o = Frame::cos_theta(wo);
        if (cos_i <= 0.f || cos_o <= 0.f) return {Mueller{}, 0.f};
        const bool radiance = ctx.mode == TransportMode::Radiance;
        const Vector3f wo_hat = radiance ? wo : si.wi, wi_hat = radiance ? si.wi : wo;
        const Vector3f n(0.f, 0.f, 1.f);
        Mueller value;
        if (ctx.is_enabled(BSDFFlags::GlossyReflection, 0)) {
            const Vector3f h = normalize(si.wi + wo);
            Mueller F = mueller::specular_reflection(dot(wo_hat, h), m_eta);
            F = mueller::reflection_to_implicit(F, h, wo_hat, wi_hat);
            value += F * (specular_tint(si) * glossy(si, wo, h));
        }
        if (ctx.is_enabled(BSDFFlags::DiffuseReflection, 1)) {
            // Into the coating along −wo_hat, depolarised by the base, out along wi_hat (its
            // direction inside the coating refracted from wi_hat).
            const Mueller T_in =
                mueller::specular_transmission(std::abs(Frame::cos_theta(wo_hat)), m_eta);
            const float cos_t = fresnel_dielectric(Frame::cos_theta(wi_hat), m_eta).cos_t;
            const Mueller T_out = mueller::specular_transmission(std::abs(cos_t), 1.f / m_eta);
            const Mueller D = T_out * mueller::depolarizer(m_diffuse_reflectance->eval(si)) * T_in;
            value += mueller::reflection_to_implicit(D, n, wo_hat, wi_hat) * Color3f(cos_o * InvPi);
        }
        return {value, pdf(ctx, si, wo)};
    }

    Color3f eval_diffuse_reflectance(const SurfaceInteraction &si) const override {
        return m_diffuse_reflectance->eval(si);
    }

    bool prefetch(const SurfaceInteraction &si) const override {
        // Every one is told, whatever the others said.
        bool started = facet::prefetch(m_diffuse_reflectance, si);
        started |= facet::prefetch(m_specular_reflectance, si);
        started |= m_microfacet.prefetch(si);
        return started;
    }

    std::string to_string() const override {
        return fmt::format("PolarizedPlastic[{}, eta = {}, diffuse_reflectance = {}, "
                           "specular_reflectance = {}]",
                           m_microfacet.to_string(), m_eta, m_diffuse_reflectance->to_string(),
                           m_specular_reflectance ? m_specular_reflectance->to_string() : "1");
    }

private:
    /// The probability of sampling the glossy lobe: s/(s + d) with both lobes enabled.
    float specular_probability(bool has_spec, bool has_diff) const {
        if (has_spec != has_diff) return has_spec ? 1.f : 0.f;
        return has_spec ? m_specular_sampling_weight : 0.f;
    }

    Color3f specular_tint(const SurfaceInteraction &si) const {
        return m_specular_reflectance ? m_specular_reflectance->eval(si) : Color3f(1.f);
    }

    /// D(h)·G(wi, wo, h)/(4 cos θi): the glossy lobe without its Fresnel term and tint.
    float glossy(const SurfaceInteraction &si, const Vector3f &wo, const Vector3f &h) const {
        const MicrofacetDistribution distr = m_microfacet.at(si);
        const float D = distr.eval(h);
        if (D == 0.f) return 0.f;
        return D * distr.G(si.wi, wo, h) / (4.f * Frame::cos_theta(si.wi));
    }

    /// Picks a lobe with sample1 and draws wo into bs (all but the pdf); false on failure.
    bool sample_direction(const BSDFContext &ctx, const SurfaceInteraction &si, float sample1,
                          const Point2f &sample2, BSDFSample &bs) const {
        const bool has_spec = ctx.is_enabled(BSDFFlags::GlossyReflection, 0);
        const bool has_diff = ctx.is_enabled(BSDFFlags::DiffuseReflection, 1);
        if ((!has_spec && !has_diff) || Frame::cos_theta(si.wi) <= 0.f) return false;
        bs.eta = 1.f;
        if (sample1 < specular_probability(has_spec, has_diff)) {
            auto [m, pdf_m] = m_microfacet.at(si).sample(si.wi, sample2);
            if (!(pdf_m > 0.f) || dot(si.wi, m) <= 0.f) return false;
            bs.wo = facet::reflect(si.wi, m);
            bs.sampled_type = BSDFFlags::GlossyReflection;
            bs.sampled_component = 0;
        } else {
            bs.wo = warp::square_to_cosine_hemisphere(sample2);
            bs.sampled_type = BSDFFlags::DiffuseReflection;
            bs.sampled_component = 1;
        }
        return Frame::cos_theta(bs.wo) > 0.f;
    }

    MicrofacetParameters m_microfacet;
    float m_eta;
    float m_specular_sampling_weight;
    std::shared_ptr<Texture> m_diffuse_reflectance, m_specular_reflectance;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::PolarizedPlastic, BSDF, "pplastic",
                          "Polarized plastic: a rough dielectric coating over a diffuse base", DOC,
                          ::facet::AllModes)
