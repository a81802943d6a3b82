static const char *DOC = R"DOC(
# conductor: smooth conductor (polished metal, mirror)

A perfectly smooth metal surface: light is reflected into the mirror direction with the Fresnel
reflectance of a conductor with complex index of refraction η + i·k. Either name a measured
`material` or give `eta` and `k`; the default is an ideal mirror (η = 0, k = 1). Only the front
side reflects (wrap the BSDF in `twosided` for two-sided surfaces).

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| material | string | none | Measured material (Ag, Al, Au, Cr, Cu, ..., listed below); none = ideal mirror |
| eta | spectrum or texture | 0.0 | Real part of the IOR (only without material; unbounded spectrum) |
| k | spectrum or texture | 1.0 | Imaginary part of the IOR (only without material; unbounded spectrum) |
| specular_reflectance | spectrum or texture | 1.0 | Tint of the reflection (for artistic control only) |

Materials: a-C, Ag, Al, AlAs, AlSb, Au, Be, Cr, CsI, Cu, Cu2O, CuO, d-C, Hg, HgTe, Ir, K, Li,
MgO, Mo, Nb, Rh, Se, Se-e, SiC, SnTe, Ta, Te, Te-e, ThF4, TiC, TiN, TiO2, TiO2-e, VC, VN, W,
most also as <name>_palik, plus Na_palik, Ni_palik and V_palik.

```xml
<bsdf type="conductor">
    <string name="material" value="Au"/>
</bsdf>
```
)DOC";

#include <facet/bsdf.h>
#include <facet/conductor_data.h>
#include <facet/fresnel.h>
#include <facet/plugin.h>
#include <facet/properties.h>
#include <facet/texture.h>

#include <fmt/format.h>

namespace facet {

class Conductor final : public BSDF {
public:
    explicit Conductor(const Properties &props) {
        ConductorIOR ior = read_conductor_ior(props);
        m_material = ior.material;
        m_eta = ior.eta;
        m_k = ior.k;
        m_specular_reflectance = props.texture("specular_reflectance", 1.f);
        BSDFFlags flags = BSDFFlags::DeltaReflection | BSDFFlags::FrontSide | BSDFFlags::Polarizing;
        if (varies(m_eta) || varies(m_k) || varies(m_specular_reflectance))
            flags |= BSDFFlags::SpatiallyVarying;
        set_components({flags});
    }

    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float /*sample1*/,
                                          const Point2f & /*sample2*/) const override {
        BSDFSample bs;
        float cos_i = Frame::cos_theta(si.wi);
        if (!ctx.is_enabled(BSDFFlags::DeltaReflection, 0) || cos_i <= 0.f)
            return {bs, Color3f(0.f)};

        bs.wo = facet::reflect(si.wi);
        bs.pdf = 1.f;
        bs.eta = 1.f;
        bs.sampled_type = BSDFFlags::DeltaReflection;
        bs.sampled_component = 0;
        Color3f F = fresnel_conductor(cos_i, m_eta->eval(si), m_k->eval(si));
        return {bs, F * m_specular_reflectance->eval(si)};
    }

    /// The polarized mode: the metal's Fresnel reflection with its phases.
    std::pair<BSDFSample, Mueller> sample_polarized(const BSDFContext &ctx,
                                                    const SurfaceInteraction &si, float /*sample1*/,
                                                    const Point2f & /*sample2*/) const override {
        BSDFSample bs;
        if (!ctx.is_enabled(BSDFFlags::DeltaReflection, 0) || Frame::cos_theta(si.wi) <= 0.f)
            return {bs, Mueller{}};
        bs.wo = facet::reflect(si.wi);
        bs.pdf = 1.f;
        bs.eta = 1.f;
        bs.sampled_type = BSDFFlags::DeltaReflection;
        bs.sampled_component = 0;
        // Light travels from wo_hat to wi_hat (BSDF's conventions).
        const bool radiance = ctx.mode == TransportMode::Radiance;
        const Vector3f wo_hat = radiance ? bs.wo : si.wi, wi_hat = radiance ? si.wi : bs.wo;
        Mueller F =
            mueller::specular_reflection(Frame::cos_theta(wo_hat), m_eta->eval(si), m_k->eval(si));
        F = mueller::reflection_to_implicit(F, Vector3f(0.f, 0.f, 1.f), wo_hat, wi_hat);
        return {bs, F * m_specular_reflectance->eval(si)};
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

    bool prefetch(const SurfaceInteraction &si) const override {
        // Every one is told, whatever the others said.
        bool started = facet::prefetch(m_eta, si);
        started |= facet::prefetch(m_k, si);
        started |= facet::prefetch(m_specular_reflectance, si);
        return started;
    }

    std::string to_string() const override {
        return fmt::format("Conductor[material = {}, eta = {}, k = {}, specular_reflectance = {}]",
                           m_material, m_eta->to_string(), m_k->to_string(),
                           m_specular_reflectance->to_string());
    }

private:
    std::string m_material;
    std::shared_ptr<Texture> m_eta, m_k, m_specular_reflectance;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Conductor, BSDF, "conductor",
                          "Smooth conductor with measured or given complex IOR", DOC,
                          ::facet::AllModes)
