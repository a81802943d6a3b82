// Tests of the chi-square harness itself (facet::testing): its statistics, its pooling, and that
// it rejects wrong samplers and accepts right ones. The BSDFs here are test-only and live in this
// file; the chi-square configurations of facet's plugins are lines of tests/chi2/configs.txt.

#include <facet/bsdf.h>
#include <facet/chi2.h>
#include <facet/warp.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

using namespace facet;

namespace {

/// A Lambertian BSDF with optional, deliberate mistakes.
class TestLambert final : public BSDF {
public:
    enum class Bug {
        None,
        PdfScaled,     ///< pdf() and the reported pdf are 5 % too large
        MissingCosine, ///< samples uniformly but claims a cosine density (weights stay eval/pdf)
        NanPdf,        ///< pdf() is NaN in a small region
        NanWeight,     ///< sample() returns a NaN weight in a small region
        StrayBelow,    ///< one sample in 10^5 goes below the horizon, where the pdf is zero
        WrongWeight,   ///< the weight misses the reflectance
        Energy,        ///< reflects 20 % more than it receives
    };
    explicit TestLambert(Bug bug) : m_reflectance(bug == Bug::Energy ? 1.2f : 0.7f), m_bug(bug) {
        set_components({BSDFFlags::DiffuseReflection | BSDFFlags::FrontSide});
    }

    std::pair<BSDFSample, Color3f> sample(const BSDFContext &ctx, const SurfaceInteraction &si,
                                          float sample1, const Point2f &u) const override {
        BSDFSample bs;
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || si.wi.z <= 0.f)
            return {bs, Color3f(0.f)};
        bs.wo = m_bug == Bug::MissingCosine ? warp::square_to_uniform_hemisphere(u)
                                            : warp::square_to_cosine_hemisphere(u);
        if (m_bug == Bug::StrayBelow && sample1 < 1e-5f) bs.wo.z = -bs.wo.z;
        bs.pdf = pdf(ctx, si, bs.wo);
        bs.sampled_type = BSDFFlags::DiffuseReflection;
        bs.sampled_component = 0;
        if (m_bug == Bug::StrayBelow && bs.wo.z < 0.f) return {bs, m_reflectance};
        if (!(bs.pdf > 0.f)) return {bs, Color3f(0.f)};
        Color3f weight = eval(ctx, si, bs.wo) / bs.pdf;
        if (m_bug == Bug::WrongWeight) weight = Color3f(1.f);
        if (m_bug == Bug::NanWeight && bs.wo.x > 0.95f)
            weight.g = std::numeric_limits<float>::quiet_NaN();
        return {bs, weight};
    }
    Color3f eval(const BSDFContext &ctx, const SurfaceInteraction &si,
                 const Vector3f &wo) const override {
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || si.wi.z <= 0.f || wo.z <= 0.f)
            return Color3f(0.f);
        return m_reflectance * (wo.z * InvPi);
    }
    float pdf(const BSDFContext &ctx, const SurfaceInteraction &si,
              const Vector3f &wo) const override {
        if (!ctx.is_enabled(BSDFFlags::DiffuseReflection) || si.wi.z <= 0.f || wo.z <= 0.f)
            return 0.f;
        if (m_bug == Bug::NanPdf && wo.x > 0.95f) return std::numeric_limits<float>::quiet_NaN();
        float p = wo.z * InvPi;
        return m_bug == Bug::PdfScaled ? 1.05f * p : p;
    }
    std::string to_string() const override { return "TestLambert"; }

    Color3f m_reflectance;

private:
    Bug m_bug;
};

Chi2Result run_lambert(TestLambert::Bug bug, uint32_t seed = 0, uint32_t tests = 1) {
    BSDFAdapter adapter(std::make_shared<TestLambert>(bug), direction_from_angles(40.f, 20.f));
    Chi2Options opts;
    opts.res = 16;
    opts.samples = 250000;
    opts.seed = seed;
    opts.test_count = tests;
    return run_chi2(adapter, opts);
}

bool mentions(const Chi2Result &r, const std::string &text) {
    for (const std::string &f : r.failures)
        if (f.find(text) != std::string::npos) return true;
    return false;
}

/// Q(a, x) for integer a, by the finite sum e^-x Σ_{k<a} x^k/k! (independent of the code tested).
double gamma_q_integer(int a, double x) {
    double term = std::exp(-x), sum = 0.0;
    for (int k = 0; k < a; ++k) {
        sum += term;
        term *= x / (k + 1);
    }
    return sum;
}

} // namespace

TEST(Chi2Statistics, IncompleteGammaKnownValues) {
    for (double x : {0.01, 0.5, 1.0, 2.5, 7.0, 30.0}) {
        EXPECT_NEAR(regularized_gamma_p(1.0, x), 1.0 - std::exp(-x), 1e-13) << x;
        EXPECT_NEAR(regularized_gamma_p(0.5, x), std::erf(std::sqrt(x)), 1e-13) << x;
        EXPECT_NEAR(regularized_gamma_q(3.0, x), std::exp(-x) * (1.0 + x + 0.5 * x * x), 1e-13)
            << x;
    }
    // Both expansions (x < a + 1 and x >= a + 1) against the finite sum, relative to the value.
    for (int a : {5, 50, 400})
        for (double f : {0.3, 0.9, 1.0, 1.1, 2.0}) {
            double x = f * a, q = gamma_q_integer(a, x);
            EXPECT_NEAR(regularized_gamma_q(a, x), q, 1e-10 * std::max(q, 1e-300) + 1e-15)
                << a << " " << x;
            EXPECT_NEAR(regularized_gamma_p(a, x) + regularized_gamma_q(a, x), 1.0, 1e-12);
        }
    EXPECT_EQ(regularized_gamma_p(2.0, 0.0), 0.0);
    EXPECT_EQ(regularized_gamma_q(2.0, 0.0), 1.0);
    EXPECT_TRUE(std::isnan(regularized_gamma_p(-1.0, 1.0)));
}

TEST(Chi2Statistics, ChiSquareSurvivalTable) {
    // 95 % quantiles of the chi-square distribution from statistical tables.
    EXPECT_NEAR(chi2_survival(3.841458820694124, 1), 0.05, 1e-10);
    EXPECT_NEAR(chi2_survival(18.307038053275146, 10), 0.05, 1e-10);
    EXPECT_NEAR(chi2_survival(124.34211340400407, 100), 0.05, 1e-9);
    EXPECT_NEAR(chi2_survival(6.634896601021214, 1), 0.01, 1e-10);
    for (double x : {0.5, 3.0, 20.0}) EXPECT_NEAR(chi2_survival(x, 2), std::exp(-0.5 * x), 1e-13);
    EXPECT_EQ(chi2_survival(0.0, 5), 1.0);
}

TEST(Chi2Statistics, SidakCorrection) {
    EXPECT_DOUBLE_EQ(sidak_correction(0.01, 1), 0.01);
    EXPECT_NEAR(sidak_correction(0.01, 20), 1.0 - std::pow(0.99, 1.0 / 20.0), 1e-15);
    EXPECT_NEAR(sidak_correction(0.05, 1000000), 5.1293294e-8, 1e-14);
}

TEST(Chi2Pearson, PoolsCellsBelowTheThreshold) {
    // Five cells expecting 1 become one term once the pool reaches 5; two big cells are terms.
    std::vector<double> exp = {1, 1, 1, 1, 1, 10, 20}, obs = {0, 2, 1, 3, 1, 12, 16};
    PearsonResult r = pearson_chi2(obs, exp, 5.0);
    EXPECT_EQ(r.pooled_cells, 5);
    EXPECT_EQ(r.dof, 2);
    double want = sqr(7.0 - 5.0) / 5.0 + sqr(12.0 - 10.0) / 10.0 + sqr(16.0 - 20.0) / 20.0;
    EXPECT_NEAR(r.statistic, want, 1e-12);
    EXPECT_FALSE(r.zero_expected_hit);
}

TEST(Chi2Pearson, LeftoverPoolJoinsTheSmallestLargeCell) {
    std::vector<double> exp = {2, 30, 2, 10}, obs = {3, 33, 0, 11};
    PearsonResult r = pearson_chi2(obs, exp, 5.0);
    // Pool {2, 2} -> 4 < 5 joins the cell expecting 10: (14 - 14)^2/14 = 0; then (33-30)^2/30.
    EXPECT_EQ(r.dof, 1);
    EXPECT_NEAR(r.statistic, 9.0 / 30.0, 1e-12);
}

TEST(Chi2Pearson, OrderOfCellsDoesNotMatter) {
    std::vector<double> exp = {3, 40, 0.5, 8, 2, 25}, obs = {4, 38, 1, 9, 0, 30};
    PearsonResult a = pearson_chi2(obs, exp);
    std::vector<double> exp2(exp.rbegin(), exp.rend()), obs2(obs.rbegin(), obs.rend());
    PearsonResult b = pearson_chi2(obs2, exp2);
    EXPECT_EQ(a.dof, b.dof);
    EXPECT_NEAR(a.statistic, b.statistic, 1e-12);
}

TEST(Chi2Pearson, ZeroExpectationWithSamplesIsFlagged) {
    PearsonResult r = pearson_chi2({0, 1, 9, 10}, {0, 0, 10, 10});
    EXPECT_TRUE(r.zero_expected_hit);
    EXPECT_EQ(r.zero_expected_cell, 1u);
    // Cells where both counts are zero are skipped silently.
    PearsonResult s = pearson_chi2({0, 9, 10}, {0, 10, 10});
    EXPECT_FALSE(s.zero_expected_hit);
    EXPECT_EQ(s.dof, 1);
}

TEST(SlowChi2BSDF, CorrectSamplerAcceptedOverTwentySeeds) {
    // Family of 20 tests at 1 % with Sidak: each must pass at the corrected level, and all of
    // them pass with probability 0.99 for a correct sampler; the seeds are fixed.
    for (uint32_t seed = 0; seed < 20; ++seed) {
        Chi2Result r = run_lambert(TestLambert::Bug::None, seed, 20);
        EXPECT_TRUE(r.passed) << "seed " << seed << "\n" << r.summary();
        EXPECT_GT(r.dof, 100);
        EXPECT_NEAR(r.pdf_integral, 1.0, 1e-4);
        EXPECT_NEAR(r.mean_weight.r, 0.7, 1e-5);
    }
}

TEST(Chi2BSDF, ResultsReproduce) {
    Chi2Result a = run_lambert(TestLambert::Bug::None, 7),
               b = run_lambert(TestLambert::Bug::None, 7);
    EXPECT_EQ(a.observed, b.observed);
    EXPECT_EQ(a.statistic, b.statistic);
    Chi2Result c = run_lambert(TestLambert::Bug::None, 8);
    EXPECT_NE(a.observed, c.observed);
}

TEST(Chi2BSDF, MissingCosineRejectedByTheHistogram) {
    Chi2Result r = run_lambert(TestLambert::Bug::MissingCosine);
    EXPECT_FALSE(r.passed);
    EXPECT_TRUE(mentions(r, "histogram does not match")) << r.summary();
    EXPECT_LT(r.p_value, 1e-10);
    // The pdf itself is normalised and the weights are eval/pdf: only the histogram sees it.
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-4);
    EXPECT_EQ(r.weight_mismatches, 0u);
}

TEST(Chi2BSDF, ScaledPdfRejected) {
    Chi2Result r = run_lambert(TestLambert::Bug::PdfScaled);
    EXPECT_FALSE(r.passed);
    EXPECT_TRUE(mentions(r, "integrates to")) << r.summary();
    EXPECT_TRUE(mentions(r, "histogram does not match")) << r.summary();
}

TEST(Chi2BSDF, NaNPdfIsAnOutrightFailure) {
    Chi2Result r = run_lambert(TestLambert::Bug::NanPdf);
    EXPECT_FALSE(r.passed);
    EXPECT_TRUE(mentions(r, "non-finite")) << r.summary();
}

TEST(Chi2BSDF, NaNWeightIsAnOutrightFailure) {
    Chi2Result r = run_lambert(TestLambert::Bug::NanWeight);
    EXPECT_FALSE(r.passed);
    EXPECT_TRUE(mentions(r, "non-finite weight")) << r.summary();
    // The histogram and the pdf are right: only the weights give it away.
    EXPECT_GT(r.p_value, 1e-3) << r.summary();
}

TEST(Chi2BSDF, SampleInZeroExpectationCellIsAnOutrightFailure) {
    Chi2Result r = run_lambert(TestLambert::Bug::StrayBelow);
    EXPECT_FALSE(r.passed);
    EXPECT_TRUE(mentions(r, "integrates to zero")) << r.summary();
    // A couple of stray samples among 250000 are invisible to the statistic itself.
    EXPECT_GT(r.p_value, 1e-3) << r.summary();
}

TEST(SlowChi2BSDF, WeightNotEvalOverPdfRejected) {
    Chi2Result r = run_lambert(TestLambert::Bug::WrongWeight);
    EXPECT_FALSE(r.passed);
    EXPECT_EQ(r.weight_mismatches, r.smooth);
    EXPECT_TRUE(mentions(r, "eval/pdf")) << r.summary();
}

TEST(Chi2BSDF, EnergyGainRejected) {
    Chi2Result r = run_lambert(TestLambert::Bug::Energy);
    EXPECT_FALSE(r.passed);
    EXPECT_TRUE(mentions(r, "energy")) << r.summary();
}

TEST(Chi2BSDF, BackSideGivesNoSamplesAndZeroPdf) {
    // From below, the Lambertian BSDF does nothing: no histogram to test, and that is no failure.
    BSDFAdapter adapter(std::make_shared<TestLambert>(TestLambert::Bug::None),
                        Vector3f(0.3f, 0.f, -1.f));
    Chi2Options opts;
    opts.res = 8;
    opts.samples = 10000;
    Chi2Result r = run_chi2(adapter, opts);
    EXPECT_TRUE(r.passed) << r.summary();
    EXPECT_EQ(r.failed, 10000u);
}

TEST(Chi2Microfacet, GGXVisibleNormalsAccepted) {
    MicrofacetAdapter adapter("ggx", 0.5f, 0.3f, true, direction_from_angles(50.f, 30.f));
    Chi2Options opts;
    opts.res = 16;
    opts.samples = 200000;
    Chi2Result r = run_chi2(adapter, opts);
    EXPECT_TRUE(r.passed) << r.summary();
    EXPECT_THROW(MicrofacetAdapter("phong", 0.1f, 0.1f, true, Vector3f(0, 0, 1)), Error);
}

TEST(Chi2Xml, EntriesGetTheirTypes) {
    std::string xml =
        chi2_object_xml(ObjectType::BSDF, "roughconductor",
                        {"alpha=0.2", "sample_visible=false", "specular_reflectance=0.5,0.6,0.7",
                         "distribution=ggx", "integer:n=3", "vector:v=1,2,3"});
    EXPECT_NE(xml.find("<bsdf version=\"3.0.0\" type=\"roughconductor\">"), std::string::npos)
        << xml;
    EXPECT_NE(xml.find("<float name=\"alpha\" value=\"0.2\"/>"), std::string::npos) << xml;
    EXPECT_NE(xml.find("<boolean name=\"sample_visible\" value=\"false\"/>"), std::string::npos)
        << xml;
    EXPECT_NE(xml.find("<rgb name=\"specular_reflectance\" value=\"0.5,0.6,0.7\"/>"),
              std::string::npos)
        << xml;
    EXPECT_NE(xml.find("<string name=\"distribution\" value=\"ggx\"/>"), std::string::npos) << xml;
    EXPECT_NE(xml.find("<integer name=\"n\" value=\"3\"/>"), std::string::npos) << xml;
    EXPECT_NE(xml.find("<vector name=\"v\" x=\"1\" y=\"2\" z=\"3\"/>"), std::string::npos) << xml;
    EXPECT_THROW(chi2_object_xml(ObjectType::BSDF, "x", {"novalue"}), Error);
    EXPECT_THROW(chi2_object_xml(ObjectType::BSDF, "x", {"matrix:m=1"}), Error);
    // Markup in values is escaped.
    EXPECT_NE(chi2_object_xml(ObjectType::BSDF, "x", {"s=a<b"}).find("a&lt;b"), std::string::npos);
}
