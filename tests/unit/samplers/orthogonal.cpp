// The orthogonal array sampler: sample-count rounding to a prime square, the strength-2
// stratification of every pair of dimensions and of each dimension alone, determinism per seed,
// unbiasedness beyond the array's columns and in Bush's construction, and convergence on a
// smooth integral (faster than the Monte Carlo rate).
#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/sampler.h>

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

using namespace facet;

namespace {

std::unique_ptr<Sampler> make_sampler(const std::string &type, int spp, Properties props = {}) {
    props.set_plugin_name(type);
    props.set_int("sample_count", spp);
    return PluginRegistry::instance().create_as<Sampler>(ObjectType::Sampler, props)->clone();
}

/// The N samples of one pixel, `dims` values each.
std::vector<std::vector<float>> pixel_samples(Sampler &s, uint64_t seed, int dims) {
    s.seed(seed);
    std::vector<std::vector<float>> out;
    for (uint32_t i = 0; i < s.sample_count(); ++i) {
        if (i > 0) s.advance();
        std::vector<float> v;
        for (int d = 0; d < dims; ++d) v.push_back(s.next_1d());
        out.push_back(v);
    }
    return out;
}

/// Smooth integrand on [0,1]²: x·e^x · (1 + cos(2πy)/2) with integral 1.
double f2(float x, float y) { return x * std::exp(x) * (1.0 + 0.5 * std::cos(2.0 * M_PI * y)); }

/// RMS error over `pixels` pixels of the estimate from dimensions (2·dim, 2·dim + 1).
double rms_error(const std::string &type, int spp, int pixels, int dim) {
    auto s = make_sampler(type, spp);
    const int n = int(s->sample_count());
    double sum_sq = 0.0;
    for (int px = 0; px < pixels; ++px) {
        s->seed(uint64_t(px) * 7919u + 13u);
        double est = 0.0;
        for (int i = 0; i < n; ++i) {
            if (i > 0) s->advance();
            for (int d = 0; d < dim; ++d) s->next_2d();
            Point2f p = s->next_2d();
            est += f2(p.x, p.y);
        }
        est /= n;
        sum_sq += (est - 1.0) * (est - 1.0);
    }
    return std::sqrt(sum_sq / pixels);
}

double convergence_slope(const std::string &type, const std::vector<int> &counts, int dim) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int n : counts) {
        const double x = std::log(double(n)), y = std::log(rms_error(type, n, 256, dim));
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
    }
    const double k = double(counts.size());
    return (k * sxy - sx * sy) / (k * sxx - sx * sx);
}

} // namespace

TEST(Orthogonal, SampleCountIsRoundedUpToAPrimeSquare) {
    for (auto [asked, got] : {std::pair{4, 4}, std::pair{49, 49}, std::pair{16, 25},
                              std::pair{64, 121}, std::pair{1, 4}, std::pair{488, 529}}) {
        const size_t warnings = Logger::warning_count();
        EXPECT_EQ(make_sampler("orthogonal", asked)->sample_count(), uint32_t(got)) << asked;
        EXPECT_EQ(Logger::warning_count(), warnings + (asked == got ? 0 : 1)) << asked;
    }
    Properties bad;
    bad.set_int("strength", 1);
    EXPECT_THROW(make_sampler("orthogonal", 4, bad), Error);
}

TEST(Orthogonal, EveryPairOfDimensionsIsStratifiedOnThePrimeGrid) {
    // OA(p², p + 1, p, 2): the first p + 1 dimensions, taken two at a time, put exactly one of
    // the p² samples in each cell of the p × p grid; each dimension alone has one sample in
    // each of p² intervals.
    for (int p : {2, 5, 7}) {
        auto s = make_sampler("orthogonal", p * p);
        for (uint64_t seed : {1u, 99u}) {
            auto samples = pixel_samples(*s, seed, p + 1);
            for (int j = 0; j <= p; ++j) {
                std::set<int> fine;
                for (auto &v : samples) fine.insert(int(v[size_t(j)] * float(p * p)));
                EXPECT_EQ(fine.size(), size_t(p * p)) << "p " << p << " dimension " << j;
                for (int k = j + 1; k <= p; ++k) {
                    std::set<int> cells;
                    for (auto &v : samples)
                        cells.insert(int(v[size_t(j)] * float(p)) * p +
                                     int(v[size_t(k)] * float(p)));
                    EXPECT_EQ(cells.size(), size_t(p * p)) << "p " << p << " dims " << j << k;
                }
            }
        }
    }
}

TEST(Orthogonal, DeterministicPerSeedInTheUnitIntervalAndShuffledPerPixel) {
    Properties seeded;
    seeded.set_int("seed", 5);
    auto a = make_sampler("orthogonal", 25), b = make_sampler("orthogonal", 25);
    auto c = make_sampler("orthogonal", 25, seeded);
    auto sa = pixel_samples(*a, 42, 12), sb = pixel_samples(*b, 42, 12);
    auto other_pixel = pixel_samples(*a, 43, 12), other_seed = pixel_samples(*c, 42, 12);
    EXPECT_EQ(sa, sb);
    EXPECT_NE(sa, other_pixel);
    EXPECT_NE(sa, other_seed);
    for (auto &v : sa)
        for (float x : v) {
            EXPECT_GE(x, 0.f);
            EXPECT_LT(x, 1.f);
        }
    // Without jitter the values sit at sub-stratum centres.
    Properties nj;
    nj.set_bool("jitter", false);
    auto d = make_sampler("orthogonal", 25, nj);
    for (auto &v : pixel_samples(*d, 3, 4))
        for (float x : v) EXPECT_NEAR(std::fmod(x * 25.f, 1.f), 0.5f, 1e-4f);
}

TEST(Orthogonal, UnbiasedBeyondTheColumnsAndWithBush) {
    // With 4 samples (p = 2) only 3 columns exist; later dimensions repeat columns but every
    // sample stays uniform, so E[x·y] over dimensions (0, 3) and (4, 9) is 1/4. Bush's
    // construction (strength 3) too.
    Properties bush;
    bush.set_int("strength", 3);
    for (auto props : {Properties(), bush}) {
        auto s = make_sampler("orthogonal", 4, props);
        const int pixels = 40000;
        double s03 = 0.0, s49 = 0.0;
        for (int px = 0; px < pixels; ++px) {
            for (auto &v : pixel_samples(*s, uint64_t(px), 10)) {
                s03 += double(v[0]) * v[3];
                s49 += double(v[4]) * v[9];
            }
        }
        const double n = 4.0 * pixels, sd = std::sqrt(7.0 / 144.0 / n); // Var(xy) = 7/144
        EXPECT_NEAR(s03 / n, 0.25, 5.0 * sd * 2.0);                     // samples correlate
        EXPECT_NEAR(s49 / n, 0.25, 5.0 * sd * 2.0);
    }
}

TEST(Orthogonal, ConvergesFasterThanIndependent) {
    // The sub-stratum of one dimension is set by another column of the array, as in correlated
    // multi-jittering, which converges at about N^-0.8 on this integrand (independent: N^-0.5).
    const std::vector<int> counts = {25, 121, 529, 961};
    EXPECT_LT(convergence_slope("orthogonal", counts, 0), -0.7);
    EXPECT_LT(convergence_slope("orthogonal", counts, 2), -0.7);
    // Never worse than independent sampling at the same count.
    for (int n : {25, 121})
        EXPECT_LT(rms_error("orthogonal", n, 256, 1), rms_error("independent", n, 256, 1)) << n;
}
