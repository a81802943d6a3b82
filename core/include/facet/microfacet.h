#pragma once

#include <facet/frame.h>
#include <facet/texture.h>
#include <facet/warp.h>

#include <memory>
#include <string>
#include <utility>

/// Microfacet normal distributions (Beckmann and GGX/Trowbridge-Reitz), their Smith masking
/// functions and the two sampling schemes: all normals by D(m)·cos θm, and the normals visible
/// from a direction (Heitz & d'Eon 2014). Normals and directions are in the local shading frame.
namespace facet {

enum class MicrofacetType : uint32_t { Beckmann = 0, GGX = 1 };

/// "beckmann" or "ggx".
const char *microfacet_type_name(MicrofacetType type);

/**
 * An anisotropic microfacet distribution with roughness αu (along the tangent s) and αv (along t).
 * The struct is small and allocation-free: BSDFs with textured roughness build one per query.
 */
class MicrofacetDistribution {
public:
    /// Smallest roughness kept; smaller values are clamped (the smooth plugins cover α = 0).
    static constexpr float MinAlpha = 1e-4f;
    /// α² tan²θ at and below which Beckmann's visible_normalization() is exactly 1 in float
    /// (a = 1/(α tan θ) ≥ 4).
    static constexpr float BeckmannUnmaskedTan2 = 1.f / 16.f;

    MicrofacetDistribution(MicrofacetType type, float alpha, bool sample_visible = true)
        : MicrofacetDistribution(type, alpha, alpha, sample_visible) {}
    MicrofacetDistribution(MicrofacetType type, float alpha_u, float alpha_v,
                           bool sample_visible = true)
        : m_type(type), m_alpha_u(std::max(alpha_u, MinAlpha)),
          m_alpha_v(std::max(alpha_v, MinAlpha)), m_sample_visible(sample_visible) {}

    MicrofacetType type() const { return m_type; }
    float alpha() const { return m_alpha_u; }
    float alpha_u() const { return m_alpha_u; }
    float alpha_v() const { return m_alpha_v; }
    bool sample_visible() const { return m_sample_visible; }
    bool is_anisotropic() const { return m_alpha_u != m_alpha_v; }

    /// Multiplies both roughnesses (Walter et al.'s widened sampling lobe for rough dielectrics).
    void scale_alpha(float s) {
        m_alpha_u = std::max(m_alpha_u * s, MinAlpha);
        m_alpha_v = std::max(m_alpha_v * s, MinAlpha);
    }

    /// The normal distribution D(m) (per unit solid angle of m, normalised so that
    /// ∫ D(m) cos θm dω = 1). Zero in the lower hemisphere.
    float eval(const Vector3f &m) const {
        float cos_m = Frame::cos_theta(m);
        float cos_m_2 = cos_m * cos_m;
        float e = sqr(m.x / m_alpha_u) + sqr(m.y / m_alpha_v); // tan²θm/α² · cos²θm
        float a_uv = m_alpha_u * m_alpha_v;
        float result;
        if (m_type == MicrofacetType::Beckmann)
            result = std::exp(-e / cos_m_2) / (Pi * a_uv * cos_m_2 * cos_m_2);
        else
            result = 1.f / (Pi * a_uv * sqr(e + cos_m_2));
        // Also removes m in the lower hemisphere and the underflow near grazing normals.
        return result * cos_m > 1e-20f ? result : 0.f;
    }

    /// Smith's masking function G1(v, m) (Walter et al. 2007). For Beckmann this is Walter's
    /// rational approximation of (1 + erf(a) + exp(−a²)/(a√π))⁻¹·2, relative error < 0.35 %.
    float smith_g1(const Vector3f &v, const Vector3f &m) const {
        // A microfacet seen from its back side is masked.
        if (dot(v, m) * Frame::cos_theta(v) <= 0.f) return 0.f;
        float xy_alpha_2 = sqr(m_alpha_u * v.x) + sqr(m_alpha_v * v.y);
        if (xy_alpha_2 == 0.f) return 1.f;               // normal incidence
        float tan_theta_alpha_2 = xy_alpha_2 / sqr(v.z); // α²·tan²θ along v's azimuth
        if (m_type == MicrofacetType::Beckmann) {
            float a = 1.f / std::sqrt(tan_theta_alpha_2);
            if (a >= 1.6f) return 1.f;
            float a2 = a * a;
            return (3.535f * a + 2.181f * a2) / (1.f + 2.276f * a + 2.577f * a2);
        }
        return 2.f / (1.f + std::sqrt(1.f + tan_theta_alpha_2));
    }

    /// Uncorrelated shadowing-masking G(wi, wo, m) = G1(wi, m)·G1(wo, m).
    float G(const Vector3f &wi, const Vector3f &wo, const Vector3f &m) const {
        return smith_g1(wi, m) * smith_g1(wo, m);
    }

    /**
     * The exact Smith masking of the unmasked microfacets seen from v (upper hemisphere), which
     * normalises the distribution of visible normals. Equal to smith_g1() for GGX; for Beckmann
     * it is 2/(1 + erf(a) + exp(−a²)/(a√π)), a = 1/(α tan θ), of which smith_g1() is Walter's fit.
     */
    float visible_normalization(const Vector3f &v) const {
        float xy_alpha_2 = sqr(m_alpha_u * v.x) + sqr(m_alpha_v * v.y);
        if (xy_alpha_2 == 0.f) return 1.f;
        float tan_theta_alpha_2 = xy_alpha_2 / sqr(v.z);
        if (m_type == MicrofacetType::GGX) return 2.f / (1.f + std::sqrt(1.f + tan_theta_alpha_2));
        // From a = 4 on (3.715 would do) the expression below is 1 to the last bit, as a test
        // checks: smooth surfaces and steep views need neither erf nor exp.
        if (tan_theta_alpha_2 <= BeckmannUnmaskedTan2) return 1.f;
        float a = 1.f / std::sqrt(tan_theta_alpha_2);
        const float InvSqrtPi = 0.56418958354775628f;
        return 2.f / (1.f + std::erf(a) + std::exp(-a * a) * InvSqrtPi / a);
    }

    /**
     * Density of sample(wi, ·) per unit solid angle of m; `wi` must be in the upper hemisphere.
     * Visible normals have D_wi(m) = G1(wi)·max(0, wi·m)·D(m)/cos θi (Heitz 2014, eq. 2) with the
     * exact G1 (visible_normalization), so the density integrates to one for Beckmann too.
     */
    float pdf(const Vector3f &wi, const Vector3f &m) const {
        float d = eval(m);
        if (d == 0.f) return 0.f;
        if (m_sample_visible) {
            float cos_i = Frame::cos_theta(wi), wi_dot_m = dot(wi, m);
            if (cos_i <= 0.f || wi_dot_m <= 0.f) return 0.f;
            return d * visible_normalization(wi) * wi_dot_m / cos_i;
        }
        return d * Frame::cos_theta(m);
    }

    /// Samples a microfacet normal for the incident direction `wi` (upper hemisphere); returns the
    /// normal and pdf(wi, m) (zero on failure).
    std::pair<Vector3f, float> sample(const Vector3f &wi, const Point2f &u) const;

    /// Squared roughness along the azimuth of v: cos²φ·αu² + sin²φ·αv².
    float project_roughness_2(const Vector3f &v) const {
        float xy_2 = v.x * v.x + v.y * v.y;
        if (m_alpha_u == m_alpha_v || xy_2 <= 0.f) return m_alpha_u * m_alpha_v;
        return (sqr(v.x * m_alpha_u) + sqr(v.y * m_alpha_v)) / xy_2;
    }
    float project_roughness(const Vector3f &v) const { return std::sqrt(project_roughness_2(v)); }

    /// Slope (x̃, ỹ) of a visible normal of the α = 1 distribution seen at elevation cos θ
    /// from the azimuth φ = 0 (Heitz & d'Eon 2014, step 2).
    Point2f sample_visible_11(float cos_theta_i, const Point2f &u) const;

    std::string to_string() const;

private:
    std::pair<Vector3f, float> sample_all(const Point2f &u) const;
    std::pair<Vector3f, float> sample_visible_normals(const Vector3f &wi, const Point2f &u) const;

    MicrofacetType m_type;
    float m_alpha_u, m_alpha_v;
    bool m_sample_visible;
};

/**
 * Microfacet parameters as a scene gives them: the roughness may be a texture, so a BSDF asks for
 * the distribution at each surface point (no allocation: the distribution is a few floats).
 */
class MicrofacetParameters {
public:
    MicrofacetParameters() = default;
    MicrofacetParameters(MicrofacetType type, std::shared_ptr<Texture> alpha_u,
                         std::shared_ptr<Texture> alpha_v, bool sample_visible);

    /// The distribution at `si` (roughness textures evaluated with eval_1).
    MicrofacetDistribution at(const SurfaceInteraction &si) const {
        if (m_constant)
            return MicrofacetDistribution(m_type, m_const_u, m_const_v, m_sample_visible);
        return MicrofacetDistribution(m_type, m_alpha_u->eval_1(si), m_alpha_v->eval_1(si),
                                      m_sample_visible);
    }

    MicrofacetType type() const { return m_type; }
    bool sample_visible() const { return m_sample_visible; }
    const std::shared_ptr<Texture> &alpha_u() const { return m_alpha_u; }
    const std::shared_ptr<Texture> &alpha_v() const { return m_alpha_v; }
    /// True unless αu and αv are the same texture or equal constants.
    bool is_anisotropic() const { return m_anisotropic; }
    bool is_spatially_varying() const { return !m_constant; }
    /// Texture::prefetch() of the roughness textures, for a BSDF's prefetch(): false at once for
    /// constants; a texture given for both αu and αv is told once.
    bool prefetch(const SurfaceInteraction &si) const {
        if (m_constant) return false;
        bool started = facet::prefetch(m_alpha_u, si);
        if (m_alpha_v != m_alpha_u) started |= facet::prefetch(m_alpha_v, si);
        return started;
    }
    std::string to_string() const;

private:
    MicrofacetType m_type = MicrofacetType::Beckmann;
    std::shared_ptr<Texture> m_alpha_u, m_alpha_v;
    bool m_sample_visible = true;
    bool m_anisotropic = false;
    bool m_constant = false;
    float m_const_u = 0.1f, m_const_v = 0.1f;
};

/**
 * Reads the microfacet parameters of a scene object, with Mitsuba's names and defaults:
 * `distribution` (beckmann | ggx, default beckmann), `alpha` (default `default_alpha`) or both
 * `alpha_u` and `alpha_v`, and `sample_visible` (default true). Roughness values are numbers or
 * (when `allow_textures`) textures. Giving only one of alpha_u/alpha_v, mixing them with alpha,
 * an unknown distribution or a negative roughness throws facet::Error.
 */
MicrofacetParameters read_microfacet(const Properties &props, float default_alpha = 0.1f,
                                     bool allow_textures = true);

} // namespace facet
