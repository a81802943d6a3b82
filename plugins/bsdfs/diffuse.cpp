static const char *DOC = R"DOC(
# diffuse: smooth diffuse (Lambertian) reflection

An ideally rough surface that scatters light equally into every direction of the hemisphere on
its front side: f = ρ/π. The back side is black (wrap the BSDF in `twosided` for two-sided
surfaces). Sampling draws a cosine-weighted direction, so the sample weight is exactly ρ.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| reflectance | spectrum or texture | 0.5 | Diffuse albedo ρ (a number, `rgb`, `spectrum` or nested texture, values in [0, 1]) |

```xml
<bsdf type="diffuse">
    <rgb name="reflectance" value="0.2, 0.25, 0.7"/>
</bsdf>
```
)DOC";

#include <facet/bsdf.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>
#include <facet/warp.h>

#include <fmt/format.h>

namespace facet {

class Diffuse final : public BSDF {
public:
    explicit Diffuse(const Properties &props) {
        m_reflectance = props.texture("reflectance", 0.5f);
        BSDFFlags flags =
            BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide | BSDFFlags::WiSideOnly;
        if (m_reflectance->is_spatially_varying()) flags |= BSDFFlags::SpatiallyVarying;
        set_components({flags});
    }

    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float /*sample1*/,
                                          const Point2f &sample2) const override {
        BSDFSample bs;
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || Frame::cos_theta(si.wi) <= 0.f)
            return {bs, Color3f(0.f)};

        bs.wo = warp::square_to_cosine_hemisphere(sample2);
        bs.pdf = warp::square_to_cosine_hemisphere_pdf(bs.wo);
        bs.eta = 1.f;
        bs.sampled_type = BSDFFlags::DiffuseReflection;
        bs.sampled_component = 0;
        // f·cos θo / pdf = (ρ/π · cos θo) / (cos θo/π) = ρ.
        if (!(bs.pdf > 0.f) || Frame::cos_theta(bs.wo) <= 0.f) return {bs, Color3f(0.f)};
        return {bs, m_reflectance.eval(si)};
    }

    Color3f eval(const BSDFContext &ctx, const SurfaceInteraction &si,
                 const Vector3f &wo) const override {
        float cos_i = Frame::cos_theta(si.wi), cos_o = Frame::cos_theta(wo);
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || cos_i <= 0.f || cos_o <= 0.f)
            return Color3f(0.f);
        return m_reflectance.eval(si) * (InvPi * cos_o);
    }

    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
              const Vector3f &wo) const override {
        float cos_i = Frame::cos_theta(si.wi), cos_o = Frame::cos_theta(wo);
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || cos_i <= 0.f || cos_o <= 0.f)
            return 0.f;
        return warp::square_to_cosine_hemisphere_pdf(wo);
    }

    std::pair<Color3f, float> eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
                                       const Vector3f &wo) const override {
        float cos_i = Frame::cos_theta(si.wi), cos_o = Frame::cos_theta(wo);
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || cos_i <= 0.f || cos_o <= 0.f)
            return {Color3f(0.f), 0.f};
        return {m_reflectance.eval(si) * (InvPi * cos_o),
                warp::square_to_cosine_hemisphere_pdf(wo)};
    }

    Color3f eval_diffuse_reflectance(const SurfaceInteraction &si) const override {
        return m_reflectance.eval(si);
    }

    bool prefetch(const SurfaceInteraction &si) const override {
        return m_reflectance.prefetch(si);
    }

    std::string to_string() const override {
        return fmt::format("Diffuse[reflectance = {}]", m_reflectance->to_string());
    }

private:
    BakedTexture m_reflectance; ///< a constant reflectance is evaluated without a virtual call
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Diffuse, BSDF, "diffuse", "Smooth diffuse (Lambertian) reflection",
                          DOC, ::facet::AllModes)
