// `facet compare`: does a render agree with a reference (mean and per-sample variance) within its
// noise? The rule, applied per pixel and XYZ channel with N samples per pixel:
//   z = |ours - ref| · sqrt(N / max(var, 1e-4)),  p = erfc(z / √2)
// and with the Šidák-corrected level alpha = 1 - 0.99^(1 / pixels) the render agrees when at least
// 99.75% of the pixel-channels have p > alpha. The last line of the output is the verdict:
//   PASS|FAIL agreeing=<%> required=<%> rel_error=<%> ratio=<mean Y ours / mean Y reference>

#include "commands.h"

#include <facet/image.h>
#include <facet/logger.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <array>
#include <cmath>
#include <string>

namespace {

using namespace facet;

constexpr double PassFraction = 0.9975;
constexpr double MinVariance = 1e-4;

/// Linear Rec.709 to CIE XYZ (D65).
std::array<double, 3> rgb_to_xyz(double r, double g, double b) {
    return {0.412453 * r + 0.357580 * g + 0.180423 * b, 0.212671 * r + 0.715160 * g + 0.072169 * b,
            0.019334 * r + 0.119193 * g + 0.950227 * b};
}

/// Indices of the channels named `names` (e.g. R, G, B), else of the first three channels.
std::array<int, 3> find_channels(const Image &img, const char *const (&names)[3],
                                 const std::string &path) {
    if (img.channels < 3)
        FACET_THROW("\"{}\" has {} channel{}, expected at least 3", path, img.channels,
                    img.channels == 1 ? "" : "s");
    std::array<int, 3> idx{0, 1, 2};
    for (int k = 0; k < 3; ++k) {
        for (int c = 0; c < int(img.channel_names.size()); ++c)
            if (img.channel_names[size_t(c)] == names[k]) idx[size_t(k)] = c;
    }
    return idx;
}

} // namespace

int compare_main(int argc, char **argv) {
    std::string ours_path, mean_path, var_path, z_path;
    int spp = 0;
    CLI::App app("Compare a render with a reference mean image and its per-sample XYZ variance",
                 "facet compare");
    app.add_option("ours", ours_path, "The render to check (linear RGB EXR)")->required();
    app.add_option("ref_mean", mean_path, "Reference mean radiance (linear RGB EXR)")->required();
    app.add_option("ref_var_xyz", var_path, "Reference per-sample variance (CIE XYZ EXR)")
        ->required();
    app.add_option("--spp", spp, "Samples per pixel of the render being checked")
        ->required()
        ->check(CLI::PositiveNumber);
    app.add_option("--z-image", z_path, "Write the per-channel z scores (XYZ) to this EXR");
    if (int code = cli::parse(app, argc, argv); code >= 0) return code;

    Image ours = read_image(ours_path), mean = read_image(mean_path), var = read_image(var_path);
    for (const auto *other : {&mean, &var}) {
        if (other->width != ours.width || other->height != ours.height)
            FACET_THROW("image sizes differ: \"{}\" is {}x{}, \"{}\" is {}x{} (render at the "
                        "reference's resolution)",
                        ours_path, ours.width, ours.height, other == &mean ? mean_path : var_path,
                        other->width, other->height);
    }
    const char *const rgb_names[3] = {"R", "G", "B"};
    const char *const xyz_names[3] = {"X", "Y", "Z"};
    auto ours_c = find_channels(ours, rgb_names, ours_path);
    auto mean_c = find_channels(mean, rgb_names, mean_path);
    auto var_c = find_channels(var, xyz_names, var_path);

    const size_t pixels = size_t(ours.width) * size_t(ours.height);
    const double alpha = 1.0 - std::pow(0.99, 1.0 / double(pixels));
    Image z_img(ours.width, ours.height, 3);
    z_img.channel_names = {"X", "Y", "Z"};

    std::array<size_t, 3> passed{0, 0, 0};
    size_t non_finite = 0;
    double sum_ours = 0.0, sum_ref = 0.0;
    for (int y = 0; y < ours.height; ++y) {
        for (int x = 0; x < ours.width; ++x) {
            auto a = rgb_to_xyz(ours.at(x, y, ours_c[0]), ours.at(x, y, ours_c[1]),
                                ours.at(x, y, ours_c[2]));
            auto b = rgb_to_xyz(mean.at(x, y, mean_c[0]), mean.at(x, y, mean_c[1]),
                                mean.at(x, y, mean_c[2]));
            sum_ours += a[1];
            sum_ref += b[1];
            for (int k = 0; k < 3; ++k) {
                double v = std::max(double(var.at(x, y, var_c[size_t(k)])), MinVariance);
                double z = std::abs(a[size_t(k)] - b[size_t(k)]) * std::sqrt(double(spp) / v);
                z_img.at(x, y, k) = float(z);
                if (!std::isfinite(z)) {
                    ++non_finite;
                    continue;
                }
                if (std::erfc(z / std::sqrt(2.0)) > alpha) ++passed[size_t(k)];
            }
        }
    }

    size_t total = 3 * pixels, good = passed[0] + passed[1] + passed[2];
    double fraction = double(good) / double(total);
    double brightness = sum_ref > 0.0 ? sum_ours / sum_ref - 1.0 : 0.0;
    bool ok = fraction >= PassFraction;

    fmt::print("{}x{} pixels, {} spp, alpha = {:.3g} (Sidak over {} pixels)\n", ours.width,
               ours.height, spp, alpha, pixels);
    fmt::print("pixel-channels with p > alpha: {:.3f}% (X {:.3f}%, Y {:.3f}%, Z {:.3f}%), "
               "required {:.2f}%\n",
               100.0 * fraction, 100.0 * double(passed[0]) / double(pixels),
               100.0 * double(passed[1]) / double(pixels),
               100.0 * double(passed[2]) / double(pixels), 100.0 * PassFraction);
    if (non_finite) fmt::print("non-finite values: {}\n", non_finite);
    fmt::print("mean brightness (Y): ours {:.6g}, reference {:.6g}, relative difference {:+.3f}%\n",
               sum_ours / double(pixels), sum_ref / double(pixels), 100.0 * brightness);
    if (!z_path.empty()) write_image(z_path, z_img);
    // The verdict in one stable line for scripts and test logs: the agreeing fraction and the
    // relative error of the mean (mean brightness ratio - 1).
    fmt::print("{} agreeing={:.3f}% required={:.2f}% rel_error={:+.3f}% ratio={:.6f}\n",
               ok ? "PASS" : "FAIL", 100.0 * fraction, 100.0 * PassFraction, 100.0 * brightness,
               1.0 + brightness);
    return ok ? 0 : 1;
}
