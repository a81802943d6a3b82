// The peer comparison rule of `facet compare` (facet/compare.h, facet::testing): z per pixel and
// XYZ channel, the Šidák level, the 99.75 % agreement and the errors on mismatched images.

#include <facet/compare.h>
#include <facet/logger.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace facet;

namespace {

Image constant(int w, int h, float r, float g, float b, const char *names = "RGB") {
    Image img(w, h, 3);
    img.channel_names = {std::string(1, names[0]), std::string(1, names[1]),
                         std::string(1, names[2])};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            img.at(x, y, 0) = r;
            img.at(x, y, 1) = g;
            img.at(x, y, 2) = b;
        }
    return img;
}

} // namespace

TEST(PeerComparison, IdenticalImagesAgree) {
    Image ref = constant(16, 8, 0.2f, 0.4f, 0.6f), var = constant(16, 8, 0.1f, 0.1f, 0.1f, "XYZ");
    PeerComparison r = compare_with_reference(ref, ref, var, 64);
    EXPECT_TRUE(r.passed_rule);
    EXPECT_EQ(r.pixels, 128u);
    EXPECT_DOUBLE_EQ(r.fraction, 1.0);
    EXPECT_NEAR(r.alpha, 1.0 - std::pow(0.99, 1.0 / 128.0), 1e-15);
    EXPECT_EQ(r.z.at(3, 2, 1), 0.f);
    EXPECT_NEAR(r.brightness_difference(), 0.0, 1e-12);
}

TEST(PeerComparison, ZIsTheDifferenceInStandardErrors) {
    // A grey offset d changes Y by d (the Y row of the RGB to XYZ matrix sums to 1).
    Image ours = constant(4, 4, 0.51f, 0.51f, 0.51f), ref = constant(4, 4, 0.5f, 0.5f, 0.5f);
    Image var = constant(4, 4, 0.04f, 0.04f, 0.04f, "XYZ");
    PeerComparison r = compare_with_reference(ours, ref, var, 100);
    // z = 0.01 · sqrt(100 / 0.04) = 0.5
    EXPECT_NEAR(r.z.at(1, 1, 1), 0.5f, 1e-4f);
    EXPECT_TRUE(r.passed_rule);
    EXPECT_NEAR(r.brightness_difference(), 0.02, 1e-5);
}

TEST(PeerComparison, ABiasedRenderFailsAndTheVarianceHasAFloor) {
    Image ref = constant(8, 8, 0.5f, 0.5f, 0.5f);
    // Zero variance is floored at 1e-4: an offset of 0.01 at 100 spp is z = 10, far beyond alpha.
    Image var = constant(8, 8, 0.f, 0.f, 0.f, "XYZ");
    PeerComparison r = compare_with_reference(constant(8, 8, 0.51f, 0.51f, 0.51f), ref, var, 100);
    EXPECT_FALSE(r.passed_rule);
    EXPECT_NEAR(r.z.at(0, 0, 1), 10.f, 1e-3f);
    EXPECT_EQ(r.passed[1], 0u);
    // One bad pixel in 64 is 1.6 % of the channels: more than the 0.25 % allowed.
    Image ours = ref;
    ours.at(5, 5, 0) = 10.f;
    PeerComparison one =
        compare_with_reference(ours, ref, constant(8, 8, 0.01f, 0.01f, 0.01f, "XYZ"), 100);
    EXPECT_FALSE(one.passed_rule);
    EXPECT_LT(one.fraction, 1.0);
}

TEST(PeerComparison, NonFiniteValuesFail) {
    Image ref = constant(2, 2, 0.5f, 0.5f, 0.5f), var = constant(2, 2, 0.1f, 0.1f, 0.1f, "XYZ");
    Image ours = ref;
    ours.at(0, 0, 1) = std::nanf("");
    PeerComparison r = compare_with_reference(ours, ref, var, 16);
    EXPECT_GT(r.non_finite, 0u);
    EXPECT_FALSE(r.passed_rule);
}

TEST(PeerComparison, MismatchedImagesAreErrors) {
    Image ref = constant(4, 4, 0.5f, 0.5f, 0.5f), var = constant(4, 4, 0.1f, 0.1f, 0.1f, "XYZ");
    EXPECT_THROW(compare_with_reference(constant(4, 2, 0.5f, 0.5f, 0.5f), ref, var, 16), Error);
    Image grey(4, 4, 1);
    EXPECT_THROW(compare_with_reference(grey, ref, var, 16), Error);
    EXPECT_THROW(compare_with_reference(ref, ref, var, 0), Error);
}

TEST(PeerComparison, ImageMeansAndTheirStandardErrors) {
    // 10x10 pixels, per-sample variance 0.04 in every channel, 100 spp: each pixel's error is
    // 0.02, the mean's 0.02 / sqrt(100) = 0.002. A grey offset of 0.005 moves X, Y and Z by
    // 0.005 times the rows' sums of the RGB to XYZ matrix.
    Image ours = constant(10, 10, 0.505f, 0.505f, 0.505f), ref = constant(10, 10, 0.5f, 0.5f, 0.5f);
    Image var = constant(10, 10, 0.04f, 0.04f, 0.04f, "XYZ");
    PeerComparison r = compare_with_reference(ours, ref, var, 100);
    const double row[3] = {0.412453 + 0.357580 + 0.180423, 0.212671 + 0.715160 + 0.072169,
                           0.019334 + 0.119193 + 0.950227};
    for (size_t k = 0; k < 3; ++k) {
        EXPECT_NEAR(r.mean_ref_xyz[k], 0.5 * row[k], 1e-6);
        EXPECT_NEAR(r.mean_ours_xyz[k], 0.505 * row[k], 1e-6);
        EXPECT_NEAR(r.mean_error[k], 0.002, 1e-9);
        EXPECT_NEAR(r.mean_sigmas[k], 0.005 * row[k] / 0.002, 1e-3);
    }
    EXPECT_NEAR(r.max_mean_sigmas(), 0.005 * row[2] / 0.002, 1e-3);
    EXPECT_TRUE(r.passed_rule); // z = 0.025 per pixel: only the mean can tell

    // The variance floor of the rule also bounds the standard error from below.
    PeerComparison f =
        compare_with_reference(ours, ref, constant(10, 10, 0.f, 0.f, 0.f, "XYZ"), 100);
    EXPECT_NEAR(f.mean_error[1], std::sqrt(100 * PeerComparison::MinVariance / 100) / 100, 1e-12);

    // A non-finite render has no finite distance from the reference.
    Image bad = ours;
    bad.at(3, 3, 1) = std::nanf("");
    EXPECT_TRUE(std::isnan(compare_with_reference(bad, ref, var, 100).max_mean_sigmas()));
}
