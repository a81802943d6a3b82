// The independent sampler: determinism per seed, distinct pixel streams, range, clones.
#include <facet/plugin.h>
#include <facet/random.h>
#include <facet/sampler.h>

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <utility>
#include <vector>

using namespace facet;

namespace {

std::shared_ptr<Sampler> independent(int64_t spp = 4, int64_t seed = 0) {
    Properties p("independent");
    p.set_int("sample_count", spp);
    p.set_int("seed", seed);
    return PluginRegistry::instance().create_as<Sampler>(ObjectType::Sampler, p);
}

std::vector<float> stream(Sampler &s, uint64_t pixel_seed, int n) {
    s.seed(pixel_seed);
    std::vector<float> v;
    for (int i = 0; i < n; ++i) {
        if (i % 3 == 0) {
            Point2f p = s.next_2d();
            v.push_back(p.x);
            v.push_back(p.y);
        } else {
            v.push_back(s.next_1d());
        }
        if (i % 7 == 6) s.advance();
    }
    return v;
}

} // namespace

TEST(IndependentSampler, Parameters) {
    auto s = PluginRegistry::instance().create_as<Sampler>(ObjectType::Sampler,
                                                           Properties("independent"));
    EXPECT_EQ(s->sample_count(), 4u);
    EXPECT_EQ(s->base_seed(), 0u);
    auto t = independent(64, 17);
    EXPECT_EQ(t->sample_count(), 64u);
    EXPECT_EQ(t->base_seed(), 17u);
    EXPECT_THROW(independent(0), Error);
    EXPECT_THROW(independent(-3), Error);
}

TEST(IndependentSampler, DeterministicPerSeed) {
    auto a = independent(), b = independent();
    EXPECT_EQ(stream(*a, 123, 100), stream(*b, 123, 100));
    // Re-seeding restarts the stream.
    EXPECT_EQ(stream(*a, 123, 100), stream(*a, 123, 100));
    // Clones produce the same values and are independent objects.
    auto c = a->clone();
    EXPECT_EQ(stream(*c, 99, 50), stream(*a, 99, 50));
    c->set_sample_count(16);
    EXPECT_EQ(a->sample_count(), 4u);
}

TEST(IndependentSampler, DifferentPixelsAndSeedsGiveDifferentStreams) {
    auto s = independent();
    std::set<std::vector<float>> seen;
    for (uint64_t px = 0; px < 64; ++px) seen.insert(stream(*s, px, 8));
    EXPECT_EQ(seen.size(), 64u);
    // Neighbouring pixels are not shifted copies of each other.
    auto a = stream(*s, 10, 32), b = stream(*s, 11, 32);
    for (size_t i = 0; i + 1 < a.size(); ++i) EXPECT_NE(a[i + 1], b[i]);
    // The sampler's own seed changes everything.
    auto t = independent(4, 1);
    EXPECT_NE(stream(*s, 10, 16), stream(*t, 10, 16));
    // High bits of the pixel seed matter too.
    EXPECT_NE(stream(*s, 5, 16), stream(*s, 5 + (uint64_t(1) << 40), 16));
}

TEST(IndependentSampler, ValuesInUnitIntervalAndUniform) {
    auto s = independent();
    const int bins = 16, n = 160000;
    std::vector<int> hist(bins, 0);
    s->seed(42);
    for (int i = 0; i < n; ++i) {
        float u = s->next_1d();
        ASSERT_GE(u, 0.f);
        ASSERT_LT(u, 1.f);
        Point2f p = s->next_2d();
        ASSERT_GE(p.x, 0.f);
        ASSERT_LT(p.x, 1.f);
        ASSERT_GE(p.y, 0.f);
        ASSERT_LT(p.y, 1.f);
        hist[int(u * bins)]++;
    }
    // Each bin expects 10000 with a standard deviation of ~97: 6 sigma is generous but finite.
    for (int h : hist) EXPECT_NEAR(h, n / bins, 600);
}

TEST(IndependentSampler, NeighbouringSamplesAndPixelsAreUncorrelated) {
    // The first value of every sample of pixels with neighbouring seeds (0, 1, 2, 3: the
    // hardest case for the seed hash), paired with the next sample's and the next pixel's:
    // uniform on an 8x8 grid (chi-square, 63 degrees of freedom: mean 63, sd 11.2; the bound is
    // 6 sd above) and with no linear correlation beyond 6 standard errors.
    auto s = independent(1 << 14);
    const uint32_t n = 1 << 14;
    std::vector<std::vector<float>> first(4, std::vector<float>(n));
    for (uint64_t px = 0; px < 4; ++px) {
        s->seed(px);
        for (uint32_t i = 0; i < n; ++i) {
            s->set_sample_index(i);
            first[px][i] = s->next_1d();
        }
    }
    auto check = [](const std::vector<std::pair<float, float>> &pairs, const char *what) {
        std::vector<double> cells(64, 0.0);
        double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
        for (auto [x, y] : pairs) {
            cells[size_t(int(x * 8) * 8 + int(y * 8))] += 1;
            sx += x, sy += y, sxx += double(x) * x, syy += double(y) * y, sxy += double(x) * y;
        }
        const double m = double(pairs.size()), expected = m / 64;
        double chi2 = 0;
        for (double c : cells) chi2 += (c - expected) * (c - expected) / expected;
        EXPECT_LT(chi2, 63 + 6 * 11.2) << what;
        const double cov = sxy / m - sx / m * sy / m;
        const double r = cov / std::sqrt((sxx / m - sx / m * sx / m) * (syy / m - sy / m * sy / m));
        EXPECT_LT(std::abs(r), 6 / std::sqrt(m)) << what;
    };
    std::vector<std::pair<float, float>> next_sample, next_pixel;
    for (size_t px = 0; px < 4; ++px)
        for (uint32_t i = 0; i < n; ++i) {
            if (i + 1 < n) next_sample.push_back({first[px][i], first[px][i + 1]});
            if (px + 1 < 4) next_pixel.push_back({first[px][i], first[px + 1][i]});
        }
    check(next_sample, "sample i against sample i + 1");
    check(next_pixel, "pixel seed p against p + 1");
}

TEST(TeaHash, PairIsTwoHashesBitForBit) {
    // tea_hash_pair runs both hashes in one SSE register: it must give exactly tea_hash's words,
    // for any inputs (carries, sign bits) and round counts.
    PCG32 rng(7, 11);
    for (int rounds : {1, 4, 8, 16})
        for (int i = 0; i < 2000; ++i) {
            uint32_t a0 = rng.next_uint32(), a1 = rng.next_uint32(), b0 = rng.next_uint32(),
                     b1 = rng.next_uint32();
            if (i == 0) a0 = a1 = b0 = b1 = 0u;
            if (i == 1) a0 = a1 = b0 = b1 = 0xffffffffu;
            auto [a, b] = tea_hash_pair(a0, a1, b0, b1, rounds);
            ASSERT_EQ(a, tea_hash(a0, a1, rounds)) << "rounds " << rounds << ", case " << i;
            ASSERT_EQ(b, tea_hash(b0, b1, rounds)) << "rounds " << rounds << ", case " << i;
        }
}

TEST(TeaHash, FourAreFourHashesBitForBit) {
    // tea_hash4 runs four hashes in the lanes of one SSE register (the render loop hashes the
    // seeds of four pixels at once): each lane must be exactly tea_hash's words.
    PCG32 rng(13, 17);
    for (int rounds : {1, 4, 8, 16})
        for (int i = 0; i < 2000; ++i) {
            uint32_t v0[4], v1[4];
            for (int k = 0; k < 4; ++k) {
                v0[k] = i == 0 ? 0u : i == 1 ? 0xffffffffu : rng.next_uint32();
                v1[k] = i == 0 ? 0u : i == 1 ? 0xffffffffu : rng.next_uint32();
            }
            uint64_t out[4];
            tea_hash4(v0, v1, out, rounds);
            for (int k = 0; k < 4; ++k)
                ASSERT_EQ(out[k], tea_hash(v0[k], v1[k], rounds))
                    << "rounds " << rounds << ", case " << i << ", lane " << k;
        }
}

TEST(IndependentSampler, DrawsEqualTheVirtualCallsAndClonesOwnTheirStream) {
    // draw_1d()/draw_2d() take the sampler's PCG32 directly: the values must be next_1d()'s and
    // next_2d()'s, and a clone must draw from its own generator, not the original's.
    auto proto = independent(16, 3);
    std::unique_ptr<Sampler> a = proto->clone(), b = proto->clone();
    a->seed(12345);
    b->seed(12345);
    for (uint32_t s = 0; s < 16; ++s) {
        a->set_sample_index(s);
        b->set_sample_index(s);
        for (int i = 0; i < 5; ++i) {
            ASSERT_EQ(a->draw_1d(), b->next_1d());
            Point2f pa = a->draw_2d(), pb = b->next_2d();
            ASSERT_EQ(pa.x, pb.x);
            ASSERT_EQ(pa.y, pb.y);
        }
    }
    // Drawing from a clone leaves the prototype's stream where it was.
    proto->seed(7);
    std::unique_ptr<Sampler> c = proto->clone();
    float first = c->draw_1d();
    for (int i = 0; i < 10; ++i) c->draw_2d();
    EXPECT_EQ(proto->draw_1d(), first);
}
