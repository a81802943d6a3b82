// DiscreteDistribution::sample_reuse() must pick the entry an inversion of the whole CDF picks
// (the first whose cumulative weight exceeds u), whatever its guide table: the same entry and the
// same rescaled variate, at the guide's own thresholds k/K, on both sides of every CDF value and
// for zero-weight runs, a dominant entry and sizes on either side of a power of two.
#include <facet/distribution.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

using namespace facet;

namespace {

/// The plain inversion: a linear scan of the CDF accumulated as build() accumulates it.
struct Inversion {
    std::vector<double> cdf;

    explicit Inversion(const std::vector<float> &w) : cdf(w.size() + 1, 0.0) {
        for (size_t i = 0; i < w.size(); ++i) cdf[i + 1] = cdf[i] + double(std::max(w[i], 0.f));
        const double sum = cdf.back();
        if (sum > 0.0)
            for (double &c : cdf) c /= sum;
    }

    size_t sample(float &u) const {
        const size_t n = cdf.size() - 1;
        size_t i = 0;
        while (i < n && !(cdf[i + 1] > double(u))) ++i;
        i = std::min(i, n - 1);
        while (i + 1 < n && float(cdf[i + 1] - cdf[i]) == 0.f) ++i;
        const double lo = cdf[i], w = cdf[i + 1] - cdf[i];
        u = w > 0.0 ? std::min(float((double(u) - lo) / w), OneMinusEpsilon) : 0.f;
        return i;
    }
};

/// Variates that land on the edges: 0, the largest float below 1, 1, every multiple of 1/K for
/// the powers of two K up to 2n (the guide's thresholds), each CDF value rounded to float and its
/// float neighbours, and random ones.
std::vector<float> probes(const Inversion &inv, std::mt19937 &rng) {
    std::vector<float> u = {0.f, OneMinusEpsilon, 1.f};
    const size_t n = inv.cdf.size() - 1;
    for (size_t K = 1; K <= 2 * n; K *= 2)
        for (size_t k = 0; k <= K; ++k) u.push_back(float(double(k) / double(K)));
    for (double c : inv.cdf) {
        const float f = float(c);
        for (float v : {std::nextafter(f, 0.f), f, std::nextafter(f, 2.f)})
            if (v >= 0.f && v <= 1.f) u.push_back(v);
    }
    std::uniform_real_distribution<float> uniform(0.f, 1.f);
    for (int i = 0; i < 2000; ++i) u.push_back(std::min(uniform(rng), OneMinusEpsilon));
    return u;
}

void expect_same_as_inversion(const std::vector<float> &weights, const char *what) {
    SCOPED_TRACE(what);
    const DiscreteDistribution dist(weights);
    const Inversion inv(weights);
    std::mt19937 rng(uint32_t(weights.size()) * 7919u + 1u);
    size_t checked = 0;
    for (float u : probes(inv, rng)) {
        float got_u = u, want_u = u;
        const size_t got = dist.sample_reuse(got_u), want = inv.sample(want_u);
        ASSERT_EQ(got, want) << "u = " << u << " (n = " << weights.size() << ")";
        ASSERT_EQ(got_u, want_u) << "u = " << u;
        ++checked;
    }
    EXPECT_GT(checked, 2000u);
}

} // namespace

TEST(DiscreteDistribution, GuidedSearchPicksTheEntryOfTheFullInversion) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> uniform(0.f, 1.f);
    for (size_t n : {1, 2, 3, 7, 8, 9, 31, 32, 33, 1000, 4096, 32512}) {
        std::vector<float> w(n);
        for (float &x : w) x = uniform(rng);
        expect_same_as_inversion(w, "random weights");
        std::fill(w.begin(), w.end(), 1.f);
        expect_same_as_inversion(w, "equal weights");
    }
}

TEST(DiscreteDistribution, GuidedSearchHandlesZeroRunsAndADominantEntry) {
    // A sky with a sun: one entry holds nearly all the weight, so most of the guide's buckets
    // fall inside it and one bucket spans hundreds of entries.
    std::vector<float> sun(1000, 1e-3f);
    sun[617] = 1e6f;
    expect_same_as_inversion(sun, "dominant entry");
    // Runs of zero weight at the start, the end and between the others.
    std::vector<float> gaps(300, 0.f);
    for (size_t i = 40; i < 300; i += 37) gaps[i] = float(i % 5 + 1);
    expect_same_as_inversion(gaps, "zero runs");
    // Weights 2^-k: the CDF values crowd towards 1, many inside the last bucket.
    std::vector<float> halving(60);
    for (size_t i = 0; i < halving.size(); ++i) halving[i] = std::ldexp(1.f, -int(i));
    expect_same_as_inversion(halving, "halving weights");
    // Nothing to sample: the last entry with rescaled 0, as before.
    expect_same_as_inversion(std::vector<float>(17, 0.f), "all zero");
}

TEST(DiscreteDistribution, PickFrequenciesFollowTheWeights) {
    // The guide only shortens the search: frequencies still match the weights.
    const std::vector<float> w = {1.f, 0.f, 3.f, 0.5f, 0.f, 0.f, 2.5f, 1.f, 0.f};
    const DiscreteDistribution dist(w);
    std::vector<size_t> hits(w.size(), 0);
    const size_t draws = 1 << 20;
    for (size_t s = 0; s < draws; ++s) {
        float u = (float(s) + 0.5f) / float(draws); // stratified: exact up to the strata
        ++hits[dist.sample_reuse(u)];
    }
    for (size_t i = 0; i < w.size(); ++i)
        EXPECT_NEAR(double(hits[i]) / double(draws), double(w[i]) / 8.0, 2.0 / double(draws))
            << "entry " << i;
}
