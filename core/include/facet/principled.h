#pragma once

#include <facet/color.h>
#include <facet/frame.h>
#include <facet/fresnel.h>
#include <facet/math.h>
#include <facet/properties.h>
#include <facet/spectrum.h>

#include <cmath>
#include <string>
#include <utility>

/// Physics shared by the Disney/Burley "principled" BSDFs (`principled`, `principledthin`), in
/// the form Mitsuba 3 uses: Schlick weights and Fresnel, the tint colour, the anisotropic roughness
/// map, the GTR1 clearcoat distribution and its separable masking, the Burley diffuse with retro-
/// reflection, the Hanrahan–Krueger "flatness" term and the sheen. Burley 2012 ("Physically Based
/// Shading at Disney") and Burley 2015 ("Extending the Disney BRDF to a BSDF with Integrated
/// Subsurface Scattering"). Directions are in the local shading frame.
namespace facet::principled {

/// True when the scene gives `name` and it is not the plain number 0 (a lobe switched on): a
/// texture or any non-zero value enables the lobe, like Mitsuba's principled plugins.
inline bool lobe_present(const Properties &props, const std::string &name) {
    if (!props.has(name)) return false;
    if (props.type(name) == Properties::Type::Float) return props.get_float(name) != 0.0;
    if (props.type(name) == Properties::Type::Integer) return props.get_int(name) != 0;
    return true;
}

/// Schlick's weight (1 − cos θ)⁵, the argument clamped to [0, 1].
inline float schlick_weight(float cos_theta) {
    float m = clamp(1.f - cos_theta, 0.f, 1.f);
    return (m * m) * (m * m) * m;
}

/// Normal-incidence reflectance ((η − 1)/(η + 1))² of a dielectric.
inline float schlick_r0(float eta) { return sqr((eta - 1.f) / (eta + 1.f)); }

/**
 * Schlick's approximation R0 + (1 − R0)·(1 − cos)⁵ at the microfacet cosine `cos_i` of an
 * interface with relative IOR `eta`: from the optically thinner side the incident cosine is used,
 * from the denser side the refracted one (1 under total internal reflection).
 */
template <typename T> T schlick_fresnel(const T &r0, float cos_i, float eta) {
    bool outside = cos_i >= 0.f;
    float eta_it = outside ? eta : 1.f / eta, eta_ti = outside ? 1.f / eta : eta;
    float w;
    if (eta_it > 1.f) {
        w = schlick_weight(std::abs(cos_i));
    } else {
        float cos_t = safe_sqrt(1.f - (1.f - cos_i * cos_i) * eta_ti * eta_ti);
        w = schlick_weight(cos_t);
    }
    return r0 * (1.f - w) + T(1.f) * w;
}

/**
 * The luminance the tint normalises the base colour by, as Mitsuba 3 takes it: Rec.709 Y of an
 * RGB colour (of mono's equal channels: the value); in the spectral modes (`spectral`) the mean
 * over the path's wavelengths `lambda` of ȳ(λ)·value, with the CIE 1931 ȳ (peak 1) and no
 * division by the wavelengths' density.
 */
inline float tint_luminance(const Color3f &base_color, const Wavelengths &lambda, bool spectral) {
    if (!spectral) return base_color.luminance();
    float sum = 0.f;
    for (int i = 0; i < Color3f::Channels; ++i) sum += cie1931_xyz(lambda[i]).g * base_color[i];
    return sum * (1.f / float(Color3f::Channels));
}

/// The base colour normalised by its luminance `lum` (tint_luminance(); white where it is zero).
inline Color3f tint_color(const Color3f &base_color, float lum) {
    return lum > 0.f ? base_color / lum : Color3f(1.f);
}

/**
 * Roughness and anisotropy to the GGX (αu, αv) of Burley 2012 (addendum B.2):
 * aspect = √(1 − 0.9·anisotropic), αu = r²/aspect, αv = r²·aspect, both at least 0.001.
 */
inline std::pair<float, float> alphas(float roughness, float anisotropic, bool has_anisotropic) {
    float r2 = roughness * roughness;
    if (!has_anisotropic) {
        float a = std::max(0.001f, r2);
        return {a, a};
    }
    float aspect = std::sqrt(1.f - 0.9f * anisotropic);
    return {std::max(0.001f, r2 / aspect), std::max(0.001f, r2 * aspect)};
}

/**
 * Whether the microfacet normal m agrees with the macro surface for the pair (wi, wo): both on
 * m's side for reflection; wi on m's side and wo on the other for transmission (m taken on wi's
 * side of the macro surface, given by the sign of cos_i).
 */
inline bool compatible(const Vector3f &m, const Vector3f &wi, const Vector3f &wo, float cos_i,
                       bool reflection) {
    Vector3f ms = m * (std::signbit(cos_i) ? -1.f : 1.f);
    if (dot(wi, ms) <= 0.f) return false;
    return reflection ? dot(wo, ms) > 0.f : dot(wo, ms) < 0.f;
}

/**
 * Burley's GTR1 ("generalised Trowbridge–Reitz", γ = 1) isotropic normal distribution of the
 * clearcoat: D(m) = (α² − 1)/(π·ln α²·(1 + (α² − 1)·cos²θm)), normalised so that
 * ∫ D cos θm dω = 1; sampled exactly in proportion to D·cos θm (Burley 2012, eq. 4 and B.2).
 */
class GTR1 {
public:
    explicit GTR1(float alpha) : m_alpha(alpha) {}
    float alpha() const { return m_alpha; }

    float eval(const Vector3f &m) const {
        float cos2 = sqr(Frame::cos_theta(m)), a2 = m_alpha * m_alpha;
        float d = (a2 - 1.f) / (Pi * std::log(a2) * (1.f + (a2 - 1.f) * cos2));
        return d * Frame::cos_theta(m) > 1e-20f ? d : 0.f;
    }
    /// Density of sample() per unit solid angle of m: D(m)·cos θm.
    float pdf(const Vector3f &m) const { return m.z < 0.f ? 0.f : Frame::cos_theta(m) * eval(m); }
    /// Inverts the CDF of cos²θm: cos²θ = (1 − α^(2(1 − u)))/(1 − α²).
    Vector3f sample(const Point2f &u) const {
        float phi = 2.f * Pi * u.x, a2 = m_alpha * m_alpha;
        float cos2 = (1.f - std::pow(a2, 1.f - u.y)) / (1.f - a2);
        float sin_t = safe_sqrt(1.f - cos2), cos_t = safe_sqrt(cos2);
        return {std::cos(phi) * sin_t, std::sin(phi) * sin_t, cos_t};
    }

private:
    float m_alpha;
};

/// The clearcoat roughness: α = 0.1 at clearcoat_gloss 0 down to 0.001 at 1.
inline float clearcoat_alpha(float gloss) { return 0.1f + (0.001f - 0.1f) * gloss; }

/// Isotropic Smith GGX masking G1(v) with roughness α (the clearcoat's fixed α = 0.25); zero when
/// v sees the back of the microfacet h.
inline float smith_ggx1(const Vector3f &v, const Vector3f &h, float alpha) {
    if (dot(v, h) * Frame::cos_theta(v) <= 0.f) return 0.f;
    if (v.z == 1.f) return 1.f;
    float c2 = sqr(Frame::cos_theta(v)), tan2 = (1.f - c2) / c2;
    return 2.f / (1.f + std::sqrt(1.f + alpha * alpha * tan2));
}

/// Separable masking-shadowing of the clearcoat, G1(wi)·G1(wo) with α = 0.25.
inline float clearcoat_g(const Vector3f &wi, const Vector3f &wo, const Vector3f &h) {
    return smith_ggx1(wi, h, 0.25f) * smith_ggx1(wo, h, 0.25f);
}

/**
 * The scalar factor of Burley's diffuse (without base_color/π and the cosine): the Schlick-shaped
 * Lambert term (1 − Fi/2)(1 − Fo/2) plus retro-reflection R_R(Fo + Fi + Fo·Fi·(R_R − 1)),
 * R_R = 2·roughness·cos²θd, blended by `flatness` towards the Hanrahan–Krueger-like term
 * 1.25·(Fss·(1/(|cos θo| + |cos θi|) − 0.5) + 0.5), Fss = (1 + (F_SS90 − 1)Fo)(1 + (F_SS90 − 1)Fi),
 * F_SS90 = R_R/2 (Burley 2015, §5.3). `cos_d` is the cosine between the half vector and wo.
 */
inline float diffuse_factor(float cos_i, float cos_o, float cos_d, float roughness, float flatness,
                            bool has_flatness) {
    float fo = schlick_weight(std::abs(cos_o)), fi = schlick_weight(std::abs(cos_i));
    float f_diff = (1.f - 0.5f * fi) * (1.f - 0.5f * fo);
    float rr = 2.f * roughness * cos_d * cos_d;
    float f_retro = rr * (fo + fi + fo * fi * (rr - 1.f));
    if (!has_flatness) return f_diff + f_retro;
    float fss90 = 0.5f * rr;
    float fss = (1.f + (fss90 - 1.f) * fo) * (1.f + (fss90 - 1.f) * fi);
    float f_ss = 1.25f * (fss * (1.f / (std::abs(cos_o) + std::abs(cos_i)) - 0.5f) + 0.5f);
    return (f_diff + f_retro) * (1.f - flatness) + f_ss * flatness;
}

/// Sheen colour: white blended towards the tint (the luminance-normalised base colour,
/// tint_color()) by `sheen_tint`, times the Schlick weight of cos θd (Burley 2012, B.1). Without
/// the cosine and the lobe weights.
inline Color3f sheen_color(const Color3f &tint_colour, float sheen_tint, float cos_d) {
    Color3f tint = sheen_tint > 0.f ? Color3f(1.f) * (1.f - sheen_tint) + tint_colour * sheen_tint
                                    : Color3f(1.f);
    return tint * schlick_weight(std::abs(cos_d));
}

/**
 * The Fresnel term of `principled`'s main specular lobe: on the front side a blend of the true
 * dielectric Fresnel F_d (weight (1 − metallic)(1 − spec_tint)), Schlick with base_color as R0
 * (weight metallic) and Schlick with the tinted R0 = tint·((η − 1)/(η + 1))² (weight
 * (1 − metallic)·spec_tint); on the back side only the dielectric part, weighted by the
 * transmission lobe's share `bsdf` = (1 − metallic)·spec_trans.
 */
inline Color3f principled_fresnel(float F_d, float metallic, float spec_tint,
                                  const Color3f &base_color, const Color3f &tint_colour,
                                  float cos_i, bool front_side, float bsdf, float eta) {
    if (!front_side) return Color3f(bsdf * F_d);
    float eta_it = cos_i >= 0.f ? eta : 1.f / eta;
    Color3f F = Color3f((1.f - metallic) * (1.f - spec_tint) * F_d);
    if (metallic > 0.f) F += metallic * schlick_fresnel(base_color, cos_i, eta);
    if (spec_tint > 0.f)
        F += (1.f - metallic) * spec_tint *
             schlick_fresnel(tint_colour * schlick_r0(eta_it), cos_i, eta);
    return F;
}

/// `principledthin`'s Fresnel: F_d blended by spec_tint towards Schlick with the tinted R0
/// (`tint_colour`, tint_color()).
inline Color3f thin_fresnel(float F_d, float spec_tint, const Color3f &tint_colour, float cos_i,
                            float eta) {
    if (!(spec_tint > 0.f)) return Color3f(F_d);
    Color3f F_s = schlick_fresnel(tint_colour * schlick_r0(eta), cos_i, eta);
    return Color3f(F_d) * (1.f - spec_tint) + F_s * spec_tint;
}

} // namespace facet::principled
