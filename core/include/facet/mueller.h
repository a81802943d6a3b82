#pragma once

#include <facet/color.h>
#include <facet/frame.h>
#include <facet/fresnel.h>
#include <facet/vector.h>

#include <cmath>
#include <complex>
#include <cstring>

/**
 * Polarisation in the scalar_spectral_polarized mode: Stokes vectors and Mueller matrices, one
 * real number per wavelength lane (a Color3f per entry), and the reference frames they are
 * expressed in.
 *
 * Conventions (those of Mitsuba 3's documentation, in facet's words):
 * - A Stokes vector (S0, S1, S2, S3) describes light travelling along a direction `d` in a
 *   reference frame: a unit vector `x` perpendicular to d (its "s axis"), with y = d × x. S0 is the
 *   intensity, S1 = I(x) − I(y) (horizontal minus vertical linear light), S2 = I(+45°) − I(−45°)
 *   where +45° lies between x and y, S3 = I(right) − I(left) circular light.
 * - Unless a function says otherwise the frame of light travelling along d is the implicit one,
 *   stokes_basis(d) (the first axis coordinate_system() builds from d).
 * - rotator(θ) re-expresses a Stokes vector in the frame turned by θ about the direction of
 *   travel (right-handed: x turns towards y).
 * - A Mueller matrix maps the Stokes vector of the light arriving (travelling along `in`, in a
 *   frame of `in`) to the Stokes vector of the light leaving (along `out`, in a frame of `out`).
 *   A BSDF's matrix (BSDF::sample_polarized()) is in the local shading frame, between the
 *   implicit frames of the local directions; Interaction's frame turns it into the implicit
 *   frames of the world directions (to_world_mueller()).
 */
namespace facet {

/// A Stokes vector per wavelength: s[k] holds component S_k at the path's wavelengths.
struct Stokes {
    Color3f s[4];

    Stokes &operator+=(const Stokes &o) {
        for (int k = 0; k < 4; ++k) s[k] += o.s[k];
        return *this;
    }
    Stokes operator*(const Color3f &c) const { return {{s[0] * c, s[1] * c, s[2] * c, s[3] * c}}; }
    /// Unpolarised light of intensity `c`.
    static Stokes unpolarized(const Color3f &c) {
        return {{c, Color3f(0.f), Color3f(0.f), Color3f(0.f)}};
    }
};

/// A Mueller matrix per wavelength: m[i][j] holds entry (i, j) at the path's wavelengths.
struct Mueller {
    Color3f m[4][4];

    /// The identity: light passes unchanged (a null interface).
    static Mueller identity(const Color3f &scale = Color3f(1.f)) {
        Mueller r;
        for (int i = 0; i < 4; ++i) r.m[i][i] = scale;
        return r;
    }
    /// The same real 4×4 matrix at every wavelength.
    static Mueller constant(const float (&a)[4][4]) {
        Mueller r;
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) r.m[i][j] = Color3f(a[i][j]);
        return r;
    }

    Mueller operator*(const Mueller &o) const {
        Mueller r;
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j)
                r.m[i][j] = m[i][0] * o.m[0][j] + m[i][1] * o.m[1][j] + m[i][2] * o.m[2][j] +
                            m[i][3] * o.m[3][j];
        return r;
    }
    Stokes operator*(const Stokes &v) const {
        Stokes r;
        for (int i = 0; i < 4; ++i)
            r.s[i] = m[i][0] * v.s[0] + m[i][1] * v.s[1] + m[i][2] * v.s[2] + m[i][3] * v.s[3];
        return r;
    }
    Mueller operator*(const Color3f &c) const {
        Mueller r;
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) r.m[i][j] = m[i][j] * c;
        return r;
    }
    Mueller operator*(float c) const { return *this * Color3f(c); }
    Mueller operator/(float c) const { return *this * Color3f(1.f / c); }
    Mueller &operator+=(const Mueller &o) { return *this = *this + o; }
    Mueller operator+(const Mueller &o) const {
        Mueller r;
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) r.m[i][j] = m[i][j] + o.m[i][j];
        return r;
    }
    Mueller transposed() const {
        Mueller r;
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) r.m[i][j] = m[j][i];
        return r;
    }
    /// Column j: what the matrix makes of light that is all Stokes component j.
    Stokes column(int j) const { return {{m[0][j], m[1][j], m[2][j], m[3][j]}}; }
    /// The intensity the matrix passes of unpolarised light: entry (0, 0).
    const Color3f &unpolarized() const { return m[0][0]; }
    /// True when the matrix passes no unpolarised light (for a physical element: no light).
    bool is_black() const { return m[0][0].is_black(); }
    bool is_finite() const {
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j)
                if (!m[i][j].is_finite()) return false;
        return true;
    }
};

namespace mueller {

/// An ideal depolariser that passes the intensity `value` (only entry (0, 0) is non-zero): what
/// a BSDF that does not polarise returns in the polarized mode.
inline Mueller depolarizer(const Color3f &value = Color3f(1.f)) {
    Mueller r;
    r.m[0][0] = value;
    return r;
}

/// An ideal linear polariser transmitting light polarised along the frame's x axis, times
/// `value`.
inline Mueller linear_polarizer(const Color3f &value = Color3f(1.f)) {
    const Color3f h = value * 0.5f;
    Mueller r;
    r.m[0][0] = r.m[0][1] = r.m[1][0] = r.m[1][1] = h;
    return r;
}

/// A linear retarder with its fast axis along the frame's x axis, delaying the y component's
/// phase by `phase` radians (π/2: a quarter-wave plate, π: a half-wave plate): S2 and S3 turn
/// by `phase`, so a quarter-wave plate turns light polarised at −45° (S2 = −1) into right
/// circular light (S3 = +1) and +45° into left.
inline Mueller linear_retarder(float phase) {
    const float c = std::cos(phase), s = std::sin(phase);
    const float a[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, c, s}, {0, 0, -s, c}};
    return Mueller::constant(a);
}

/// An ideal circular polariser passing right-circular light (S3 > 0), or left-circular light
/// with `left`.
inline Mueller circular_polarizer(bool left = false) {
    const float v = left ? -0.5f : 0.5f;
    const float a[4][4] = {{0.5f, 0, 0, v}, {0, 0, 0, 0}, {0, 0, 0, 0}, {v, 0, 0, 0.5f}};
    return Mueller::constant(a);
}

/// Re-expresses a Stokes vector in the frame turned by `theta` radians about the direction of
/// travel (x towards y).
inline Mueller rotator(float theta) {
    const float c = std::cos(2.f * theta), s = std::sin(2.f * theta);
    const float a[4][4] = {{1, 0, 0, 0}, {0, c, s, 0}, {0, -s, c, 0}, {0, 0, 0, 1}};
    return Mueller::constant(a);
}

/// The element `M` turned by `theta` about the direction of travel (a polariser whose axis is
/// at `theta` from x): rotator(−θ)·M·rotator(θ).
inline Mueller rotated_element(float theta, const Mueller &M) {
    return rotator(-theta) * M * rotator(theta);
}

/// The angle between the unit vectors a and b, accurate near 0 and π (where acos of the dot
/// product is not).
inline float unit_angle(const Vector3f &a, const Vector3f &b) {
    if (dot(a, b) < 0.f) return Pi - 2.f * std::asin(std::min(1.f, norm(a + b) * 0.5f));
    return 2.f * std::asin(std::min(1.f, norm(a - b) * 0.5f));
}

/**
 * Reflection off a specular interface of relative IOR `eta` (η_inside/η_outside, n + ik for a
 * conductor) for light arriving with cosine `cos_i`, in the frames whose x axes are the s
 * direction (perpendicular to the plane of incidence) of the arriving and the leaving light:
 * with r_s = |a_s|², r_p = |a_p|² and δ = arg a_p − arg a_s (fresnel_polarized()),
 *   | (r_s + r_p)/2   (r_s − r_p)/2        0             0       |
 *   | (r_s − r_p)/2   (r_s + r_p)/2        0             0       |
 *   |       0               0        √(r_s r_p) cos δ  −√(r_s r_p) sin δ |
 *   |       0               0        √(r_s r_p) sin δ   √(r_s r_p) cos δ |
 */
inline void specular_reflection(float cos_i, const std::complex<float> &eta, float (&m)[4][4]) {
    FresnelPolarized f;
    fresnel_polarized(cos_i, eta, f);
    const float r_s = std::norm(f.a_s), r_p = std::norm(f.a_p);
    const float a = 0.5f * (r_s + r_p), b = 0.5f * (r_s - r_p), c = std::sqrt(r_s * r_p);
    float cos_d = 0.f, sin_d = 0.f;
    if (c > 0.f) {
        const std::complex<float> z = f.a_p * std::conj(f.a_s) / c; // |a_p||a_s| = c
        cos_d = z.real();
        sin_d = z.imag();
    }
    const float r[4][4] = {
        {a, b, 0, 0}, {b, a, 0, 0}, {0, 0, c * cos_d, -c * sin_d}, {0, 0, c * sin_d, c * cos_d}};
    std::memcpy(m, r, sizeof r);
}
/// specular_reflection() at the same real IOR at every wavelength.
inline Mueller specular_reflection(float cos_i, float eta) {
    float m[4][4];
    specular_reflection(cos_i, std::complex<float>(eta, 0.f), m);
    return Mueller::constant(m);
}
/// specular_reflection() of a conductor whose index is eta + i·k at each wavelength.
inline Mueller specular_reflection(float cos_i, const Color3f &eta, const Color3f &k) {
    Mueller r;
    for (int lane = 0; lane < Color3f::Channels; ++lane) {
        float m[4][4];
        specular_reflection(cos_i, std::complex<float>(eta[lane], k[lane]), m);
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) r.m[i][j][lane] = m[i][j];
    }
    return r;
}

/**
 * Refraction through a specular dielectric interface of real relative IOR `eta`, in the frames
 * of specular_reflection(): the transmitted power of s- and p-polarised light, t_s = 1 + a_s and
 * t_p = (1 + a_p)·η_ti, times η_it·|cos θt / cos θi| (the beam's change of cross-section and
 * medium), so that entry (0, 0) is 1 − F. Without phases; zero under total internal reflection.
 */
inline Mueller specular_transmission(float cos_i, float eta) {
    FresnelPolarized f;
    fresnel_polarized(cos_i, std::complex<float>(eta, 0.f), f);
    const float factor = std::abs(cos_i) > 1e-8f ? -f.eta_it.real() * (f.cos_t / cos_i) : 0.f;
    const float t_s = 1.f + f.a_s.real(), t_p = (1.f + f.a_p.real()) * f.eta_ti.real();
    const float a = 0.5f * factor * (t_s * t_s + t_p * t_p),
                b = 0.5f * factor * (t_s * t_s - t_p * t_p), c = factor * std::abs(t_s * t_p);
    const float m[4][4] = {{a, b, 0, 0}, {b, a, 0, 0}, {0, 0, c, 0}, {0, 0, 0, c}};
    return Mueller::constant(m);
}

/// The implicit frame of light travelling along `d`: the first axis coordinate_system() builds.
inline Vector3f stokes_basis(const Vector3f &d) {
    Vector3f s, t;
    coordinate_system(d, s, t);
    return s;
}

/// The rotator that re-expresses Stokes vectors of light travelling along `forward` from the
/// frame `current` to the frame `target` (both perpendicular to `forward`).
inline Mueller rotate_stokes_basis(const Vector3f &forward, const Vector3f &current,
                                   const Vector3f &target) {
    float theta = unit_angle(normalize(current), normalize(target));
    if (dot(forward, cross(current, target)) < 0.f) theta = -theta;
    return rotator(theta);
}

/// `M`, mapping light along `in_forward` in the frame `in_current` to light along `out_forward`
/// in the frame `out_current`, re-expressed between the frames `in_target` and `out_target`.
inline Mueller rotate_mueller_basis(const Mueller &M, const Vector3f &in_forward,
                                    const Vector3f &in_current, const Vector3f &in_target,
                                    const Vector3f &out_forward, const Vector3f &out_current,
                                    const Vector3f &out_target) {
    const Mueller r_in = rotate_stokes_basis(in_forward, in_current, in_target);
    const Mueller r_out = rotate_stokes_basis(out_forward, out_current, out_target);
    return r_out * M * r_in.transposed();
}

/// rotate_mueller_basis() for an element that leaves the direction of travel `forward` as it is
/// (a polariser, a retarder): both frames turn from `current` to `target`.
inline Mueller rotate_mueller_basis_collinear(const Mueller &M, const Vector3f &forward,
                                              const Vector3f &current, const Vector3f &target) {
    const Mueller r = rotate_stokes_basis(forward, current, target);
    return r * M * r.transposed();
}

/**
 * A BSDF's reflection matrix `M`, given in the frames of the s direction n × d (n the interface's
 * normal, +Z or a microfacet's), turned into the implicit frames of the local directions: light
 * arrives along −wo_hat and leaves along wi_hat (see BSDF). At normal incidence, where the plane
 * of incidence is undefined, the s direction is the x axis (for each direction on its own).
 */
inline Mueller reflection_to_implicit(const Mueller &M, const Vector3f &n, const Vector3f &wo_hat,
                                      const Vector3f &wi_hat) {
    auto s_axis = [](const Vector3f &s) {
        return s.x == 0.f && s.y == 0.f && s.z == 0.f ? Vector3f(1.f, 0.f, 0.f) : normalize(s);
    };
    const Vector3f s_in = s_axis(cross(n, -wo_hat)), s_out = s_axis(cross(n, wi_hat));
    return rotate_mueller_basis(M, -wo_hat, s_in, stokes_basis(-wo_hat), wi_hat, s_out,
                                stokes_basis(wi_hat));
}

/// `M`, given between the implicit frames of the directions `in` and `out` of `frame`'s local
/// coordinates, between the implicit frames of the same directions in world coordinates.
inline Mueller to_world(const Frame &frame, const Mueller &M, const Vector3f &in,
                        const Vector3f &out) {
    const Vector3f in_world = frame.to_world(in), out_world = frame.to_world(out);
    return rotate_mueller_basis(M, in_world, frame.to_world(stokes_basis(in)),
                                stokes_basis(in_world), out_world,
                                frame.to_world(stokes_basis(out)), stokes_basis(out_world));
}

/// The inverse of to_world(): `M` between the implicit frames of the world directions `in` and
/// `out`, between those of their local coordinates in `frame`.
inline Mueller to_local(const Frame &frame, const Mueller &M, const Vector3f &in_world,
                        const Vector3f &out_world) {
    const Vector3f in = frame.to_local(in_world), out = frame.to_local(out_world);
    return rotate_mueller_basis(M, in, frame.to_local(stokes_basis(in_world)), stokes_basis(in),
                                out, frame.to_local(stokes_basis(out_world)), stokes_basis(out));
}

} // namespace mueller
} // namespace facet
