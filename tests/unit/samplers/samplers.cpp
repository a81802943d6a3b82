// Convergence of every sampler on smooth integrals: the RMS error over many pixels must fall at
// the rate the sampler promises (N^-1/2 for independent sampling, about N^-1 or better for the
// stratified and low-discrepancy ones on a smooth 2D integrand).
#include <facet/plugin.h>
#include <facet/qmc.h>
#include <facet/sampler.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

using namespace facet;

namespace {

std::shared_ptr<Sampler> make_sampler(const std::string &type, int64_t spp) {
    Properties props(type);
    props.set_int("sample_count", spp);
    return PluginRegistry::instance().create_as<Sampler>(ObjectType::Sampler, props);
}

/// Smooth integrand on [0,1]²: x·e^x · (1 + cos(2πy)/2) with integral 1.
double f2(const Point2f &p) {
    return p.x * std::exp(p.x) * (1.0 + 0.5 * std::cos(2.0 * M_PI * p.y));
}

/// RMS error of the N-sample estimate over `pixels` independent pixels. `dim` 2D draws are skipped
/// first, so dimensions other than the first are exercised too.
double rms_error_2d(const std::string &type, int spp, int pixels, int dim) {
    auto base = make_sampler(type, spp);
    auto sampler = base->clone();
    int n = int(sampler->sample_count());
    double sum_sq = 0.0;
    for (int px = 0; px < pixels; ++px) {
        sampler->seed(uint64_t(px) * 7919u + 13u);
        double est = 0.0;
        for (int s = 0; s < n; ++s) {
            for (int d = 0; d < dim; ++d) sampler->next_2d();
            est += f2(sampler->next_2d());
            sampler->advance();
        }
        est /= n;
        sum_sq += (est - 1.0) * (est - 1.0);
    }
    return std::sqrt(sum_sq / pixels);
}

/// Least-squares slope of log(rmse) against log(N).
double convergence_slope(const std::string &type, int dim) {
    std::vector<int> counts = {16, 64, 256, 1024};
    std::vector<double> xs, ys;
    for (int n : counts) {
        xs.push_back(std::log(double(n)));
        ys.push_back(std::log(rms_error_2d(type, n, 256, dim)));
    }
    double mx = 0, my = 0;
    for (size_t i = 0; i < xs.size(); ++i) {
        mx += xs[i];
        my += ys[i];
    }
    mx /= xs.size();
    my /= ys.size();
    double num = 0, den = 0;
    for (size_t i = 0; i < xs.size(); ++i) {
        num += (xs[i] - mx) * (ys[i] - my);
        den += sqr(xs[i] - mx);
    }
    return num / den;
}

} // namespace

TEST(SamplerConvergence, IndependentIsMonteCarloRate) {
    double slope = convergence_slope("independent", 0);
    EXPECT_NEAR(slope, -0.5, 0.1);
}

TEST(SamplerConvergence, StratifiedBeatsMonteCarlo) {
    EXPECT_LT(convergence_slope("stratified", 0), -0.85);
    EXPECT_LT(convergence_slope("stratified", 3), -0.85);
}

TEST(SamplerConvergence, MultijitterBeatsMonteCarlo) {
    EXPECT_LT(convergence_slope("multijitter", 0), -0.85);
    EXPECT_LT(convergence_slope("multijitter", 3), -0.85);
}

TEST(SamplerConvergence, LowDiscrepancyBeatsMonteCarlo) {
    EXPECT_LT(convergence_slope("ldsampler", 0), -0.85);
    EXPECT_LT(convergence_slope("ldsampler", 3), -0.85);
}

TEST(Samplers, DeterministicPerSeedAndInUnitInterval) {
    for (const char *type : {"independent", "stratified", "multijitter", "ldsampler"}) {
        auto a = make_sampler(type, 64)->clone(), b = make_sampler(type, 64)->clone();
        a->seed(42);
        b->seed(42);
        bool differs_from_other_pixel = false;
        auto c = make_sampler(type, 64)->clone();
        c->seed(43);
        for (int s = 0; s < 64; ++s) {
            for (int d = 0; d < 4; ++d) {
                Point2f pa = a->next_2d(), pb = b->next_2d(), pc = c->next_2d();
                float fa = a->next_1d(), fb = b->next_1d();
                c->next_1d();
                ASSERT_EQ(pa, pb) << type;
                ASSERT_EQ(fa, fb) << type;
                for (float v : {pa.x, pa.y, fa}) {
                    ASSERT_GE(v, 0.f) << type;
                    ASSERT_LT(v, 1.f) << type;
                }
                differs_from_other_pixel |= pa != pc;
            }
            a->advance();
            b->advance();
            c->advance();
        }
        EXPECT_TRUE(differs_from_other_pixel) << type;
    }
}

TEST(Samplers, StratifiedCoversEveryStratumOnce) {
    auto s = make_sampler("stratified", 16)->clone();
    s->seed(7);
    std::vector<int> hits(16, 0);
    for (int i = 0; i < 16; ++i) {
        Point2f p = s->next_2d();
        hits[size_t(int(p.y * 4) * 4 + int(p.x * 4))]++;
        s->advance();
    }
    for (int h : hits) EXPECT_EQ(h, 1);
}

TEST(Samplers, SampleCountRounding) {
    EXPECT_EQ(make_sampler("stratified", 10)->sample_count(), 16u);
    EXPECT_EQ(make_sampler("ldsampler", 10)->sample_count(), 16u);
    EXPECT_EQ(make_sampler("multijitter", 10)->sample_count(), 10u);
    // A count set by the render loop (--spp) is rounded the same way, and set_sample_count()
    // returns it, so the render loop can report the samples actually taken.
    for (auto [type, rounded] : {std::pair<const char *, uint32_t>{"stratified", 16u},
                                 {"ldsampler", 16u},
                                 {"multijitter", 10u},
                                 {"orthogonal", 25u},
                                 {"independent", 10u}}) {
        auto s = make_sampler(type, 4)->clone();
        EXPECT_EQ(s->set_sample_count(10), rounded) << type;
        EXPECT_EQ(s->sample_count(), rounded) << type;
    }
}

// ldsampler rounds up to a power of two in 32 bits: 2^31 is the largest count it can take; a
// larger one is an error (once the rounding looped forever above 2^31).
TEST(Samplers, LowDiscrepancyCountLimit) {
    Properties props("ldsampler");
    props.set_int("sample_count", int64_t(1) << 31);
    auto s = PluginRegistry::instance().create_as<Sampler>(ObjectType::Sampler, props);
    EXPECT_EQ(s->sample_count(), uint32_t(1) << 31);
    auto big = make_sampler("ldsampler", (1 << 30) + 1)->clone();
    EXPECT_EQ(big->sample_count(), uint32_t(1) << 31);
    for (int64_t count : {(int64_t(1) << 31) + 1, int64_t(UINT32_MAX)}) {
        Properties bad("ldsampler");
        bad.set_int("sample_count", count);
        try {
            PluginRegistry::instance().create(ObjectType::Sampler, bad);
            ADD_FAILURE() << "sample_count " << count << " was accepted";
        } catch (const Error &e) {
            EXPECT_NE(std::string(e.what()).find("at most 2^31"), std::string::npos) << e.what();
        }
        // The same limit when the render loop sets the count.
        auto clone = make_sampler("ldsampler", 4)->clone();
        EXPECT_THROW(clone->set_sample_count(uint32_t(count)), Error);
    }
}

// The sample counts near 2^32: stratified rounds up to a square in 32 bits, so 65535^2 is the
// largest count it can take and a larger one is an error (it once wrapped to 0 and took `% 0`);
// orthogonal's prime square must fit too; multijitter takes any count.
TEST(Samplers, HugeSampleCounts) {
    const uint32_t max_square = 65535u * 65535u;
    auto s = make_sampler("stratified", max_square)->clone();
    EXPECT_EQ(s->sample_count(), max_square);
    s->seed(3);
    Point2f p = s->next_2d();
    EXPECT_TRUE(p.x >= 0.f && p.x < 1.f && p.y >= 0.f && p.y < 1.f);
    for (int64_t count : {int64_t(max_square) + 1, int64_t(UINT32_MAX)}) {
        Properties bad("stratified");
        bad.set_int("sample_count", count);
        try {
            PluginRegistry::instance().create(ObjectType::Sampler, bad);
            ADD_FAILURE() << "stratified sample_count " << count << " was accepted";
        } catch (const Error &e) {
            EXPECT_NE(std::string(e.what()).find("at most 65535^2"), std::string::npos) << e.what();
        }
        auto clone = make_sampler("stratified", 4)->clone();
        EXPECT_THROW(clone->set_sample_count(uint32_t(count)), Error);
    }
    // 65521 is the largest prime below 2^16: a larger count needs 65537^2 > 2^32 rows.
    EXPECT_EQ(make_sampler("orthogonal", 65521u * 65521u)->sample_count(), 65521u * 65521u);
    Properties ortho("orthogonal");
    ortho.set_int("sample_count", int64_t(65521u) * 65521u + 1);
    EXPECT_THROW(PluginRegistry::instance().create(ObjectType::Sampler, ortho), Error);
    auto mj = make_sampler("multijitter", UINT32_MAX)->clone();
    EXPECT_EQ(mj->sample_count(), UINT32_MAX);
    mj->seed(5);
    p = mj->next_2d();
    EXPECT_TRUE(p.x >= 0.f && p.x < 1.f && p.y >= 0.f && p.y < 1.f);
}

// qmc::Divisor replaces the samplers' divisions by multiplications: it must give the quotient
// and remainder of the processor's division for every 32-bit value, and permute() over a
// Divisor the same element as over the plain count.
TEST(Samplers, DivisorDividesExactly) {
    const uint32_t big = 1u << 31;
    std::vector<uint32_t> divisors = {65521u, 65536u, big - 1u, big, UINT32_MAX - 1u, UINT32_MAX};
    for (uint32_t d = 1; d <= 1000; ++d) divisors.push_back(d);
    std::mt19937 rng(17);
    for (int i = 0; i < 200; ++i) divisors.push_back(uint32_t(rng()) >> (rng() % 32));
    for (uint32_t d : divisors) {
        if (d == 0) continue;
        const qmc::Divisor div(d);
        std::vector<uint32_t> xs = {0u,
                                    1u,
                                    d - 1u,
                                    d,
                                    d + 1u,
                                    2u * d - 1u,
                                    2u * d,
                                    UINT32_MAX / d * d,
                                    UINT32_MAX / d * d - 1u,
                                    UINT32_MAX - 1u,
                                    UINT32_MAX};
        for (int i = 0; i < 300; ++i) xs.push_back(uint32_t(rng()));
        for (uint32_t x : xs) {
            ASSERT_EQ(div.div(x), x / d) << x << " / " << d;
            ASSERT_EQ(div.mod(x), x % d) << x << " % " << d;
        }
    }
    for (uint32_t n : {1u, 2u, 5u, 8u, 24u, 64u, 100u, 1000u, 4096u})
        for (uint32_t seed : {0u, 1u, 0x9e3779b9u, 0xfffffffbu})
            for (uint32_t i = 0; i < n; ++i)
                ASSERT_EQ(qmc::permute(i, qmc::Divisor(n), seed), qmc::permute(i, n, seed))
                    << "n " << n << " seed " << seed << " i " << i;
}

TEST(Samplers, MultijitterStratifiesGridAndProjections) {
    const int n = 24; // a 4 x 6 grid
    auto s = make_sampler("multijitter", n)->clone();
    s->seed(11);
    std::vector<int> xs(n, 0), ys(n, 0);
    for (int i = 0; i < n; ++i) {
        Point2f p = s->next_2d();
        xs[size_t(p.x * n)]++;
        ys[size_t(p.y * n)]++;
        s->advance();
    }
    for (int i = 0; i < n; ++i) {
        EXPECT_EQ(xs[size_t(i)], 1) << "x stratum " << i;
        EXPECT_EQ(ys[size_t(i)], 1) << "y stratum " << i;
    }
}

TEST(Samplers, SampleIndexAloneDecidesTheValues) {
    // Sample i of a pixel is the same whether the samples before it were taken (with any number
    // of dimensions each) or skipped: parts of a render may take any range of samples.
    for (const char *type :
         {"independent", "stratified", "multijitter", "ldsampler", "orthogonal"}) {
        auto a = make_sampler(type, 25)->clone(), b = make_sampler(type, 25)->clone();
        a->seed(99);
        std::vector<float> sequential;
        for (uint32_t i = 0; i < 25; ++i) {
            if (i > 0) a->advance();
            EXPECT_EQ(a->sample_index(), i);
            for (int d = 0; d < 3; ++d) {
                Point2f p = a->next_2d();
                sequential.push_back(p.x);
                sequential.push_back(p.y);
                sequential.push_back(a->next_1d());
            }
            for (uint32_t d = 0; d < i % 4; ++d) a->next_1d(); // uneven path lengths
        }
        b->seed(99);
        for (uint32_t i = 25; i-- > 0;) { // backwards, one sample at a time
            b->set_sample_index(i);
            for (int d = 0; d < 3; ++d) {
                Point2f p = b->next_2d();
                EXPECT_EQ(p.x, sequential[i * 9 + d * 3]) << type << " sample " << i;
                EXPECT_EQ(p.y, sequential[i * 9 + d * 3 + 1]) << type << " sample " << i;
                EXPECT_EQ(b->next_1d(), sequential[i * 9 + d * 3 + 2]) << type << " sample " << i;
            }
        }
    }
}

TEST(Samplers, IndependentSamplesDifferAcrossIndices) {
    auto s = make_sampler("independent", 4)->clone();
    s->seed(5);
    Point2f first = s->next_2d();
    for (uint32_t i = 1; i < 64; ++i) {
        s->set_sample_index(i);
        EXPECT_NE(s->next_2d(), first) << i;
    }
}
