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

/// The plain inversion of the two-level CDF (a CDF over blocks of BlockSize entries, then each
/// block's own CDF relative to it) accumulated as build() accumulates it: a search of the whole
/// block CDF, without the guide or the candidate shortcut, then a scan of the block.
struct Inversion {
    static constexpr size_t B = DiscreteDistribution::BlockSize;
    size_t n;
    std::vector<double> cdf;                  ///< over the blocks, normalised
    std::vector<std::vector<float>> in_block; ///< each block's CDF relative to it

    explicit Inversion(const std::vector<float> &w) : n(w.size()) {
        const size_t blocks = (n + B - 1) / B;
        cdf.assign(blocks + 1, 0.0);
        for (size_t b = 0; b < blocks; ++b) {
            std::vector<double> partial;
            double s = 0.0;
            for (size_t i = b * B; i < b * B + B; ++i) {
                if (i < n) s += double(std::max(w[i], 0.f));
                partial.push_back(s);
            }
            std::vector<float> c;
            for (double p : partial) c.push_back(s > 0.0 ? float(p / s) : 1.f);
            in_block.push_back(c);
            cdf[b + 1] = cdf[b] + s;
        }
        const double sum = cdf.back();
        if (sum > 0.0)
            for (double &c : cdf) c /= sum;
    }

    size_t sample(float &u) const {
        const size_t blocks = cdf.size() - 1;
        // The first block whose CDF exceeds u, by a search of the whole block CDF (no guide).
        size_t b =
            size_t(std::upper_bound(cdf.begin() + 1, cdf.end(), double(u)) - cdf.begin()) - 1;
        b = std::min(b, blocks - 1);
        while (b + 1 < blocks && !(cdf[b + 1] > cdf[b])) ++b;
        const double width = cdf[b + 1] - cdf[b];
        if (!(width > 0.0)) {
            u = 0.f;
            return n - 1;
        }
        const float v = std::clamp(float((double(u) - cdf[b]) / width), 0.f, OneMinusEpsilon);
        const std::vector<float> &c = in_block[b];
        size_t j = 0;
        while (j + 1 < B && !(c[j] > v)) ++j;
        const float c0 = j > 0 ? c[j - 1] : 0.f;
        u = c[j] > c0 ? std::clamp((v - c0) / (c[j] - c0), 0.f, OneMinusEpsilon) : 0.f;
        return std::min(b * B + j, n - 1);
    }
};

/// Variates that land on the edges: 0, the largest float below 1, 1, every multiple of 1/K for
/// the powers of two K up to 2n (the guide's thresholds), each block's and each entry's CDF value
/// rounded to float and its float neighbours, and random ones.
std::vector<float> probes(const Inversion &inv, std::mt19937 &rng) {
    std::vector<float> u = {0.f, OneMinusEpsilon, 1.f};
    for (size_t K = 1; K <= 2 * inv.n; K *= 2)
        for (size_t k = 0; k <= K; ++k) u.push_back(float(double(k) / double(K)));
    std::vector<double> edges(inv.cdf);
    for (size_t b = 0; b + 1 < inv.cdf.size(); ++b)
        for (float c : inv.in_block[b])
            edges.push_back(inv.cdf[b] + (inv.cdf[b + 1] - inv.cdf[b]) * double(c));
    for (double c : edges) {
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
    const size_t n_max = size_t(-1);
    for (float u : probes(inv, rng)) {
        float got_u = u, want_u = u;
        const size_t got = dist.sample_reuse(got_u), want = inv.sample(want_u);
        ASSERT_EQ(got, want) << "u = " << u << " (n = " << weights.size() << ")";
        ASSERT_EQ(got_u, want_u) << "u = " << u;
        // The hint names the entries the pick comes from, before it is made.
        float hinted_u = u;
        size_t first = n_max, last = n_max, calls = 0;
        const size_t hinted = dist.sample_reuse(hinted_u, [&](size_t a, size_t b) {
            first = a;
            last = b;
            ++calls;
        });
        ASSERT_EQ(hinted, got);
        ASSERT_EQ(hinted_u, got_u);
        ASSERT_EQ(calls, 1u);
        ASSERT_LE(first, got);
        ASSERT_GE(last, got);
        ASSERT_LT(last - first, DiscreteDistribution::BlockSize);
        ++checked;
    }
    EXPECT_GT(checked, 2000u);
}

} // namespace

TEST(DiscreteDistribution, GuidedSearchPicksTheEntryOfTheFullInversion) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> uniform(0.f, 1.f);
    // Sizes around a block (12 entries) and around the guide's eight-candidate limit: 63 and 127
    // blocks leave 8 or 9 candidates between guide entries.
    for (size_t n :
         {1, 2, 3, 7, 8, 9, 11, 12, 13, 24, 25, 31, 32, 33, 756, 1000, 1524, 4096, 32512}) {
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

TEST(DiscreteDistribution, PickFrequenciesFollowPmfAcrossBlocks) {
    // Many blocks, zero runs inside and across them, and a dominant entry: stratified draws pick
    // each entry as often as pmf() says, and pmf() is the weight's share to float precision.
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> uniform(0.f, 1.f);
    std::vector<float> w(137);
    for (float &x : w) x = uniform(rng);
    for (size_t i = 20; i < 40; ++i) w[i] = 0.f;
    w[3] = w[60] = w[136] = 0.f;
    w[77] = 40.f;
    double sum = 0.0;
    for (float x : w) sum += double(x);
    const DiscreteDistribution dist(w);
    std::vector<size_t> hits(w.size(), 0);
    const size_t draws = 1 << 22;
    for (size_t s = 0; s < draws; ++s) {
        float u = (float(s) + 0.5f) / float(draws);
        ++hits[dist.sample_reuse(u)];
    }
    constexpr size_t B = DiscreteDistribution::BlockSize;
    for (size_t i = 0; i < w.size(); ++i) {
        // An entry's share of its block is a difference of two floats relative to the block:
        // exact to a float ulp of the block's probability (plus pmf()'s own rounding).
        double block = 0.0;
        for (size_t k = i / B * B; k < std::min(i / B * B + B, w.size()); ++k) block += w[k];
        EXPECT_NEAR(dist.pmf(i), double(w[i]) / sum, 0x1p-23 * block / sum + 0x1p-24 * w[i] / sum)
            << "entry " << i;
        EXPECT_NEAR(double(hits[i]) / double(draws), double(dist.pmf(i)), 2.0 / double(draws))
            << "entry " << i;
        if (w[i] == 0.f) {
            EXPECT_EQ(hits[i], 0u) << "entry " << i;
        }
    }
}
