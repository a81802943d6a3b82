#pragma once

#include <facet/color.h>
#include <facet/vector.h>

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

/// fresnel_conductor() per RGB channel.
inline Color3f fresnel_conductor(float cos_i, const Color3f &eta, const Color3f &k) {
    return {fresnel_conductor(cos_i, eta.r, k.r), fresnel_conductor(cos_i, eta.g, k.g),
            fresnel_conductor(cos_i, eta.b, k.b)};
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
