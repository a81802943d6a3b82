// `facet compare`: does a render agree with a reference (mean and per-sample variance) within its
// noise? The rule is facet::testing's (facet/compare.h): per pixel and XYZ channel with N samples
// per pixel, z = |ours - ref| · sqrt(N / max(var, 1e-4)), p = erfc(z / √2), and with the
// Šidák-corrected level alpha = 1 - 0.99^(1 / pixels) the render agrees when at least 99.75% of
// the pixel-channels have p > alpha. This file only reads the images and prints the verdict.
// With --mean-sigmas K it also fails when an image mean (X, Y or Z) differs from the reference's
// by more than K of its standard errors: a bias over the whole image the per-pixel rule misses.
// The last line of the output is the verdict:
//   PASS|FAIL agreeing=<%> required=<%> rel_error=<%> ratio=<mean Y ours / mean Y reference>

#include "commands.h"

#include <facet/compare.h>
#include <facet/image.h>
#include <facet/logger.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>

using namespace facet;

namespace {

/// The per-sample variance (CIE XYZ) of a render of the moment integrator, m2 - m1² of its first
/// nested integrator's `<name>.X/Y/Z` and `m2_<name>.X/Y/Z` channels; `image` keeps only its
/// leading R, G, B (the mean).
Image variance_from_moments(Image &image, const std::string &path) {
    auto index = [&](const std::string &name) {
        for (size_t i = 0; i < image.channel_names.size(); ++i)
            if (image.channel_names[i] == name) return int(i);
        return -1;
    };
    int first = -1;
    for (size_t i = 0; i < image.channel_names.size() && first < 0; ++i) {
        const std::string &n = image.channel_names[i];
        if (n.size() > 2 && n.compare(n.size() - 2, 2, ".X") == 0 && n.compare(0, 3, "m2_") != 0 &&
            index("m2_" + n) >= 0)
            first = int(i);
    }
    if (first < 0 || index("R") != 0 || index("G") != 1 || index("B") != 2)
        FACET_THROW("\"{}\" has no moment channels (<name>.X and m2_<name>.X): give the "
                    "variance image as the third argument, or render the reference with the "
                    "moment integrator",
                    path);
    const std::string stem = image.channel_names[size_t(first)];
    const std::string name = stem.substr(0, stem.size() - 2);
    int m1[3], m2[3];
    for (int c = 0; c < 3; ++c) {
        const std::string ch = name + "." + std::string(1, "XYZ"[c]);
        m1[c] = index(ch);
        m2[c] = index("m2_" + ch);
        if (m1[c] < 0 || m2[c] < 0)
            FACET_THROW("\"{}\": the moment channels of \"{}\" are incomplete", path, name);
    }
    Image var(image.width, image.height, 3), mean(image.width, image.height, 3);
    var.channel_names = {"X", "Y", "Z"};
    mean.channel_names = {"R", "G", "B"};
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const double a = image.at(x, y, m1[c]), b = image.at(x, y, m2[c]);
                var.at(x, y, c) = float(std::max(0.0, b - a * a));
                mean.at(x, y, c) = image.at(x, y, c);
            }
    image = std::move(mean);
    return var;
}

} // namespace

int compare_main(int argc, char **argv) {
    std::string ours_path, mean_path, var_path, z_path;
    int spp = 0;
    double mean_sigmas = 0.0;
    CLI::App app("Compare a render with a reference mean image and its per-sample XYZ variance",
                 "facet compare");
    app.add_option("ours", ours_path, "The render to check (linear RGB EXR)")->required();
    app.add_option("ref_mean", mean_path, "Reference mean radiance (linear RGB EXR)")->required();
    app.add_option("ref_var_xyz", var_path,
                   "Reference per-sample variance (CIE XYZ EXR); without it, ref_mean is a "
                   "render of the moment integrator and the variance comes from its moments");
    app.add_option("--spp", spp, "Samples per pixel of the render being checked")
        ->required()
        ->check(CLI::PositiveNumber);
    app.add_option("--mean-sigmas", mean_sigmas,
                   "Also fail when an image mean (X, Y or Z) is more than this many standard "
                   "errors from the reference's (0: no such check)")
        ->check(CLI::NonNegativeNumber);
    app.add_option("--z-image", z_path, "Write the per-channel z scores (XYZ) to this EXR");
    if (int code = cli::parse(app, argc, argv); code >= 0) return code;

    Image ours = read_image(ours_path), mean = read_image(mean_path), var;
    if (!var_path.empty()) {
        var = read_image(var_path);
    } else {
        var = variance_from_moments(mean, mean_path);
        var_path = mean_path + " (moments)";
    }
    PeerComparison r = compare_with_reference(
        ours, mean, var, spp,
        {"\"" + ours_path + "\"", "\"" + mean_path + "\"", "\"" + var_path + "\""});
    const size_t pixels = r.pixels;
    const double fraction = r.fraction, brightness = r.brightness_difference();
    auto rel = [&](int k) {
        return r.mean_ref_xyz[size_t(k)] != 0.0
                   ? r.mean_ours_xyz[size_t(k)] / r.mean_ref_xyz[size_t(k)] - 1.0
                   : 0.0;
    };
    auto se = [&](int k) {
        return r.mean_ref_xyz[size_t(k)] != 0.0
                   ? r.mean_error[size_t(k)] / std::abs(r.mean_ref_xyz[size_t(k)])
                   : 0.0;
    };
    const double sigmas = r.max_mean_sigmas();
    const bool mean_ok = mean_sigmas <= 0.0 || sigmas <= mean_sigmas; // false for NaN
    const bool ok = r.passed_rule && mean_ok;

    fmt::print("{}x{} pixels, {} spp, alpha = {:.3g} (Sidak over {} pixels)\n", r.width, r.height,
               spp, r.alpha, pixels);
    fmt::print("pixel-channels with p > alpha: {:.3f}% (X {:.3f}%, Y {:.3f}%, Z {:.3f}%), "
               "required {:.2f}%\n",
               100.0 * fraction, 100.0 * double(r.passed[0]) / double(pixels),
               100.0 * double(r.passed[1]) / double(pixels),
               100.0 * double(r.passed[2]) / double(pixels), 100.0 * PeerComparison::PassFraction);
    if (r.non_finite) fmt::print("non-finite values: {}\n", r.non_finite);
    fmt::print("mean brightness (Y): ours {:.6g}, reference {:.6g}, relative difference {:+.3f}%\n",
               r.mean_ours, r.mean_ref, 100.0 * brightness);
    fmt::print("image mean ours/reference - 1 (X, Y, Z): {:+.3f}%, {:+.3f}%, {:+.3f}%; standard "
               "error {:.3f}%, {:.3f}%, {:.3f}%; {:.2f} sigma at most",
               100.0 * rel(0), 100.0 * rel(1), 100.0 * rel(2), 100.0 * se(0), 100.0 * se(1),
               100.0 * se(2), sigmas);
    if (mean_sigmas > 0.0)
        fmt::print(" ({} {:g})", mean_ok ? "within" : "FAILS the bound of", mean_sigmas);
    fmt::print("\n");
    if (!z_path.empty()) write_image(z_path, r.z);
    // The verdict in one stable line for scripts and test logs: the agreeing fraction and the
    // relative error of the mean (mean brightness ratio - 1).
    fmt::print("{} agreeing={:.3f}% required={:.2f}% rel_error={:+.3f}% ratio={:.6f}\n",
               ok ? "PASS" : "FAIL", 100.0 * fraction, 100.0 * PeerComparison::PassFraction,
               100.0 * brightness, 1.0 + brightness);
    return ok ? 0 : 1;
}
