#pragma once

#include <facet/color.h>
#include <facet/vector.h>

#include <complex>

/// Fresnel equations and the reflection/refraction directions shared by the specular and
/// microfacet BSDFs. All directions live in the local shading frame (normal = +Z) and point away
/// from the surface.
namespace facet {

/// Result of fresnel_dielectric().
struct FresnelResult {
    float F;      ///< unpolarised reflectance
    float cos_t;  ///< cosine of the refracted direction; opposite sign to cos θi, 0 under TIR
    float eta_it; ///< relative IOR η_t/η_i along the direction of travel
    float eta_ti; ///< its reciprocal η_i/η_t
};

/**
 * Unpolarised Fresnel reflectance of a smooth dielectric interface with relative IOR
 * `eta` = η_inside/η_outside, for light arriving with cosine `cos_i` against the normal.
 * cos_i < 0 means the light arrives from the inside; η_it and η_ti swap accordingly. Total internal
 * reflection gives F = 1 and cos_t = 0.
 */
inline FresnelResult fresnel_dielectric(float cos_i, float eta) {
    bool outside = cos_i >= 0.f;
    float eta_it = outside ? eta : 1.f / eta, eta_ti = outside ? 1.f / eta : eta;

    // Snell's law: sin²θt = η_ti²·sin²θi.
    float cos_t_2 = 1.f - (1.f - cos_i * cos_i) * eta_ti * eta_ti;
    float ci = std::abs(cos_i), ct = safe_sqrt(cos_t_2);

    // Amplitude reflection coefficients of s- and p-polarised light (ratio form, η_i = 1).
    float r_s = (ci - eta_it * ct) / (ci + eta_it * ct);
    float r_p = (ct - eta_it * ci) / (ct + eta_it * ci);
    float F = 0.5f * (r_s * r_s + r_p * r_p);

    if (eta == 1.f)
        F = 0.f; // index-matched: no interface
    else if (ci == 0.f)
        F = 1.f; // grazing incidence (0/0 in r_p otherwise)
    else if (cos_t_2 <= 0.f)
        F = 1.f; // total internal reflection

    return {F, outside ? -ct : ct, eta_it, eta_ti};
}

/**
 * Fresnel reflectance of a conductor with complex IOR η + i·k for cos_i > 0 (Möller's real-valued
 * formulation of the complex Fresnel equations).
 */
inline float fresnel_conductor(float cos_i, float eta, float k) {
    float c2 = cos_i * cos_i, s2 = 1.f - c2, s4 = s2 * s2;
    float t1 = eta * eta - k * k - s2;
    float a2b2 = safe_sqrt(t1 * t1 + 4.f * eta * eta * k * k); // a² + b²
    float a = safe_sqrt(0.5f * (a2b2 + t1));
    float two_a_c = 2.f * a * cos_i;

    float r_s = (a2b2 + c2 - two_a_c) / (a2b2 + c2 + two_a_c);
    float q = a2b2 * c2 + s4;
    float r_p = r_s * (q - two_a_c * s2) / (q + two_a_c * s2);
    return 0.5f * (r_s + r_p);
}

/// fresnel_conductor() per channel.
inline Color3f fresnel_conductor(float cos_i, const Color3f &eta, const Color3f &k) {
    return map(eta, k, [cos_i](float e, float kk) { return fresnel_conductor(cos_i, e, kk); });
}

/// Result of fresnel_polarized(): the complex amplitude reflection coefficients and the
/// refraction's geometry.
struct FresnelPolarized {
    std::complex<float> a_s;    ///< amplitude of s-polarised light (perpendicular to the plane)
    std::complex<float> a_p;    ///< amplitude of p-polarised light (in the plane of incidence)
    float cos_t;                ///< as FresnelResult::cos_t (0 under total internal reflection)
    std::complex<float> eta_it; ///< relative IOR η_t/η_i along the direction of travel
    std::complex<float> eta_ti; ///< its reciprocal
};

/**
 * The Fresnel equations with their phases, for light arriving with cosine `cos_i` at an
 * interface of relative IOR `eta` = η_inside/η_outside, real (a dielectric) or n + ik (a
 * conductor; either sign of k means the same absorbing metal). cos_i < 0: the light arrives
 * from the inside.
 *
 * The signs are Verdet's (Mitsuba 3's): with θt the angle of refraction and η = η_it,
 *   a_s = (cos θi − η cos θt) / (cos θi + η cos θt),
 *   a_p = (η cos θi − cos θt) / (η cos θi + cos θt),
 * so at normal incidence a_p = −a_s (for η > 1: a_s < 0 < a_p), and |a_s|² and |a_p|² are the
 * reflectances the unpolarised fresnel_dielectric() averages. cos θt is the root of
 * 1 − η_ti²·sin²θi with the sign that keeps refracted waves decaying: under total internal
 * reflection it is −i·√|…|, which gives |a_s| = |a_p| = 1 and the phases of the evanescent wave.
 * An index-matched interface (η = 1) reflects nothing. (The result is written to `out`: a
 * structure of complex numbers returned by value draws an ABI note from GCC.)
 */
inline void fresnel_polarized(float cos_i, const std::complex<float> &eta_in,
                              FresnelPolarized &out) {
    using C = std::complex<float>;
    C eta = eta_in;
    // The formulas take the conductor's index as n − ik.
    if (eta.imag() > 0.f) eta = std::conj(eta);
    const bool outside = cos_i >= 0.f;
    const C eta_it = outside ? eta : C(1.f) / eta, eta_ti = C(1.f) / eta_it;
    C cos_t_2 = C(1.f) - eta_ti * eta_ti * (1.f - cos_i * cos_i);
    // (+0: a negative zero imaginary part would flip std::sqrt's branch.)
    cos_t_2 = C(cos_t_2.real(), cos_t_2.imag() + 0.f);
    const float sign_t = cos_t_2.real() >= 0.f ? 1.f : -1.f;
    const C ct = std::sqrt(cos_t_2) * sign_t;
    const float ci = std::abs(cos_i);

    C a_s = (ci - eta_it * ct) / (ci + eta_it * ct);
    C a_p = (eta_it * ci - ct) / (eta_it * ci + ct);
    const bool matched = std::norm(eta) == 1.f && eta.imag() == 0.f;
    if (matched || eta == C(0.f)) a_s = a_p = C(0.f);
    const float cos_t = cos_t_2.real() >= 0.f ? (outside ? -ct.real() : ct.real()) : 0.f;
    out = {a_s, a_p, cos_t, eta_it, eta_ti};
}

/// Mirror direction about the shading normal: (−x, −y, z).
inline Vector3f reflect(const Vector3f &wi) { return {-wi.x, -wi.y, wi.z}; }

/// Mirror direction about the (micro)normal m.
inline Vector3f reflect(const Vector3f &wi, const Vector3f &m) {
    return m * (2.f * dot(wi, m)) - wi;
}

/// Refracted direction about the shading normal, with cos_t and eta_ti from fresnel_dielectric().
inline Vector3f refract(const Vector3f &wi, float cos_t, float eta_ti) {
    return {-eta_ti * wi.x, -eta_ti * wi.y, cos_t};
}

/// Refracted direction about the (micro)normal m, with cos_t and eta_ti from
/// fresnel_dielectric(dot(wi, m), eta).
inline Vector3f refract(const Vector3f &wi, const Vector3f &m, float cos_t, float eta_ti) {
    return m * (dot(wi, m) * eta_ti + cos_t) - wi * eta_ti;
}

/**
 * Hemispherical average of the dielectric Fresnel reflectance weighted by cos θ ("fdr"), used by
 * the plastic models for light trapped below a coating. Fits by Egan & Hilgeman (η < 1) and
 * d'Eon & Irving (η ≥ 1).
 */
inline float fresnel_diffuse_reflectance(float eta) {
    if (eta < 1.f) return 0.0636f / eta + eta * (-1.4399f * eta + 0.7099f) + 0.6681f;
    float x = 1.f / eta;
    // Horner form of 0.919317 − 3.4793x + 6.75335x² − 7.80989x³ + 4.98554x⁴ − 1.36881x⁵.
    return 0.919317f +
           x * (-3.4793f + x * (6.75335f + x * (-7.80989f + x * (4.98554f + x * -1.36881f))));
}

} // namespace facet
