static const char *DOC = R"DOC(
# principled: the Disney/Burley principled BSDF

Burley's "principled" material (2012, with the transmission of 2015) as Mitsuba 3 has it: a base
that blends a Burley diffuse with retro-reflection (and a Hanrahan–Krueger-like flattening), a
sheen, a GGX main specular lobe that reflects and (with spec_trans) refracts, and a GTR1 clearcoat.
Lobe weights: diffuse (1 − metallic)(1 − spec_trans), transmission (1 − metallic)·spec_trans,
sheen sheen·(1 − metallic), clearcoat clearcoat/4. The main specular Fresnel mixes the true
dielectric Fresnel (weight (1 − metallic)(1 − spec_tint)), Schlick with R0 = base_color (weight
metallic) and Schlick with the tinted R0 (weight (1 − metallic)·spec_tint); refracted light is
tinted by √base_color. From the back side only the dielectric reflection and transmission remain
(weighted by (1 − metallic)·spec_trans). The GGX roughness is αu = r²/a, αv = r²·a with
a = √(1 − 0.9·anisotropic) (at least 0.001); the clearcoat's GTR1 roughness goes from 0.1 at
clearcoat_gloss 0 to 0.001 at 1. As in Mitsuba the clearcoat term is 0.25·clearcoat·F·D·G·cos θo
(Schlick F with R0 = 0.04, separable GGX masking with α = 0.25).

Sampling picks the diffuse lobe (cosine-weighted), the clearcoat (GTR1 normals) or the main
specular lobe (GGX visible normals) with probabilities proportional to (1 − metallic)(1 −
spec_trans)·diffuse_reflectance_sampling_rate, clearcoat/4·clearcoat_sampling_rate and
main_specular_sampling_rate; the main lobe then reflects or refracts with probabilities
1 − bsdf·(1 − F) and bsdf·(1 − F) (F the dielectric Fresnel of the sampled normal). From the back
side it reflects with probability F and refracts with 1 − F.

Every scalar is a number or a texture (queried as a scalar); a lobe whose parameter is absent or
the plain number 0 is switched off. The parameters should lie in [0, 1] apart from the sampling
rates and eta.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| base_color | spectrum or texture | 0.5 | Colour of the material |
| roughness | float or texture | 0.5 | Roughness r of the main specular lobes (α = r²) |
| anisotropic | float or texture | 0.0 | Degree of anisotropy (0: isotropic) |
| metallic | float or texture | 0.0 | Metallicness: blends the dielectric model into a Schlick conductor with R0 = base_color |
| spec_trans | float or texture | 0.0 | Blends the opaque base (0) into the refracting dielectric lobe (1) |
| eta | float | — | Relative IOR η_inside/η_outside of the dielectric lobes (not together with specular) |
| specular | float | 0.5 | Fresnel reflectance at normal incidence, as 0.08·specular: η = 2/(1 − √(0.08·specular)) − 1 (not together with eta) |
| spec_tint | float or texture | 0.0 | Fraction of the dielectric reflection tinted towards base_color |
| sheen | float or texture | 0.0 | Weight of the sheen lobe |
| sheen_tint | float or texture | 0.0 | Fraction of the sheen tinted towards base_color |
| flatness | float or texture | 0.0 | Blends the diffuse response (0) into the fake subsurface term (1) |
| clearcoat | float or texture | 0.0 | Weight of the clearcoat lobe |
| clearcoat_gloss | float or texture | 0.0 | Glossiness of the clearcoat (0: α = 0.1, 1: α = 0.001) |
| diffuse_reflectance_sampling_rate | float | 1.0 | Relative rate of sampling the diffuse lobe |
| main_specular_sampling_rate | float | 1.0 | Relative rate of sampling the main specular lobe |
| clearcoat_sampling_rate | float | 1.0 | Relative rate of sampling the clearcoat lobe |
| sample_visible | boolean | true | Sample the GGX normals visible from wi (Heitz & d'Eon 2014); Mitsuba always does |

Components, in order: the diffuse base with sheen (DiffuseReflection, front side), the clearcoat
(GlossyReflection, front side; only with clearcoat), the specular transmission (GlossyTransmission,
both sides, non-symmetric; only with spec_trans) and the main specular reflection
(GlossyReflection, both sides). With spec_trans, η = 1 becomes 1.001 (and specular 0 becomes
0.001), as in Mitsuba. Giving both eta and specular, eta <= 0, specular outside [0, 12.5) or a
negative sampling rate is an error.

```xml
<bsdf type="principled">
    <rgb name="base_color" value="0.8, 0.3, 0.1"/>
    <float name="metallic" value="0.2"/>
    <float name="roughness" value="0.3"/>
    <float name="clearcoat" value="0.6"/>
    <float name="clearcoat_gloss" value="0.9"/>
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

class Principled final : public BSDF {
public:
    explicit Principled(const Properties &props) {
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
        m_has_metallic = lobe_present(props, "metallic");
        m_metallic = props.texture("metallic", 0.f);
        m_has_clearcoat = lobe_present(props, "clearcoat");
        m_clearcoat = props.texture("clearcoat", 0.f);
        m_clearcoat_gloss = props.texture("clearcoat_gloss", 0.f);
        m_spec_srate = rate(props, "main_specular_sampling_rate");
        m_clearcoat_srate = rate(props, "clearcoat_sampling_rate");
        m_diff_srate = rate(props, "diffuse_reflectance_sampling_rate");
        m_sample_visible = props.get_bool("sample_visible", true);

        if (props.has("eta") && props.has("specular"))
            FACET_THROW_AT(props.location(), "principled: give either eta or specular, not both "
                                             "(they set the same index of refraction)");
        if (props.has("eta")) {
            m_eta_given = true;
            m_eta = float(props.get_float("eta"));
            if (!(m_eta > 0.f))
                FACET_THROW_AT(props.location("eta"),
                               "principled: eta must be a positive relative IOR, got {}", m_eta);
            // η = 1 has no interface to refract at.
            if (m_has_spec_trans && m_eta == 1.f) m_eta = 1.001f;
        } else {
            m_specular = float(props.get_float("specular", 0.5));
            if (!(m_specular >= 0.f && m_specular < 12.5f))
                FACET_THROW_AT(props.has("specular") ? props.location("specular")
                                                     : props.location(),
                               "principled: specular must be in [0, 12.5) (normal-incidence "
                               "reflectance 0.08·specular < 1), got {}",
                               m_specular);
            if (m_has_spec_trans && m_specular == 0.f) m_specular = 1e-3f;
            m_eta = 2.f / (1.f - std::sqrt(0.08f * m_specular)) - 1.f;
        }

        auto sv = [](const std::shared_ptr<Texture> &t) {
            return varies(t) ? BSDFFlags::SpatiallyVarying : BSDFFlags::Empty;
        };
        BSDFFlags common = sv(m_base_color) | sv(m_roughness) | sv(m_metallic) | sv(m_spec_trans) |
                           sv(m_anisotropic) | sv(m_spec_tint);
        BSDFFlags aniso = m_has_anisotropic ? BSDFFlags::Anisotropic : BSDFFlags::Empty;
        std::vector<BSDFFlags> components;
        m_comp_diffuse = uint32_t(components.size());
        components.push_back(BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide | common |
                             sv(m_sheen) | sv(m_sheen_tint) | sv(m_flatness));
        if (m_has_clearcoat) {
            m_comp_clearcoat = uint32_t(components.size());
            components.push_back(BSDFFlags::GlossyReflection | BSDFFlags::FrontSide |
                                 sv(m_clearcoat) | sv(m_clearcoat_gloss));
        }
        if (m_has_spec_trans) {
            m_comp_trans = uint32_t(components.size());
            components.push_back(BSDFFlags::GlossyTransmission | BSDFFlags::FrontSide |
                                 BSDFFlags::BackSide | BSDFFlags::NonSymmetric | aniso | common);
        }
        m_comp_spec = uint32_t(components.size());
        components.push_back(BSDFFlags::GlossyReflection | BSDFFlags::FrontSide |
                             BSDFFlags::BackSide | aniso | common);
        set_components(std::move(components));
    }

    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float sample1, const Point2f &sample2) const override {
        BSDFSample bs;
        float cos_i = Frame::cos_theta(si.wi);
        if (cos_i == 0.f) return {bs, Color3f(0.f)};
        Point p = at(si);
        Enabled on = enabled(ctx);
        bool front = cos_i > 0.f;
        // From inside only the dielectric lobes exist.
        if (!front && !(p.bsdf > 0.f)) return {bs, Color3f(0.f)};

        MicrofacetDistribution distr = spec_distribution(p);
        Vector3f wi_up = si.wi * (front ? 1.f : -1.f);
        Vector3f m_spec = distr.sample(wi_up, sample2).first;
        FresnelResult fr = fresnel_dielectric(dot(si.wi, m_spec), m_eta);
        Probabilities prob = probabilities(p, on, front, fr.F);
        if (!(prob.total > 0.f)) return {bs, Color3f(0.f)};

        bs.eta = 1.f;
        float u = sample1 * prob.total;
        if (u < prob.diffuse) {
            bs.wo = warp::square_to_cosine_hemisphere(sample2);
            bs.sampled_type = BSDFFlags::DiffuseReflection;
            bs.sampled_component = m_comp_diffuse;
            if (!(cos_i * Frame::cos_theta(bs.wo) > 0.f)) return {bs, Color3f(0.f)};
        } else if (u < prob.diffuse + prob.clearcoat) {
            GTR1 cc(clearcoat_alpha(p.clearcoat_gloss));
            Vector3f m = cc.sample(sample2);
            bs.wo = facet::reflect(si.wi, m);
            bs.sampled_type = BSDFFlags::GlossyReflection;
            bs.sampled_component = m_comp_clearcoat;
            if (!(compatible(m, si.wi, bs.wo, cos_i, true) &&
                  cos_i * Frame::cos_theta(bs.wo) > 0.f))
                return {bs, Color3f(0.f)};
        } else if (u < prob.diffuse + prob.clearcoat + prob.trans) {
            bs.wo = refract(si.wi, m_spec, fr.cos_t, fr.eta_ti);
            bs.sampled_type = BSDFFlags::GlossyTransmission;
            bs.sampled_component = m_comp_trans;
            bs.eta = fr.eta_it;
            if (!(compatible(m_spec, si.wi, bs.wo, cos_i, false) &&
                  cos_i * Frame::cos_theta(bs.wo) < 0.f))
                return {bs, Color3f(0.f)};
        } else {
            bs.wo = facet::reflect(si.wi, m_spec);
            bs.sampled_type = BSDFFlags::GlossyReflection;
            bs.sampled_component = m_comp_spec;
            if (!(compatible(m_spec, si.wi, bs.wo, cos_i, true) &&
                  cos_i * Frame::cos_theta(bs.wo) > 0.f))
                return {bs, Color3f(0.f)};
        }
        // A mixture's weight is its value over its density, whichever lobe drew wo.
        auto [value, pdf] = eval_pdf_at(ctx, si, bs.wo, p, on);
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
        return eval_pdf_at(ctx, si, wo, at(si), enabled(ctx));
    }

    Color3f eval_diffuse_reflectance(const SurfaceInteraction &si) const override {
        return m_base_color->eval(si);
    }

    bool prefetch(const SurfaceInteraction &si) const override {
        bool started = false;
        for (const auto *t :
             {&m_base_color, &m_roughness, &m_anisotropic, &m_metallic, &m_spec_trans, &m_spec_tint,
              &m_sheen, &m_sheen_tint, &m_flatness, &m_clearcoat, &m_clearcoat_gloss})
            started |= facet::prefetch(*t, si);
        return started;
    }

    std::string to_string() const override {
        return fmt::format(
            "Principled[base_color = {}, roughness = {}, anisotropic = {}, metallic = {}, "
            "spec_trans = {}, {} = {}, spec_tint = {}, sheen = {}, sheen_tint = {}, flatness = "
            "{}, clearcoat = {}, clearcoat_gloss = {}, sampling rates (diffuse, specular, "
            "clearcoat) = ({}, {}, {})]",
            m_base_color->to_string(), m_roughness->to_string(), m_anisotropic->to_string(),
            m_metallic->to_string(), m_spec_trans->to_string(), m_eta_given ? "eta" : "specular",
            m_eta_given ? m_eta : m_specular, m_spec_tint->to_string(), m_sheen->to_string(),
            m_sheen_tint->to_string(), m_flatness->to_string(), m_clearcoat->to_string(),
            m_clearcoat_gloss->to_string(), m_diff_srate, m_spec_srate, m_clearcoat_srate);
    }

private:
    /// The parameters at one surface point (absent lobes read as 0).
    struct Point {
        Color3f base_color;
        Color3f tint; ///< the base colour normalised by its luminance (if a tint is used)
        float roughness, anisotropic, metallic, spec_trans, spec_tint, sheen, sheen_tint, flatness,
            clearcoat, clearcoat_gloss;
        float brdf, bsdf; ///< weights of the opaque base and of the transmission lobe
    };

    struct Enabled {
        bool diffuse, clearcoat, trans, spec;
    };

    /// Unnormalised lobe-selection probabilities; `total` is independent of the Fresnel term, so
    /// the choice between diffuse, clearcoat and the main lobe does not depend on the sampled
    /// normal (which `pdf` does not know).
    struct Probabilities {
        float diffuse = 0.f, clearcoat = 0.f, trans = 0.f, spec = 0.f, total = 0.f;
    };

    static float rate(const Properties &props, const char *name) {
        float r = float(props.get_float(name, 1.0));
        if (!(r >= 0.f))
            FACET_THROW_AT(props.location(name), "principled: {} must be >= 0, got {}", name, r);
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
        p.metallic = m_has_metallic ? m_metallic->eval_1(si) : 0.f;
        p.spec_trans = m_has_spec_trans ? m_spec_trans->eval_1(si) : 0.f;
        p.spec_tint = m_has_spec_tint ? m_spec_tint->eval_1(si) : 0.f;
        p.sheen = m_has_sheen ? m_sheen->eval_1(si) : 0.f;
        p.sheen_tint = m_has_sheen_tint ? m_sheen_tint->eval_1(si) : 0.f;
        p.flatness = m_has_flatness ? m_flatness->eval_1(si) : 0.f;
        p.clearcoat = m_has_clearcoat ? m_clearcoat->eval_1(si) : 0.f;
        p.clearcoat_gloss = m_has_clearcoat ? m_clearcoat_gloss->eval_1(si) : 0.f;
        p.brdf = (1.f - p.metallic) * (1.f - p.spec_trans);
        p.bsdf = (1.f - p.metallic) * p.spec_trans;
        return p;
    }

    Enabled enabled(const BSDFContext &ctx) const {
        Enabled on;
        on.diffuse = ctx.is_enabled(BSDFFlags::DiffuseReflection, m_comp_diffuse);
        on.clearcoat =
            m_has_clearcoat && ctx.is_enabled(BSDFFlags::GlossyReflection, m_comp_clearcoat);
        on.trans = m_has_spec_trans && ctx.is_enabled(BSDFFlags::GlossyTransmission, m_comp_trans);
        on.spec = ctx.is_enabled(BSDFFlags::GlossyReflection, m_comp_spec);
        return on;
    }

    MicrofacetDistribution spec_distribution(const Point &p) const {
        auto [ax, ay] = alphas(p.roughness, p.anisotropic, m_has_anisotropic);
        return MicrofacetDistribution(MicrofacetType::GGX, ax, ay, m_sample_visible);
    }

    Probabilities probabilities(const Point &p, const Enabled &on, bool front, float F) const {
        Probabilities prob;
        // The main lobe's mass (rate on the front side, 1 from inside) is split between
        // reflection and refraction by the Fresnel term; a lobe alone takes all of it.
        float main = front ? m_spec_srate : 1.f;
        float refl_share = front ? 1.f - p.bsdf * (1.f - F) : F;
        if (on.spec && on.trans) {
            prob.spec = main * refl_share;
            prob.trans = main * (1.f - refl_share);
        } else if (on.spec) {
            prob.spec = main;
        } else if (on.trans) {
            prob.trans = main;
        }
        if (front) {
            if (on.clearcoat) prob.clearcoat = 0.25f * p.clearcoat * m_clearcoat_srate;
            if (on.diffuse) prob.diffuse = p.brdf * m_diff_srate;
        }
        prob.total = prob.diffuse + prob.clearcoat + prob.spec + prob.trans;
        return prob;
    }

    std::pair<Color3f, float> eval_pdf_at(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          const Vector3f &wo, const Point &p,
                                          const Enabled &on) const {
        const Vector3f &wi = si.wi;
        float cos_i = Frame::cos_theta(wi), cos_o = Frame::cos_theta(wo);
        bool reflect = cos_i * cos_o > 0.f, refract = cos_i * cos_o < 0.f;
        bool front = cos_i > 0.f;
        if (!reflect && !refract) return {Color3f(0.f), 0.f};
        float eta_path = front ? m_eta : 1.f / m_eta;

        // Half vector (generalised for refraction, Walter et al. 2007 eq. 16), pointing up.
        Vector3f h = normalize(wi + wo * (reflect ? 1.f : eta_path));
        if (h.z < 0.f) h = -h;
        if (!is_finite(h)) return {Color3f(0.f), 0.f};
        float wi_h = dot(wi, h), wo_h = dot(wo, h);

        MicrofacetDistribution distr = spec_distribution(p);
        FresnelResult fr = fresnel_dielectric(wi_h, m_eta);
        float F = fr.F;
        bool refl_ok = reflect && compatible(h, wi, wo, cos_i, true);
        bool trans_ok = refract && compatible(h, wi, wo, cos_i, false);

        Color3f value(0.f);
        float D = distr.eval(h);
        if (on.spec && refl_ok && F > 0.f) {
            Color3f Fp = principled_fresnel(F, p.metallic, p.spec_tint, p.base_color, p.tint, wi_h,
                                            front, p.bsdf, m_eta);
            value += Fp * (D * distr.G(wi, wo, h) / (4.f * std::abs(cos_i)));
        }
        if (on.trans && trans_ok && p.bsdf > 0.f && F < 1.f) {
            // Walter et al. 2007 eq. 21; radiance is compressed by 1/η² across the interface.
            float scale = ctx.mode == TransportMode::Radiance ? 1.f / sqr(eta_path) : 1.f;
            float t = std::abs(scale * (1.f - F) * D * distr.G(wi, wo, h) * sqr(eta_path) * wi_h *
                               wo_h / (cos_i * sqr(wi_h + eta_path * wo_h)));
            const Color3f tint =
                map(p.base_color, [](float c) { return std::sqrt(std::max(c, 0.f)); });
            value += tint * (p.bsdf * t);
        }
        if (on.clearcoat && refl_ok && front && p.clearcoat > 0.f) {
            float Fcc = schlick_fresnel(0.04f, wi_h, m_eta);
            float Dcc = GTR1(clearcoat_alpha(p.clearcoat_gloss)).eval(h);
            value +=
                Color3f(0.25f * p.clearcoat * Fcc * Dcc * clearcoat_g(wi, wo, h) * std::abs(cos_o));
        }
        if (on.diffuse && reflect && front) {
            float cos_d = dot(h, wo);
            if (p.brdf > 0.f) {
                float f =
                    diffuse_factor(cos_i, cos_o, cos_d, p.roughness, p.flatness, m_has_flatness);
                value += p.base_color * (p.brdf * std::abs(cos_o) * InvPi * f);
            }
            if (p.sheen > 0.f && 1.f - p.metallic > 0.f)
                value += sheen_color(p.tint, p.sheen_tint, cos_d) *
                         (p.sheen * (1.f - p.metallic) * std::abs(cos_o));
        }

        // Density: the lobe probabilities of probabilities() at the Fresnel term of h.
        Probabilities prob = probabilities(p, on, front, F);
        float pdf = 0.f;
        if (prob.total > 0.f) {
            float jacobian = reflect ? 1.f / (4.f * std::abs(wo_h))
                                     : sqr(eta_path) * std::abs(wo_h) / sqr(wi_h + eta_path * wo_h);
            Vector3f wi_up = wi * (front ? 1.f : -1.f);
            if (refl_ok) {
                pdf += prob.spec * distr.pdf(wi_up, h) * jacobian;
                if (prob.clearcoat > 0.f)
                    pdf +=
                        prob.clearcoat * GTR1(clearcoat_alpha(p.clearcoat_gloss)).pdf(h) * jacobian;
            }
            if (reflect) pdf += prob.diffuse * warp::square_to_cosine_hemisphere_pdf(wo);
            if (trans_ok) pdf += prob.trans * distr.pdf(wi_up, h) * jacobian;
            pdf /= prob.total;
        }
        return {value, pdf};
    }

    std::shared_ptr<Texture> m_base_color, m_roughness, m_anisotropic, m_metallic, m_spec_trans,
        m_spec_tint, m_sheen, m_sheen_tint, m_flatness, m_clearcoat, m_clearcoat_gloss;
    float m_eta = 1.5f, m_specular = 0.5f;
    bool m_eta_given = false;
    float m_diff_srate, m_spec_srate, m_clearcoat_srate;
    bool m_sample_visible;
    bool m_spectral; ///< the tint's luminance is taken at the path's wavelengths
    bool m_has_anisotropic, m_has_spec_trans, m_has_sheen, m_has_sheen_tint, m_has_flatness,
        m_has_spec_tint, m_has_metallic, m_has_clearcoat;
    uint32_t m_comp_diffuse = 0, m_comp_clearcoat = uint32_t(-1), m_comp_trans = uint32_t(-1),
             m_comp_spec = 0;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Principled, BSDF, "principled",
                          "The Disney/Burley principled BSDF (Mitsuba 3's principled)", DOC,
                          ::facet::AllModes)
