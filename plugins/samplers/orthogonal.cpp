static const char *DOC = R"DOC(
# orthogonal: orthogonal array sampler

Orthogonal-array sampling (Jarosz et al. 2019, "Orthogonal Array Sampling for Monte Carlo
Rendering"), as in Mitsuba 3. With the default strength 2 the samples of a pixel come from
Bose's orthogonal array OA(p², p + 1, p, 2) for a prime p: any two dimensions of the p² samples
are stratified on a p × p grid (like correlated multi-jittered sampling) and every dimension on
its own in p² strata. The array's rows are visited in a random order per pixel and the strata
are shuffled per dimension, so each sample is uniformly distributed; beyond p + 1 dimensions the
columns repeat (still uniform, only less stratified). Strengths other than 2 use Bush's
construction over p^strength rows (its p-dimensional strata hold in every `strength`
dimensions). As the sub-strata of one dimension follow another column of the array, the error
on smooth 2D integrands falls about like N^-0.8 (correlated multi-jittering's rate), against
N^-0.5 for independent samples.

The sample count must be the square of a prime; another count is rounded up to the next one
with a warning (as Mitsuba does: 16 becomes 25, 64 becomes 121). Deterministic for a given `seed`.

| Parameter    | Type    | Default | Description                                            |
|--------------|---------|---------|--------------------------------------------------------|
| sample_count | integer | 4       | Samples per pixel (rounded up to the square of a prime) |
| seed         | integer | 0       | Seed offset of the permutations and jitter             |
| strength     | integer | 2       | Strength of the orthogonal array (2 to 8)              |
| jitter       | boolean | true    | Jitter inside the sub-strata (false: their centres)    |

```xml
<sampler type="orthogonal">
    <integer name="sample_count" value="49"/>
</sampler>
```
)DOC";

#include <facet/logger.h>
#include <facet/plugin.h>
#include <facet/qmc.h>
#include <facet/sampler.h>

#include <algorithm>

namespace facet {

class OrthogonalSampler final : public Sampler {
public:
    explicit OrthogonalSampler(const Properties &props)
        : Sampler(props), m_location(props.location()) {
        m_jitter = props.get_bool("jitter", true);
        int64_t strength = props.get_int("strength", 2);
        if (strength < 2 || strength > 8)
            FACET_THROW_AT(props.location("strength"),
                           "orthogonal: strength must be between 2 and 8, got {}", strength);
        m_strength = uint32_t(strength);
        update_resolution();
        const uint32_t rounded = m_resolution * m_resolution;
        if (rounded != m_sample_count) {
            FACET_LOG(Warn,
                      "orthogonal: the sample count should be the square of a prime number; "
                      "rounding {} up to {}",
                      m_sample_count, rounded);
            m_sample_count = rounded;
        }
    }

    std::unique_ptr<Sampler> clone() const override {
        return std::unique_ptr<Sampler>(new OrthogonalSampler(*this));
    }

    /// Rounds as the constructor does (without the warning): to the square of a prime.
    uint32_t set_sample_count(uint32_t spp) override {
        m_sample_count = spp;
        update_resolution();
        m_sample_count = m_resolution * m_resolution;
        return m_sample_count;
    }

    void seed(uint64_t seed_value) override {
        m_pixel_seed = qmc::hash_combine(qmc::hash64(seed_value), uint32_t(m_base_seed));
        m_sample_index = 0;
        m_dimension = 0;
    }

    float next_1d() override {
        const uint32_t j = m_dimension++;
        float v = m_strength == 2 ? bose(m_sample_index, j) : bush(m_sample_index, j);
        return std::min(v, OneMinusEpsilon);
    }

    Point2f next_2d() override {
        float x = next_1d();
        float y = next_1d();
        return {x, y};
    }

    std::string to_string() const override {
        return fmt::format("OrthogonalSampler[sample_count={}, prime={}, strength={}, jitter={}]",
                           m_sample_count, m_resolution, m_strength, m_jitter);
    }

private:
    OrthogonalSampler(const OrthogonalSampler &) = default;

    static bool is_prime(uint32_t x) {
        if (x < 2) return false;
        for (uint32_t d = 2; d * d <= x; ++d)
            if (x % d == 0) return false;
        return true;
    }

    /// The smallest prime p with p² >= sample_count; N = p^strength rows for Bush's array.
    void update_resolution() {
        uint32_t p = 2;
        while (uint64_t(p) * p < m_sample_count || !is_prime(p)) ++p;
        m_resolution = p;
        uint64_t rows = 1;
        for (uint32_t k = 0; k < m_strength; ++k) rows *= p;
        if (rows > UINT32_MAX)
            // Also when the render sets a larger count: at the sampler's place in the scene.
            FACET_THROW_AT(m_location,
                           "orthogonal: {}^{} array rows do not fit 32 bits (lower the strength or "
                           "the sample count, {} here)",
                           p, m_strength, m_sample_count);
        m_rows = uint32_t(rows);
    }

    float jitter(uint32_t i, uint32_t j) const {
        if (!m_jitter) return 0.5f;
        return qmc::to_unit_float(qmc::hash_combine(qmc::hash_combine(m_pixel_seed, i), j));
    }

    /// Bose's construction (strength 2): row r = (a0, a1) of the p × p grid; column 0 is a0,
    /// column 1 is a1 and column j >= 2 is a0 + (j - 1)·a1 (mod p). A second column of the
    /// array orders the sub-strata, which stratifies each dimension in p² intervals.
    float bose(uint32_t i, uint32_t j) const {
        const uint32_t p = m_resolution, n = p * p;
        const uint32_t r = qmc::permute(i % n, n, m_pixel_seed);
        const uint32_t a0 = r / p, a1 = r % p;
        uint32_t aj, ak;
        if (j == 0) {
            aj = a0;
            ak = a1;
        } else if (j == 1) {
            aj = a1;
            ak = a0;
        } else {
            const uint32_t k = (j % 2) ? j - 1 : j + 1;
            aj = uint32_t((a0 + uint64_t(j - 1) * a1) % p);
            ak = uint32_t((a0 + uint64_t(k - 1) * a1) % p);
        }
        const uint32_t seed_j = m_pixel_seed * (j + 1);
        const uint32_t stratum = qmc::permute(aj, p, seed_j * 0x51633e2dU);
        const uint32_t sub = qmc::permute(ak, p, seed_j * 0x68bc21ebU);
        return (float(stratum) + (float(sub) + jitter(i, j)) / float(p)) / float(p);
    }

    /// Bush's construction (any strength t): the base-p digits of the row are the coefficients
    /// of a polynomial of degree < t, evaluated at j (mod p).
    float bush(uint32_t i, uint32_t j) const {
        const uint32_t p = m_resolution, n = m_rows, stm = n / p;
        const uint32_t r = qmc::permute(i % n, n, m_pixel_seed);
        uint64_t phi = 0;
        {
            // Horner's rule on the digits, most significant first.
            uint32_t digits[8], rest = r;
            for (uint32_t k = 0; k < m_strength; ++k, rest /= p) digits[k] = rest % p;
            for (uint32_t k = m_strength; k-- > 0;) phi = (phi * (j % p) + digits[k]) % p;
        }
        const uint32_t seed_j = m_pixel_seed * (j + 1);
        const uint32_t stratum = qmc::permute(uint32_t(phi), p, seed_j * 0x51633e2dU);
        const uint32_t sub = qmc::permute((r / p) % stm, stm, seed_j * 0x68bc21ebU);
        return (float(stratum) + (float(sub) + jitter(i, j)) / float(stm)) / float(p);
    }

    Location m_location; ///< where the sampler is declared
    bool m_jitter = true;
    uint32_t m_strength = 2, m_resolution = 2, m_rows = 4;
    uint32_t m_pixel_seed = 0;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::OrthogonalSampler, Sampler, "orthogonal",
                          "Orthogonal array sampler (Bose/Bush constructions, Jarosz et al. 2019)",
                          DOC, ::facet::AllModes)
