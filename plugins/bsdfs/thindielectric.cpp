static const char *DOC = R"DOC(
# thindielectric: thin dielectric sheet (window pane, soap film)

An infinitely thin slab of dielectric material: light is reflected into the mirror direction or
passes straight through without bending. The reflectance accounts for all internal reflections
inside the slab: with R the Fresnel reflectance of one interface, the slab reflects 2R/(1 + R)
and transmits the rest. Both sides of the surface behave alike.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| int_ior | float or string | bk7 (1.5046) | Index of refraction of the slab, a number or a material name |
| ext_ior | float or string | air (1.000277) | Index of refraction of the surrounding medium |
| specular_reflectance | spectrum or texture | 1.0 | Tint of the reflected light (for artistic control only) |
| specular_transmittance | spectrum or texture | 1.0 | Tint of the transmitted light (for artistic control only) |

```xml
<bsdf type="thindielectric">
    <float name="int_ior" value="1.5"/>
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

class ThinDielectric final : public BSDF {
public:
    explicit ThinDielectric(const Properties &props) {
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
        set_components({BSDFFlags::DeltaReflection | sides, BSDFFlags::Null | sides});
    }

    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float sample1,
                                          const Point2f & /*sample2*/) const override {
        bool has_reflection = ctx.is_enabled(BSDFFlags::DeltaReflection, 0);
        bool has_transmission = ctx.is_enabled(BSDFFlags::Null, 1);
        BSDFSample bs;
        if (!has_reflection && !has_transmission) return {bs, Color3f(0.f)};

        float R = slab_reflectance(Frame::cos_theta(si.wi)), T = 1.f - R;
        bool reflect_lobe;
        float weight;
        if (has_reflection && has_transmission) {
            reflect_lobe = sample1 < R;
            bs.pdf = reflect_lobe ? R : T;
            weight = 1.f;
        } else {
            reflect_lobe = has_reflection;
            bs.pdf = 1.f;
            weight = reflect_lobe ? R : T;
        }

        Color3f result(weight);
        bs.eta = 1.f;
        if (reflect_lobe) {
            bs.wo = facet::reflect(si.wi);
            bs.sampled_type = BSDFFlags::DeltaReflection;
            bs.sampled_component = 0;
            if (m_specular_reflectance) result *= m_specular_reflectance->eval(si);
        } else {
            bs.wo = -si.wi;
            bs.sampled_type = BSDFFlags::Null;
            bs.sampled_component = 1;
            if (m_specular_transmittance) result *= m_specular_transmittance->eval(si);
        }
        if (!(bs.pdf > 0.f)) return {bs, Color3f(0.f)};
        return {bs, result};
    }

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

    Color3f eval_null_transmission(const SurfaceInteraction &si) const override {
        Color3f result(1.f - slab_reflectance(Frame::cos_theta(si.wi)));
        if (m_specular_transmittance) result *= m_specular_transmittance->eval(si);
        return result;
    }

    bool prefetch(const SurfaceInteraction &si) const override {
        // Every one is told, whatever the others said.
        bool started = facet::prefetch(m_specular_reflectance, si);
        started |= facet::prefetch(m_specular_transmittance, si);
        return started;
    }

    std::string to_string() const override {
        return fmt::format("ThinDielectric[eta = {}, specular_reflectance = {}, "
                           "specular_transmittance = {}]",
                           m_eta,
                           m_specular_reflectance ? m_specular_reflectance->to_string() : "1",
                           m_specular_transmittance ? m_specular_transmittance->to_string() : "1");
    }

private:
    /// Reflectance of the slab: R + T²R(1 + R² + R⁴ + ...) = 2R/(1 + R) for one interface's R.
    float slab_reflectance(float cos_i) const {
        float R = fresnel_dielectric(std::abs(cos_i), m_eta).F;
        return R < 1.f ? 2.f * R / (1.f + R) : 1.f;
    }

    float m_eta;
    std::shared_ptr<Texture> m_specular_reflectance, m_specular_transmittance;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::ThinDielectric, BSDF, "thindielectric",
                          "Thin dielectric sheet: Fresnel reflection and unbent transmission", DOC,
                          ::facet::AllModes)
