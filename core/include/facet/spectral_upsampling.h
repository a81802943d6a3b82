#pragma once

#include <facet/color.h>
#include <facet/spectrum.h>

#include <string>

/// RGB -> smooth spectrum upsampling for reflectances: the sigmoid-polynomial model of Jakob and
/// Hanika 2019 ("A Low-Dimensional Function Space for Efficient Spectral Upsampling"), with a
/// coefficient table facet computes itself at build time (core/scripts/rgb2spec_opt.cpp) and
/// reads on first use from share/facet/ next to libfacet.
///
/// The round trip: for a linear Rec.709 reflectance `rgb` in [0, 1]^3, the spectrum s of
/// rgb_to_sigmoid(rgb) integrated by facet's rgb mode, spectrum_to_rgb(s, Reflectance), gives
/// rgb ⊙ W within 1e-3 per channel, but for a few colours very near white (up to 2.1e-3 there:
/// tests/unit/core/spectral_upsampling.cpp). W = spectrum_to_rgb(1) = (0.99899, 0.99887,
/// 0.99880) is the white of that quadrature: the table is fitted so that 0, a grey g and 1 are
/// the constant spectra 0, g and 1 (what a spectral render of a white reflectance needs).
namespace facet {

/// s(λ) = S(c0 λ² + c1 λ + c2) with S(x) = 1/2 + x / (2 sqrt(1 + x²)), λ in nm: a smooth
/// spectrum in [0, 1] with at most one extremum. c2 = ±infinity (c0 = c1 = 0) is the constant
/// 1 or 0.
struct SigmoidPolynomial {
    float c0 = 0.f, c1 = 0.f, c2 = 0.f;

    /// The spectrum at `lambda_nm`, in [0, 1].
    float operator()(float lambda_nm) const {
        float x = (c0 * lambda_nm + c1) * lambda_nm + c2;
        // x / sqrt(1 + x²), written as sign(x) / sqrt(1 + 1 / x²) for |x| > 1: x² cannot
        // overflow, and x = ±infinity gives exactly 0 or 1.
        float t = std::abs(x) > 1.f ? std::copysign(1.f / std::sqrt(1.f + 1.f / (x * x)), x)
                                    : x / std::sqrt(1.f + x * x);
        return 0.5f + 0.5f * t;
    }
    /// The spectrum at each of `lambda`'s wavelengths: the scalar form's arithmetic, lane by
    /// lane, written without branches so that the four lanes are computed side by side.
    Color3f operator()(const Wavelengths &lambda) const {
        const float l[Color3f::Channels] = {lambda.r, lambda.g, lambda.b, lambda.w};
        float s[Color3f::Channels];
        for (int i = 0; i < Color3f::Channels; ++i) {
            const float x = (c0 * l[i] + c1) * l[i] + c2;
            const float big = std::copysign(1.f / std::sqrt(1.f + 1.f / (x * x)), x);
            const float small = x / std::sqrt(1.f + x * x);
            s[i] = 0.5f + 0.5f * (std::abs(x) > 1.f ? big : small);
        }
        return {s[0], s[1], s[2], s[3]};
    }
    std::string to_string() const;
};

/// The smooth reflectance spectrum of a linear Rec.709 colour: each channel clamped to [0, 1]
/// (NaN taken as 0), then the coefficients interpolated trilinearly between the table's cells
/// (the paper's lookup). Black and white are exact: {0, 0, -inf} and {0, 0, +inf}. Throws
/// facet::Error if the table cannot be read (the first call reads it; later calls only look up).
SigmoidPolynomial rgb_to_sigmoid(const Color3f &rgb);

/**
 * A colour a scene gives as RGB, as the spectral mode renders it: scale · s(λ), times D65(λ)
 * (cie_d65) for an emitter's colour. By kind, as Mitsuba 3's spectral modes read colours:
 * - Reflectance and Unbounded (an eta or k given as rgb): s of the colour clamped to [0, 1],
 *   scale 1 (Properties warns when an unbounded colour is clamped);
 * - Emission and Measured: s of rgb / (2 max(rgb)), scale 2 max(rgb) (0 for a black or negative
 *   colour), so that the curve stays inside the table's range whatever the magnitude; Emission
 *   is also multiplied by D65, the spectrum of an RGB white light.
 */
struct RGBSpectrum {
    SigmoidPolynomial poly;
    float scale = 1.f;
    bool illuminant = false;

    static RGBSpectrum from_rgb(const Color3f &rgb, SpectrumKind kind);
    /// The scaled form of any colour, without D65: s of rgb / (2 max(rgb)), scale 2 max(rgb)
    /// (an environment map's pixels, which the map multiplies by D65 itself).
    static RGBSpectrum scaled(const Color3f &rgb);
    /// The spectrum at each of `lambda`'s wavelengths (nm).
    Color3f eval(const Wavelengths &lambda) const;
};

/// The path of the coefficient table rgb_to_sigmoid reads.
std::string spectral_upsampling_table_path();

} // namespace facet
