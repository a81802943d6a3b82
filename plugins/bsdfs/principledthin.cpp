static const char *DOC = R"DOC(
# principledthin: the thin-surface principled BSDF

Burley's principled material for thin, translucent sheets (2015, §4) as Mitsuba 3 has it: an
infinitely thin two-sided surface (leaves, paper, cloth, window panes) that reflects and transmits
without bending light. It behaves the same from both sides. Lobes, for w = spec_trans and
d = diff_trans/2:
- glossy reflection w·F·D·G/(4 cos θi), GGX with αu = r²/a, αv = r²·a, a = √(1 − 0.9·anisotropic),
  F the dielectric Fresnel of η blended by spec_tint towards Schlick with the tinted R0;
- glossy transmission w·base_color·(1 − F)·D'·G'/(4 cos θi) about the mirrored direction (the
  reflection lobe flipped through the sheet), with the roughness scaled by (0.65·η − 0.35)
  (Burley 2015, fig. 15);
- diffuse reflection (1 − w)(1 − d)·base_color/π·(Burley diffuse with retro-reflection, blended by
  flatness to the fake subsurface term) plus the sheen (1 − w)(1 − d)·sheen·tint·(1 − cos θd)⁵;
- diffuse transmission (1 − w)·d·base_color/π (Lambertian, through the sheet).

Sampling picks the four lobes with probabilities proportional to w/2·specular_reflectance_sampling_
rate, w/2·specular_transmittance_sampling_rate, (1 − w)(1 − d)·diffuse_reflectance_sampling_rate
and (1 − w)·d·diffuse_transmittance_sampling_rate; GGX visible normals for the glossy lobes and
cosine-weighted hemispheres for the diffuse ones. Every scalar is a number or a texture (queried as
a scalar); a lobe whose parameter is absent or the plain number 0 is switched off.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| base_color | spectrum or texture | 0.5 | Colour of the material |
| roughness | float or texture | 0.5 | Roughness r of the glossy lobes (α = r²) |
| anisotropic | float or texture | 0.0 | Degree of anisotropy (0: isotropic) |
| spec_trans | float or texture | 0.0 | Blends the diffuse response (0) into the glossy one (1) |
| eta | float or texture | 1.5 | Relative IOR of the sheet (Fresnel and the transmission roughness) |
| spec_tint | float or texture | 0.0 | Fraction of the glossy reflection tinted towards base_color |
| sheen | float or texture | 0.0 | Weight of the sheen lobe |
| sheen_tint | float or texture | 0.0 | Fraction of the sheen tinted towards base_color |
| flatness | float or texture | 0.0 | Blends the diffuse response (0) into the fake subsurface term (1) |
| diff_trans | float or texture | 0.0 | Share of the diffuse energy transmitted, 0 (all reflected) to 2 (all transmitted) |
| diffuse_reflectance_sampling_rate | float | 1.0 | Relative rate of sampling the diffuse reflection |
| specular_reflectance_sampling_rate | float | 1.0 | Relative rate of sampling the glossy reflection |
| specular_transmittance_sampling_rate | float | 1.0 | Relative rate of sampling the glossy transmission |
| diffuse_transmittance_sampling_rate | float | 1.0 | Relative rate of sampling the diffuse transmission |
| sample_visible | boolean | true | Sample the GGX normals visible from wi (Heitz & d'Eon 2014); Mitsuba always does |

Components, in order: diffuse reflection with sheen (DiffuseReflection), diffuse transmission
(DiffuseTransmission), glossy transmission (GlossyTransmission; only with spec_trans) and glossy
reflection (GlossyReflection); all on both sides. A negative sampling rate, or a constant eta <= 0
or diff_trans outside [0, 2], is an error.

```xml
<bsdf type="principledthin">
    <rgb name="base_color" value="0.7, 0.1, 0.1"/>
    <float name="roughness" value="0.15"/>
    <float name="spec_trans" value="0.8"/>
    <float name="diff_trans" value="0.3"/>
    <float name="eta" value="1.33"/>
</bsdf>
```
)DOC";

#include <facet/bsdf.h>
#include <facet/fresnel.h>
#include <facet/microfacet.h>
#include <facet/mode.h>
#include <facet/plugin.h>
#include <facet/principled.h>
#include <facet/properties.h>
#include <facet/texture.h>
#include <facet/warp.h>

#include <fmt/format.h>

#include <cmath>

namespace facet {

using namespace principled;

class PrincipledThin final : public BSDF {
public:
    explicit PrincipledThin(const Properties &props) {
        m_base_color = props.texture("base_color", 0.5f);
        m_spectral = is_spectral(props.mode());
        m_roughness = props.texture("roughness", 0.5f);
        m_has_anisotropic = lobe_present(props, "anisotropic");
        m_anisotropic = props.texture("anisotropic", 0.f);
        m_has_spec_trans = lobe_present(props, "spec_trans");
        m_spec_trans = props.texture("spec_trans", 0.f);
        m_has_sheen = lobe_present(props, "sheen");
        m_sheen = props.texture("sheen", 0.f);
        m_has_sheen_tint = lobe_present(props, "sheen_tint");
        m_sheen_tint = props.texture("sheen_tint", 0.f);
        m_has_flatness = lobe_present(props, "flatness");
        m_flatness = props.texture("flatness", 0.f);
        m_has_spec_tint = lobe_present(props, "spec_tint");
        m_spec_tint = props.texture("spec_tint", 0.f);
        m_eta = props.texture("eta", 1.5f, SpectrumKind::Unbounded);
        m_has_diff_trans = lobe_present(props, "diff_trans");
        m_diff_trans = props.texture("diff_trans", 0.f, SpectrumKind::Unbounded);
        m_spec_refl_srate = rate(props, "specular_reflectance_sampling_rate");
        m_spec_trans_srate = rate(props, "specular_transmittance_sampling_rate");
        m_diff_trans_srate = rate(props, "diffuse_transmittance_sampling_rate");
        m_diff_refl_srate = rate(props, "diffuse_reflectance_sampling_rate");
        m_sample_visible = props.get_bool("sample_visible", true);

        if (!varies(m_eta) && !(m_eta->mean().mean() > 0.f))
            FACET_THROW_AT(props.has("eta") ? props.location("eta") : props.location(),
                           "principledthin: eta must be a positive relative IOR, got {}",
                           m_eta->mean().mean());
        float dt = m_diff_trans->mean().mean();
        if (!varies(m_diff_trans) && !(dt >= 0.f && dt <= 2.f))
            FACET_THROW_AT(props.location("diff_trans"),
                           "principledthin: diff_trans must be in [0, 2], got {}", dt);

        auto sv = [](const std::shared_ptr<Texture> &t) {
            return varies(t) ? BSDFFlags::SpatiallyVarying : BSDFFlags::Empty;
        };
        BSDFFlags sides = BSDFFlags::FrontSide | BSDFFlags::BackSide;
        BSDFFlags common = sides | sv(m_base_color) | sv(m_spec_trans);
        BSDFFlags glossy = common | sv(m_roughness) | sv(m_anisotropic) | sv(m_eta) |
                           (m_has_anisotropic ? BSDFFlags::Anisotropic : BSDFFlags::Empty);
        std::vector<BSDFFlags> components;
        components.push_back(BSDFFlags::DiffuseReflection | common | sv(m_roughness) |
                             sv(m_diff_trans) | sv(m_sheen) | sv(m_sheen_tint) | sv(m_flatness));
        components.push_back(BSDFFlags::DiffuseTransmission | common | sv(m_diff_trans));
        if (m_has_spec_trans) {
            m_comp_spec_trans = uint32_t(components.size());
            components.push_back(BSDFFlags::GlossyTransmission | glossy);
        }
        m_comp_spec_refl = uint32_t(components.size());
        components.push_back(BSDFFlags::GlossyReflection | glossy | sv(m_spec_tint));
        set_components(std::move(components));
    }

    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float sample1, const Point2f &sample2) const override {
        BSDFSample bs;
        float cos_i = Frame::cos_theta(si.wi);
        if (cos_i == 0.f) return {bs, Color3f(0.f)};
        Point p = at(si);
        Probabilities prob = probabilities(p, enabled(ctx));
        if (!(prob.total > 0.f)) return {bs, Color3f(0.f)};

        // The sheet is symmetric: work as if wi were on the front side and mirror back at the end.
        float side = cos_i > 0.f ? 1.f : -1.f;
        Vector3f wi = si.wi * side, wo;
        bs.eta = 1.f; // no bending through a thin sheet
        float u = sample1 * prob.total;
        if (u < prob.spec_refl) {
            Vector3f m = reflect_distribution(p).sample(wi, sample2).first;
            wo = facet::reflect(wi, m);
            bs.sampled_type = BSDFFlags::GlossyReflection;
            bs.sampled_component = m_comp_spec_refl;
            if (!(wo.z > 0.f && compatible(m, wi, wo, wi.z, true))) return {bs, Color3f(0.f)};
        } else if (u < prob.spec_refl + prob.spec_trans) {
            // Reflect about the (rougher) transmission normal, then pass through the sheet.
            Vector3f m = trans_distribution(p).sample(wi, sample2).first;
            wo = facet::reflect(wi, m);
            wo.z = -wo.z;
            bs.sampled_type = BSDFFlags::GlossyTransmission;
            bs.sampled_component = m_comp_spec_trans;
            if (!(wo.z < 0.f && compatible(m, wi, wo, wi.z, false))) return {bs, Color3f(0.f)};
        } else if (u < prob.spec_refl + prob.spec_trans + prob.diff_refl) {
            wo = warp::square_to_cosine_hemisphere(sample2);
            bs.sampled_type = BSDFFlags::DiffuseReflection;
            bs.sampled_component = 0;
        } else {
            wo = -warp::square_to_cosine_hemisphere(sample2);
            bs.sampled_type = BSDFFlags::DiffuseTransmission;
            bs.sampled_component = 1;
        }
        bs.wo = wo * side;
        auto [value, pdf] = eval_pdf_at(si, bs.wo, p, prob);
        if (!(pdf > 0.f)) return {bs, Color3f(0.f)};
        bs.pdf = pdf;
        return {bs, value / pdf};
    }

    Color3f eval(const BSDFContext &ctx, const SurfaceInteraction &si,
                 const Vector3f &wo) const override {
        return eval_pdf(ctx, si, wo).first;
    }

    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
              const Vector3f &wo) const override {
        return eval_pdf(ctx, si, wo).second;
    }

    std::pair<Color3f, float> eval_pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
                                       const Vector3f &wo) const override {
        if (Frame::cos_theta(si.wi) == 0.f) return {Color3f(0.f), 0.f};
        Point p = at(si);
        return eval_pdf_at(si, wo, p, probabilities(p, enabled(ctx)));
    }

    Color3f eval_diffuse_reflectance(const SurfaceInteraction &si) const override {
        return m_base_color->eval(si);
    }

    bool prefetch(const SurfaceInteraction &si) const override {
        bool started = false;
        for (const auto *t : {&m_base_color, &m_roughness, &m_anisotropic, &m_spec_trans, &m_eta,
                              &m_spec_tint, &m_sheen, &m_sheen_tint, &m_flatness, &m_diff_trans})
            started |= facet::prefetch(*t, si);
        return started;
    }

    std::string to_string() const override {
        return fmt::format(
            "PrincipledThin[base_color = {}, roughness = {}, anisotropic = {}, spec_trans = {}, "
            "eta = {}, spec_tint = {}, sheen = {}, sheen_tint = {}, flatness = {}, diff_trans = "
            "{}, sampling rates (specular reflection, specular transmission, diffuse reflection, "
            "diffuse transmission) = ({}, {}, {}, {})]",
            m_base_color->to_string(), m_roughness->to_string(), m_anisotropic->to_string(),
            m_spec_trans->to_string(), m_eta->to_string(), m_spec_tint->to_string(),
            m_sheen->to_string(), m_sheen_tint->to_string(), m_flatness->to_string(),
            m_diff_trans->to_string(), m_spec_refl_srate, m_spec_trans_srate, m_diff_refl_srate,
            m_diff_trans_srate);
    }

private:
    struct Point {
        Color3f base_color;
        Color3f tint; ///< the base colour normalised by its luminance (if a tint is used)
        float roughness, anisotropic, spec_trans, eta, spec_tint, sheen, sheen_tint, flatness;
        float diff_trans; ///< diff_trans/2, in [0, 1]
    };

    struct Enabled {
        bool diff_refl, diff_trans, spec_trans, spec_refl;
    };

    /// Unnormalised lobe probabilities, with the lobe switches of the context folded in (a
    /// disabled lobe is neither sampled nor evaluated).
    struct Probabilities {
        Enabled on;
        float spec_refl = 0.f, spec_trans = 0.f, diff_refl = 0.f, diff_trans = 0.f, total = 0.f;
    };

    static float rate(const Properties &props, const char *name) {
        float r = float(props.get_float(name, 1.0));
        if (!(r >= 0.f))
            FACET_THROW_AT(props.location(name), "principledthin: {} must be >= 0, got {}", name,
                           r);
        return r;
    }

    Point at(const SurfaceInteraction &si) const {
        Point p;
        p.base_color = m_base_color->eval(si);
        if (m_has_spec_tint || m_has_sheen_tint)
            p.tint =
                tint_color(p.base_color, tint_luminance(p.base_color, si.wavelengths, m_spectral));
        p.roughness = m_roughness->eval_1(si);
        p.anisotropic = m_has_anisotropic ? m_anisotropic->eval_1(si) : 0.f;
        p.spec_trans = m_has_spec_trans ? m_spec_trans->eval_1(si) : 0.f;
        p.eta = m_eta->eval_1(si);
        p.spec_tint = m_has_spec_tint ? m_spec_tint->eval_1(si) : 0.f;
        p.sheen = m_has_sheen ? m_sheen->eval_1(si) : 0.f;
        p.sheen_tint = m_has_sheen_tint ? m_sheen_tint->eval_1(si) : 0.f;
        p.flatness = m_has_flatness ? m_flatness->eval_1(si) : 0.f;
        p.diff_trans = m_has_diff_trans ? 0.5f * m_diff_trans->eval_1(si) : 0.f;
        return p;
    }

    Enabled enabled(const BSDFContext &ctx) const {
        Enabled on;
        on.diff_refl = ctx.is_enabled(BSDFFlags::DiffuseReflection, 0);
        on.diff_trans = m_has_diff_trans && ctx.is_enabled(BSDFFlags::DiffuseTransmission, 1);
        on.spec_trans =
            m_has_spec_trans && ctx.is_enabled(BSDFFlags::GlossyTransmission, m_comp_spec_trans);
        on.spec_refl =
            m_has_spec_trans && ctx.is_enabled(BSDFFlags::GlossyReflection, m_comp_spec_refl);
        return on;
    }

    Probabilities probabilities(const Point &p, const Enabled &on) const {
        Probabilities prob;
        prob.on = on;
        if (on.spec_refl) prob.spec_refl = 0.5f * p.spec_trans * m_spec_refl_srate;
        if (on.spec_trans) prob.spec_trans = 0.5f * p.spec_trans * m_spec_trans_srate;
        if (on.diff_refl)
            prob.diff_refl = m_diff_refl_srate * (1.f - p.spec_trans) * (1.f - p.diff_trans);
        if (on.diff_trans)
            prob.diff_trans = m_diff_trans_srate * (1.f - p.spec_trans) * p.diff_trans;
        prob.total = prob.spec_refl + prob.spec_trans + prob.diff_refl + prob.diff_trans;
        return prob;
    }

    MicrofacetDistribution reflect_distribution(const Point &p) const {
        auto [ax, ay] = alphas(p.roughness, p.anisotropic, m_has_anisotropic);
        return MicrofacetDistribution(MicrofacetType::GGX, ax, ay, m_sample_visible);
    }

    /// Transmission roughness scaled by (0.65η − 0.35) (Burley 2015, fig. 15).
    MicrofacetDistribution trans_distribution(const Point &p) const {
        auto [ax, ay] =
            alphas((0.65f * p.eta - 0.35f) * p.roughness, p.anisotropic, m_has_anisotropic);
        return MicrofacetDistribution(MicrofacetType::GGX, ax, ay, m_sample_visible);
    }

    std::pair<Color3f, float> eval_pdf_at(const SurfaceInteraction &si, const Vector3f &wo_world,
                                          const Point &p, const Probabilities &prob) const {
        if (!(prob.total > 0.f)) return {Color3f(0.f), 0.f};
        const Enabled &on = prob.on;
        float side = Frame::cos_theta(si.wi) > 0.f ? 1.f : -1.f;
        Vector3f wi = si.wi * side, wo = wo_world * side;
        float cos_i = wi.z, cos_o = wo.z;
        bool reflect = cos_o > 0.f, refract = cos_o < 0.f;
        if (!reflect && !refract) return {Color3f(0.f), 0.f};

        // The half vector of wi and wo mirrored to wi's side of the sheet.
        Vector3f wo_r(wo.x, wo.y, std::abs(wo.z));
        Vector3f h = normalize(wi + wo_r);
        if (!is_finite(h)) return {Color3f(0.f), 0.f};
        bool refl_ok = reflect && compatible(h, wi, wo, cos_i, true);
        bool trans_ok = refract && compatible(h, wi, wo, cos_i, false);

        Color3f value(0.f);
        float pdf = 0.f;
        float jacobian = 1.f / (4.f * std::abs(dot(wo_r, h)));
        if (p.spec_trans > 0.f && (refl_ok || trans_ok)) {
            float F = fresnel_dielectric(dot(wi, h), p.eta).F;
            if (refl_ok && on.spec_refl) {
                MicrofacetDistribution distr = reflect_distribution(p);
                Color3f Ft = thin_fresnel(F, p.spec_tint, p.tint, dot(wi, h), p.eta);
                value += Ft * (p.spec_trans * distr.eval(h) * distr.G(wi, wo, h) / (4.f * cos_i));
                pdf += prob.spec_refl * distr.pdf(wi, h) * jacobian;
            }
            if (trans_ok && on.spec_trans) {
                MicrofacetDistribution distr = trans_distribution(p);
                value += p.base_color * (p.spec_trans * (1.f - F) * distr.eval(h) *
                                         distr.G(wi, wo, h) / (4.f * cos_i));
                pdf += prob.spec_trans * distr.pdf(wi, h) * jacobian;
            }
        }
        if (reflect && on.diff_refl && p.spec_trans < 1.f && p.diff_trans < 1.f) {
            float cos_d = dot(h, wo);
            float f = diffuse_factor(cos_i, cos_o, cos_d, p.roughness, p.flatness, m_has_flatness);
            float w = (1.f - p.spec_trans) * (1.f - p.diff_trans);
            value += p.base_color * (w * cos_o * InvPi * f);
            if (p.sheen > 0.f)
                value += sheen_color(p.tint, p.sheen_tint, cos_d) * (p.sheen * w * cos_o);
            pdf += prob.diff_refl * warp::square_to_cosine_hemisphere_pdf(wo);
        }
        if (refract && on.diff_trans && p.spec_trans < 1.f && p.diff_trans > 0.f) {
            value += p.base_color * ((1.f - p.spec_trans) * p.diff_trans * InvPi * -cos_o);
            pdf += prob.diff_trans * warp::square_to_cosine_hemisphere_pdf(-wo);
        }
        return {value, pdf / prob.total};
    }

    std::shared_ptr<Texture> m_base_color, m_roughness, m_anisotropic, m_spec_trans, m_eta,
        m_spec_tint, m_sheen, m_sheen_tint, m_flatness, m_diff_trans;
    float m_spec_refl_srate, m_spec_trans_srate, m_diff_trans_srate, m_diff_refl_srate;
    bool m_sample_visible;
    bool m_spectral; ///< the tint's luminance is taken at the path's wavelengths
    bool m_has_anisotropic, m_has_spec_trans, m_has_sheen, m_has_sheen_tint, m_has_flatness,
        m_has_spec_tint, m_has_diff_trans;
    uint32_t m_comp_spec_trans = uint32_t(-1), m_comp_spec_refl = 2;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::PrincipledThin, BSDF, "principledthin",
                          "The thin-sheet principled BSDF (Mitsuba 3's principledthin)", DOC,
                          ::facet::AllModes)
