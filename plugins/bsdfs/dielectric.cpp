static const char *DOC = R"DOC(
# dielectric: smooth dielectric interface (glass, water)

A perfectly smooth boundary between two dielectrics, such as air and glass: light is either
reflected into the mirror direction or refracted following Snell's law, in the proportion given
by the Fresnel equations. Both sides of the surface are supported; the side the normal points to
is the exterior.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| int_ior | float or string | bk7 (1.5046) | Interior index of refraction, a number or a material name (water, diamond, ...) |
| ext_ior | float or string | air (1.000277) | Exterior index of refraction, a number or a material name |
| specular_reflectance | spectrum or texture | 1.0 | Tint of the reflected light (for artistic control only) |
| specular_transmittance | spectrum or texture | 1.0 | Tint of the transmitted light (for artistic control only) |

Refracted radiance is scaled by η_ti² = (η_i/η_t)² in radiance transport (the spreading of
radiance through the change of solid angle); importance transport is not scaled.

```xml
<bsdf type="dielectric">
    <string name="int_ior" value="water"/>
    <string name="ext_ior" value="air"/>
</bsdf>
```
)DOC";

#include <facet/bsdf.h>
#include <facet/fresnel.h>
#include <facet/ior.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

class Dielectric final : public BSDF {
public:
    explicit Dielectric(const Properties &props) {
        float int_ior = read_ior(props, "int_ior", "bk7");
        float ext_ior = read_ior(props, "ext_ior", "air");
        m_eta = int_ior / ext_ior;
        if (props.has("specular_reflectance"))
            m_specular_reflectance = props.texture("specular_reflectance", 1.f);
        if (props.has("specular_transmittance"))
            m_specular_transmittance = props.texture("specular_transmittance", 1.f);

        BSDFFlags sides = BSDFFlags::FrontSide | BSDFFlags::BackSide;
        if (varies(m_specular_reflectance) || varies(m_specular_transmittance))
            sides |= BSDFFlags::SpatiallyVarying;
        sides |= BSDFFlags::Polarizing;
        set_components({BSDFFlags::DeltaReflection | sides,
                        BSDFFlags::DeltaTransmission | sides | BSDFFlags::NonSymmetric});
    }

    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float sample1,
                                          const Point2f & /*sample2*/) const override {
        bool has_reflection = ctx.is_enabled(BSDFFlags::DeltaReflection, 0);
        bool has_transmission = ctx.is_enabled(BSDFFlags::DeltaTransmission, 1);
        BSDFSample bs;
        if (!has_reflection && !has_transmission) return {bs, Color3f(0.f)};

        float cos_i = Frame::cos_theta(si.wi);
        auto [F, cos_t, eta_it, eta_ti] = fresnel_dielectric(cos_i, m_eta);

        // With both lobes, pick one with probability F / 1 − F so the weight is the tint alone;
        // with one lobe, it is always taken and carries F or 1 − F in its weight.
        bool reflect_lobe;
        float weight;
        if (has_reflection && has_transmission) {
            reflect_lobe = sample1 < F;
            bs.pdf = reflect_lobe ? F : 1.f - F;
            weight = 1.f;
        } else {
            reflect_lobe = has_reflection;
            bs.pdf = 1.f;
            weight = reflect_lobe ? F : 1.f - F;
        }

        Color3f result;
        if (reflect_lobe) {
            bs.wo = facet::reflect(si.wi);
            bs.eta = 1.f;
            bs.sampled_type = BSDFFlags::DeltaReflection;
            bs.sampled_component = 0;
            result = Color3f(weight);
            if (m_specular_reflectance) result *= m_specular_reflectance->eval(si);
        } else {
            bs.wo = refract(si.wi, cos_t, eta_ti);
            bs.eta = eta_it;
            bs.sampled_type = BSDFFlags::DeltaTransmission;
            bs.sampled_component = 1;
            // Radiance is compressed into the smaller solid angle on the denser side.
            if (ctx.mode == TransportMode::Radiance) weight *= eta_ti * eta_ti;
            result = Color3f(weight);
            if (m_specular_transmittance) result *= m_specular_transmittance->eval(si);
        }
        if (!(bs.pdf > 0.f)) return {bs, Color3f(0.f)};
        return {bs, result};
    }

    /// The polarized mode: the same lobes and choice, the Fresnel matrices of the interface in
    /// place of F and 1 − F.
    std::pair<BSDFSample, Mueller> sample_polarized(const BSDFContext &ctx,
                                                    const SurfaceInteraction &si, float sample1,
                                                    const Point2f &sample2) const override {
        auto [bs, weight] = sample(ctx, si, sample1, sample2);
        if (weight.is_black()) return {bs, Mueller{}};
        const bool reflected = bs.sampled_type == BSDFFlags::DeltaReflection;
        // With one lobe enabled it is taken with probability 1 and carries its Fresnel term.
        const bool both = ctx.is_enabled(BSDFFlags::DeltaReflection, 0) &&
                          ctx.is_enabled(BSDFFlags::DeltaTransmission, 1);
        const bool radiance = ctx.mode == TransportMode::Radiance;
        const Vector3f wo_hat = radiance ? bs.wo : si.wi, wi_hat = radiance ? si.wi : bs.wo;
        const float cos_hat = Frame::cos_theta(wo_hat);
        Mueller M = reflected ? mueller::specular_reflection(cos_hat, m_eta)
                              : mueller::specular_transmission(cos_hat, m_eta);
        M = mueller::reflection_to_implicit(M, Vector3f(0.f, 0.f, 1.f), wo_hat, wi_hat);
        float scale = both ? 1.f / bs.pdf : 1.f;
        if (!reflected && radiance) scale /= bs.eta * bs.eta; // η_ti², as sample() does
        Color3f tint(scale);
        const Texture *t =
            reflected ? m_specular_reflectance.get() : m_specular_transmittance.get();
        if (t) tint *= t->eval(si);
        return {bs, M * tint};
    }

    /// Delta lobes only: no density with respect to solid angle.
    Color3f eval(const BSDFContext &, const SurfaceInteraction &, const Vector3f &) const override {
        return Color3f(0.f);
    }
    float pdf(const BSDFContext &, const SurfaceInteraction &, const Vector3f &) const override {
        return 0.f;
    }
    std::pair<Color3f, float> eval_pdf(const BSDFContext &, const SurfaceInteraction &,
                                       const Vector3f &) const override {
        return {Color3f(0.f), 0.f};
    }

    /// Relative index of refraction η = int_ior / ext_ior.
    float eta() const { return m_eta; }

    bool prefetch(const SurfaceInteraction &si) const override {
        // Every one is told, whatever the others said.
        bool started = facet::prefetch(m_specular_reflectance, si);
        started |= facet::prefetch(m_specular_transmittance, si);
        return started;
    }

    std::string to_string() const override {
        return fmt::format("Dielectric[eta = {}, specular_reflectance = {}, "
                           "specular_transmittance = {}]",
                           m_eta,
                           m_specular_reflectance ? m_specular_reflectance->to_string() : "1",
                           m_specular_transmittance ? m_specular_transmittance->to_string() : "1");
    }

private:
    float m_eta;
    std::shared_ptr<Texture> m_specular_reflectance, m_specular_transmittance;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Dielectric, BSDF, "dielectric",
                          "Smooth dielectric interface with Fresnel reflection and refraction", DOC,
                          ::facet::AllModes)
