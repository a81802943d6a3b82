static const char *DOC = R"DOC(
# phong: energy-conserving modified Phong reflection (Lafortune and Willems 1994)

A diffuse lobe plus a glossy lobe around the mirror direction:
f = ρd/π + ρs·(n + 2)/(2π)·cos^n α, where α is the angle between wo and the mirror direction of
wi. With ρd + ρs ≤ 1 no energy is created. Sampling picks a lobe in proportion to the mean
reflectances, then a cosine-weighted direction or a cos^n lobe around the mirror direction.
Front side only. Built out of tree by facet's SDK test; not part of facet's plugin set.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| diffuse_reflectance | spectrum or texture | 0.5 | Diffuse albedo ρd |
| specular_reflectance | spectrum or texture | 0.2 | Albedo ρs of the glossy lobe at normal incidence |
| exponent | float | 30 | Phong exponent n (larger is sharper), at least 0 |

```xml
<bsdf type="phong">
    <rgb name="diffuse_reflectance" value="0.4, 0.2, 0.1"/>
    <float name="exponent" value="50"/>
</bsdf>
```
)DOC";

#include <facet/bsdf.h>
#include <facet/frame.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>
#include <facet/warp.h>

#include <fmt/format.h>

namespace facet {

class Phong final : public BSDF {
public:
    explicit Phong(const Properties &props) {
        m_diffuse = props.texture("diffuse_reflectance", 0.5f);
        m_specular = props.texture("specular_reflectance", 0.2f);
        m_exponent = float(props.get_float("exponent", 30.0));
        if (!(m_exponent >= 0.f))
            FACET_THROW_AT(props.location("exponent"), "exponent must be at least 0 (got {})",
                           m_exponent);
        float d = m_diffuse->mean().mean(), s = m_specular->mean().mean();
        m_specular_probability = d + s > 0.f ? s / (d + s) : 0.f;
        BSDFFlags glossy = BSDFFlags::GlossyReflection | BSDFFlags::FrontSide;
        BSDFFlags diffuse = BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide;
        set_components({glossy, diffuse});
    }

    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float sample1, const Point2f &sample2) const override {
        BSDFSample bs;
        bool has_glossy = ctx.is_enabled(BSDFFlags::GlossyReflection, 0);
        bool has_diffuse = ctx.is_enabled(BSDFFlags::DiffuseReflection, 1);
        if (Frame::cos_theta(si.wi) <= 0.f || (!has_glossy && !has_diffuse))
            return {bs, Color3f(0.f)};

        float p_glossy = lobe_probability(has_glossy, has_diffuse);
        if (sample1 < p_glossy) {
            // A cos^n lobe around the mirror direction: cos α = u^(1/(n+1)).
            float cos_alpha = std::pow(sample2.x, 1.f / (m_exponent + 1.f));
            float sin_alpha = safe_sqrt(1.f - cos_alpha * cos_alpha);
            float phi = 2.f * Pi * sample2.y;
            Vector3f local(sin_alpha * std::cos(phi), sin_alpha * std::sin(phi), cos_alpha);
            bs.wo = Frame(mirror(si.wi)).to_world(local);
            bs.sampled_type = BSDFFlags::GlossyReflection;
            bs.sampled_component = 0;
        } else {
            bs.wo = warp::square_to_cosine_hemisphere(sample2);
            bs.sampled_type = BSDFFlags::DiffuseReflection;
            bs.sampled_component = 1;
        }
        if (Frame::cos_theta(bs.wo) <= 0.f) return {bs, Color3f(0.f)};
        bs.pdf = pdf(ctx, si, bs.wo);
        if (!(bs.pdf > 0.f)) return {bs, Color3f(0.f)};
        return {bs, eval(ctx, si, bs.wo) / bs.pdf};
    }

    Color3f eval(const BSDFContext &ctx, const SurfaceInteraction &si,
                 const Vector3f &wo) const override {
        float cos_i = Frame::cos_theta(si.wi), cos_o = Frame::cos_theta(wo);
        if (cos_i <= 0.f || cos_o <= 0.f) return Color3f(0.f);
        Color3f f(0.f);
        if (ctx.is_enabled(BSDFFlags::GlossyReflection, 0)) {
            float cos_alpha = dot(mirror(si.wi), wo);
            if (cos_alpha > 0.f)
                f += m_specular->eval(si) *
                     ((m_exponent + 2.f) * InvTwoPi * std::pow(cos_alpha, m_exponent));
        }
        if (ctx.is_enabled(BSDFFlags::DiffuseReflection, 1)) f += m_diffuse->eval(si) * InvPi;
        return f * cos_o;
    }

    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
              const Vector3f &wo) const override {
        bool has_glossy = ctx.is_enabled(BSDFFlags::GlossyReflection, 0);
        bool has_diffuse = ctx.is_enabled(BSDFFlags::DiffuseReflection, 1);
        float cos_i = Frame::cos_theta(si.wi), cos_o = Frame::cos_theta(wo);
        if (cos_i <= 0.f || cos_o <= 0.f || (!has_glossy && !has_diffuse)) return 0.f;
        float p_glossy = lobe_probability(has_glossy, has_diffuse), result = 0.f;
        float cos_alpha = dot(mirror(si.wi), wo);
        if (p_glossy > 0.f && cos_alpha > 0.f)
            result += p_glossy * (m_exponent + 1.f) * InvTwoPi * std::pow(cos_alpha, m_exponent);
        if (p_glossy < 1.f) result += (1.f - p_glossy) * cos_o * InvPi;
        return result;
    }

    Color3f eval_diffuse_reflectance(const SurfaceInteraction &si) const override {
        return m_diffuse->eval(si);
    }

    std::string to_string() const override {
        return fmt::format(
            "Phong[diffuse_reflectance = {}, specular_reflectance = {}, exponent = {}]",
            m_diffuse->to_string(), m_specular->to_string(), m_exponent);
    }

private:
    static Vector3f mirror(const Vector3f &wi) { return Vector3f(-wi.x, -wi.y, wi.z); }

    /// Probability of sampling the glossy lobe given which lobes the context enables.
    float lobe_probability(bool has_glossy, bool has_diffuse) const {
        if (has_glossy && has_diffuse) return m_specular_probability;
        return has_glossy ? 1.f : 0.f;
    }

    std::shared_ptr<Texture> m_diffuse, m_specular;
    float m_exponent;
    float m_specular_probability;
};

} // namespace facet

FACET_EXPORT_PLUGIN(facet::Phong, BSDF, "phong", "Energy-conserving modified Phong reflection", DOC)
