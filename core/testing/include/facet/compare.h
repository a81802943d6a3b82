#pragma once

#include <facet/image.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <string>

/**
 * The peer comparison rule (`facet compare`): does a render agree with a reference, given as its
 * mean and its per-sample variance, within the render's noise? Per pixel and CIE XYZ channel, with
 * N samples per pixel of the render,
 *   z = |ours - ref| · sqrt(N / max(var, 1e-4)),  p = erfc(z / √2),
 * and with the Šidák-corrected level α = 1 - 0.99^(1 / pixels) the render agrees when at least
 * 99.75 % of the pixel-channels have p > α. Colours are linear Rec.709 RGB, turned into XYZ (D65).
 *
 * The per-pixel rule cannot see a small bias spread over the whole image (0.5 % brighter passes it
 * at the test spp), so the comparison also gives the image mean per XYZ channel with its standard
 * error, sqrt(Σ max(var, 1e-4) / N) / pixels (the pixels' errors are independent; the reference's
 * own error is left out like in the rule): `mean_sigmas` is the difference of the means in those
 * standard errors, which `facet compare --mean-sigmas K` bounds.
 */
namespace facet {

struct PeerComparison {
    static constexpr double PassFraction = 0.9975; ///< of the pixel-channels
    static constexpr double MinVariance = 1e-4;    ///< floor of the reference variance

    int width = 0, height = 0, spp = 0;
    size_t pixels = 0;
    double alpha = 0.0;                     ///< per-channel level after the Šidák correction
    std::array<size_t, 3> passed{0, 0, 0};  ///< channels with p > alpha, per X, Y, Z
    size_t non_finite = 0;                  ///< channels whose z is not finite (they fail)
    double fraction = 0.0;                  ///< of the 3 · pixels channels that passed
    double mean_ours = 0.0, mean_ref = 0.0; ///< mean Y of the two images
    std::array<double, 3> mean_ours_xyz{0, 0, 0}, mean_ref_xyz{0, 0, 0}; ///< image means, X Y Z
    std::array<double, 3> mean_error{0, 0, 0};  ///< standard error of mean_ours_xyz at spp
    std::array<double, 3> mean_sigmas{0, 0, 0}; ///< (ours - ref) / mean_error, per X, Y, Z
    bool passed_rule = false;                   ///< fraction >= PassFraction
    Image z;                                    ///< z per pixel and channel (X, Y, Z)

    /// Relative difference of the mean brightness (Y), 0 when the reference is black.
    double brightness_difference() const {
        return mean_ref > 0.0 ? mean_ours / mean_ref - 1.0 : 0.0;
    }
    /// Largest |mean_sigmas| over X, Y, Z (NaN when one is: a non-finite render).
    double max_mean_sigmas() const {
        double m = 0.0;
        for (double s : mean_sigmas) {
            if (std::isnan(s)) return s;
            m = std::max(m, std::abs(s));
        }
        return m;
    }
};

/// Applies the rule. `ours` and `ref_mean` are RGB (channels R, G, B, else the first three),
/// `ref_var_xyz` holds the per-sample variance in X, Y, Z (else the first three channels). The
/// labels name the images in errors (different sizes, fewer than three channels).
PeerComparison
compare_with_reference(const Image &ours, const Image &ref_mean, const Image &ref_var_xyz, int spp,
                       const std::array<std::string, 3> &labels = {
                           "the render", "the reference mean", "the reference variance"});

} // namespace facet
