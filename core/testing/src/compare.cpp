// The peer comparison rule of facet/compare.h.

#include <facet/compare.h>
#include <facet/logger.h>

#include <cmath>

namespace facet {

namespace {

/// Linear Rec.709 to CIE XYZ (D65).
std::array<double, 3> rgb_to_xyz(double r, double g, double b) {
    return {0.412453 * r + 0.357580 * g + 0.180423 * b, 0.212671 * r + 0.715160 * g + 0.072169 * b,
            0.019334 * r + 0.119193 * g + 0.950227 * b};
}

/// Indices of the channels named `names` (e.g. R, G, B), else of the first three channels.
std::array<int, 3> find_channels(const Image &img, const char *const (&names)[3],
                                 const std::string &label) {
    if (img.channels < 3)
        FACET_THROW("{} has {} channel{}, expected at least 3", label, img.channels,
                    img.channels == 1 ? "" : "s");
    std::array<int, 3> idx{0, 1, 2};
    for (int k = 0; k < 3; ++k) {
        for (int c = 0; c < int(img.channel_names.size()); ++c)
            if (img.channel_names[size_t(c)] == names[k]) idx[size_t(k)] = c;
    }
    return idx;
}

} // namespace

PeerComparison compare_with_reference(const Image &ours, const Image &mean, const Image &var,
                                      int spp, const std::array<std::string, 3> &labels) {
    if (spp < 1) FACET_THROW("compare: the render's samples per pixel must be positive ({})", spp);
    for (const Image *other : {&mean, &var}) {
        if (other->width != ours.width || other->height != ours.height)
            FACET_THROW("image sizes differ: {} is {}x{}, {} is {}x{} (render at the "
                        "reference's resolution)",
                        labels[0], ours.width, ours.height, labels[other == &mean ? 1 : 2],
                        other->width, other->height);
    }
    const char *const rgb_names[3] = {"R", "G", "B"};
    const char *const xyz_names[3] = {"X", "Y", "Z"};
    auto ours_c = find_channels(ours, rgb_names, labels[0]);
    auto mean_c = find_channels(mean, rgb_names, labels[1]);
    auto var_c = find_channels(var, xyz_names, labels[2]);

    PeerComparison r;
    r.width = ours.width;
    r.height = ours.height;
    r.spp = spp;
    r.pixels = size_t(ours.width) * size_t(ours.height);
    r.alpha = 1.0 - std::pow(0.99, 1.0 / double(std::max<size_t>(r.pixels, 1)));
    r.z = Image(ours.width, ours.height, 3);
    r.z.channel_names = {"X", "Y", "Z"};

    double sum_ours = 0.0, sum_ref = 0.0;
    std::array<double, 3> sum_ours_xyz{0, 0, 0}, sum_ref_xyz{0, 0, 0}, sum_var{0, 0, 0};
    for (int y = 0; y < ours.height; ++y) {
        for (int x = 0; x < ours.width; ++x) {
            auto a = rgb_to_xyz(ours.at(x, y, ours_c[0]), ours.at(x, y, ours_c[1]),
                                ours.at(x, y, ours_c[2]));
            auto b = rgb_to_xyz(mean.at(x, y, mean_c[0]), mean.at(x, y, mean_c[1]),
                                mean.at(x, y, mean_c[2]));
            sum_ours += a[1];
            sum_ref += b[1];
            for (int k = 0; k < 3; ++k) {
                double v =
                    std::max(double(var.at(x, y, var_c[size_t(k)])), PeerComparison::MinVariance);
                sum_ours_xyz[size_t(k)] += a[size_t(k)];
                sum_ref_xyz[size_t(k)] += b[size_t(k)];
                sum_var[size_t(k)] += v;
                double z = std::abs(a[size_t(k)] - b[size_t(k)]) * std::sqrt(double(spp) / v);
                r.z.at(x, y, k) = float(z);
                if (!std::isfinite(z)) {
                    ++r.non_finite;
                    continue;
                }
                if (std::erfc(z / std::sqrt(2.0)) > r.alpha) ++r.passed[size_t(k)];
            }
        }
    }
    size_t total = 3 * r.pixels, good = r.passed[0] + r.passed[1] + r.passed[2];
    r.fraction = total ? double(good) / double(total) : 0.0;
    r.mean_ours = r.pixels ? sum_ours / double(r.pixels) : 0.0;
    r.mean_ref = r.pixels ? sum_ref / double(r.pixels) : 0.0;
    for (size_t k = 0; k < 3 && r.pixels; ++k) {
        const double n = double(r.pixels);
        r.mean_ours_xyz[k] = sum_ours_xyz[k] / n;
        r.mean_ref_xyz[k] = sum_ref_xyz[k] / n;
        r.mean_error[k] = std::sqrt(sum_var[k] / double(spp)) / n;
        r.mean_sigmas[k] = (r.mean_ours_xyz[k] - r.mean_ref_xyz[k]) / r.mean_error[k];
    }
    r.passed_rule = total > 0 && r.fraction >= PeerComparison::PassFraction;
    return r;
}

} // namespace facet
