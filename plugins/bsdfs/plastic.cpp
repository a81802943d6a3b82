static const char *DOC = R"DOC(
# plastic: smooth plastic (diffuse base under a smooth dielectric coating)

A diffuse material coated by a perfectly smooth dielectric layer, such as glossy paint or
plastic. Light arriving at the coating is either reflected into the mirror direction (with the
Fresnel reflectance F(cos θi)) or enters the layer, where it scatters diffusely, bounces between
the base and the underside of the coating (internal Fresnel reflectance fdr) and leaves through
the coating again:

f_diffuse·cos θo = ρ/(1 − fdr) · (1/η²) · (1 − F(cos θi)) · (1 − F(cos θo)) · cos θo/π

(with `nonlinear`, ρ/(1 − ρ·fdr): the colour shift of repeated bounces off a coloured base).
Sampling picks the mirror lobe with probability F·w / (F·w + (1 − F)(1 − w)), where w is the
specular sampling weight s/(s + d) of the mean specular and diffuse reflectances. Only the front
side reflects (wrap the BSDF in `twosided` for two-sided surfaces).

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| int_ior | float or string | polypropylene (1.49) | Interior index of refraction, a number or a material name |
| ext_ior | float or string | air (1.000277) | Exterior index of refraction, a number or a material name |
| diffuse_reflectance | spectrum or texture | 0.5 | Albedo ρ of the diffuse base |
| specular_reflectance | spectrum or texture | 1.0 | Tint of the mirror reflection (for artistic control only) |
| nonlinear | boolean | false | Account for the colour shift of internal scattering: ρ/(1 − ρ·fdr) instead of ρ/(1 − fdr) |

Components: 0 = the mirror reflection (DeltaReflection), 1 = the diffuse base (DiffuseReflection).

```xml
<bsdf type="plastic">
    <rgb name="diffuse_reflectance" value="0.1, 0.27, 0.36"/>
    <float name="int_ior" value="1.9"/>
</bsdf>
```
)DOC";

#include <facet/bsdf.h>
#include <facet/fresnel.h>
#include <facet/ior.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>
#include <facet/warp.h>

#include <fmt/format.h>

namespace facet {

class Plastic final : public BSDF {
public:
    explicit Plastic(const Properties &props) {
        float int_ior = read_ior(props, "int_ior", "polypropylene");
        float ext_ior = read_ior(props, "ext_ior", "air");
        m_eta = int_ior / ext_ior;
        m_inv_eta_2 = 1.f / (m_eta * m_eta);
        // Light inside the coating sees the relative IOR 1/η.
        m_fdr_int = fresnel_diffuse_reflectance(1.f / m_eta);
        m_fdr_ext = fresnel_diffuse_reflectance(m_eta);

        m_diffuse_reflectance = props.texture("diffuse_reflectance", 0.5f);
        if (props.has("specular_reflectance"))
            m_specular_reflectance = props.texture("specular_reflectance", 1.f);
        m_nonlinear = props.get_bool("nonlinear", false);

        float d_mean = m_diffuse_reflectance->mean().mean();
        float s_mean = m_specular_reflectance ? m_specular_reflectance->mean().mean() : 1.f;
        m_specular_sampling_weight = d_mean + s_mean > 0.f ? s_mean / (d_mean + s_mean) : 0.5f;

        // The coat sampled alone weighs its reflection by F (times specular_reflectance), what
        // sample() brings through it on average: separable.
        BSDFFlags spec = BSDFFlags::DeltaReflection | BSDFFlags::SeparableDelta |
                         BSDFFlags::FrontSide | BSDFFlags::WiSideOnly;
        BSDFFlags diff =
            BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide | BSDFFlags::WiSideOnly;
        if (m_specular_reflectance && m_specular_reflectance->is_spatially_varying())
            spec |= BSDFFlags::SpatiallyVarying;
        if (m_diffuse_reflectance->is_spatially_varying()) diff |= BSDFFlags::SpatiallyVarying;
        set_components({spec, diff});
    }

    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float sample1, const Point2f &sample2) const override {
        bool has_specular = ctx.is_enabled(BSDFFlags::DeltaReflection, 0);
        bool has_diffuse = ctx.is_enabled(BSDFFlags::DiffuseReflection, 1);
        float cos_i = Frame::cos_theta(si.wi);
        BSDFSample bs;
        if ((!has_specular && !has_diffuse) || cos_i <= 0.f) return {bs, Color3f(0.f)};

        float F_i = fresnel_dielectric(cos_i, m_eta).F;
        float p_spec = specular_probability(F_i, has_specular, has_diffuse);
        bs.eta = 1.f;

        if (sample1 < p_spec) {
            bs.wo = facet::reflect(si.wi);
            bs.pdf = p_spec;
            bs.sampled_type = BSDFFlags::DeltaReflection;
            bs.sampled_component = 0;
            Color3f weight(F_i / p_spec);
            if (m_specular_reflectance) weight *= m_specular_reflectance->eval(si);
            return {bs, weight};
        }

        float p_diff = 1.f - p_spec;
        bs.wo = warp::square_to_cosine_hemisphere(sample2);
        bs.pdf = p_diff * warp::square_to_cosine_hemisphere_pdf(bs.wo);
        bs.sampled_type = BSDFFlags::DiffuseReflection;
        bs.sampled_component = 1;
        float cos_o = Frame::cos_theta(bs.wo);
        if (!(bs.pdf > 0.f) || cos_o <= 0.f) return {bs, Color3f(0.f)};
        // f·cos θo / pdf: the cos θo/π of the value cancels against the cosine-weighted density.
        float F_o = fresnel_dielectric(cos_o, m_eta).F;
        Color3f weight = diffuse_albedo(si) * (m_inv_eta_2 * (1.f - F_i) * (1.f - F_o) / p_diff);
        return {bs, weight};
    }

    Color3f eval(const BSDFContext &ctx, const SurfaceInteraction &si,
                 const Vector3f &wo) const override {
        float cos_i = Frame::cos_theta(si.wi), cos_o = Frame::cos_theta(wo);
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection, 1) || cos_i <= 0.f || cos_o <= 0.f)
            return Color3f(0.f);
        return diffuse_value(si, cos_i, cos_o);
    }

    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
              const Vector3f &wo) const override {
        float cos_i = Frame::cos_theta(si.wi), cos_o = Frame::cos_theta(wo);
        bool has_specular = ctx.is_enabled(BSDFFlags::DeltaReflection, 0);
        bool has_diffuse = ctx.is_enabled(BSDFFlags::DiffuseReflection, 1);
        if (!has_diffuse || cos_i <= 0.f || cos_o <= 0.f) return 0.f;
        float F_i = fresnel_dielectric(cos_i, m_eta).F;
        float p_diff = 1.f - specular_probability(F_i, has_specular, has_diffuse);
        return p_diff * warp::square_to_cosine_hemisphere_pdf(wo);
    }

    std::pair<Color3f, float> eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
                                       const Vector3f &wo) const override {
        float cos_i = Frame::cos_theta(si.wi), cos_o = Frame::cos_theta(wo);
        bool has_specular = ctx.is_enabled(BSDFFlags::DeltaReflection, 0);
        bool has_diffuse = ctx.is_enabled(BSDFFlags::DiffuseReflection, 1);
        if (!has_diffuse || cos_i <= 0.f || cos_o <= 0.f) return {Color3f(0.f), 0.f};
        float F_i = fresnel_dielectric(cos_i, m_eta).F;
        float p_diff = 1.f - specular_probability(F_i, has_specular, has_diffuse);
        return {diffuse_value(si, cos_i, cos_o),
                p_diff * warp::square_to_cosine_hemisphere_pdf(wo)};
    }

    Color3f eval_diffuse_reflectance(const SurfaceInteraction &si) const override {
        return m_diffuse_reflectance->eval(si);
    }

    bool prefetch(const SurfaceInteraction &si) const override {
        // Every one is told, whatever the others said.
        bool started = facet::prefetch(m_diffuse_reflectance, si);
        started |= facet::prefetch(m_specular_reflectance, si);
        return started;
    }

    std::string to_string() const override {
        return fmt::format(
            "Plastic[eta = {}, diffuse_reflectance = {}, specular_reflectance = {}, "
            "nonlinear = {}, fdr_int = {}, fdr_ext = {}, specular_sampling_weight = {}]",
            m_eta, m_diffuse_reflectance->to_string(),
            m_specular_reflectance ? m_specular_reflectance->to_string() : "1", m_nonlinear,
            m_fdr_int, m_fdr_ext, m_specular_sampling_weight);
    }

private:
    /// Probability of choosing the mirror lobe: F·w against (1 − F)(1 − w), or all-or-nothing
    /// when only one lobe is enabled.
    float specular_probability(float F_i, bool has_specular, bool has_diffuse) const {
        if (has_specular != has_diffuse) return has_specular ? 1.f : 0.f;
        float p_spec = F_i * m_specular_sampling_weight;
        float p_diff = (1.f - F_i) * (1.f - m_specular_sampling_weight);
        return p_spec + p_diff > 0.f ? p_spec / (p_spec + p_diff) : 0.f;
    }

    /// ρ/(1 − fdr) (or ρ/(1 − ρ·fdr)): the base's albedo with the inter-reflections under the
    /// coating summed as a geometric series.
    Color3f diffuse_albedo(const SurfaceInteraction &si) const {
        Color3f rho = m_diffuse_reflectance->eval(si);
        if (m_nonlinear) return rho / (Color3f(1.f) - rho * m_fdr_int);
        return rho / (1.f - m_fdr_int);
    }

    Color3f diffuse_value(const SurfaceInteraction &si, float cos_i, float cos_o) const {
        float F_i = fresnel_dielectric(cos_i, m_eta).F, F_o = fresnel_dielectric(cos_o, m_eta).F;
        return diffuse_albedo(si) * (m_inv_eta_2 * (1.f - F_i) * (1.f - F_o) * InvPi * cos_o);
    }

    float m_eta, m_inv_eta_2, m_fdr_int, m_fdr_ext;
    float m_specular_sampling_weight;
    bool m_nonlinear;
    std::shared_ptr<Texture> m_diffuse_reflectance, m_specular_reflectance;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Plastic, BSDF, "plastic",
                          "Smooth plastic: a diffuse base under a smooth dielectric coating", DOC,
                          ::facet::AllModes)
