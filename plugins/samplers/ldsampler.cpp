static const char *DOC = R"DOC(
# ldsampler: low-discrepancy sampler

Each pair of dimensions draws from the base-2 (0,2)-sequence (van der Corput and Sobol's second
component), randomised per pixel and per dimension by an XOR scramble and a random permutation
of the sample index, so different dimensions are not correlated. 1D requests use the scrambled
van der Corput sequence. `sample_count` is rounded up to a power of two, where the sequence is
best stratified. Deterministic for a given `seed`.

| Parameter    | Type    | Default | Description                                         |
|--------------|---------|---------|-----------------------------------------------------|
| sample_count | integer | 4       | Samples per pixel; rounded up to a power of two (at most 2^31) |
| seed         | integer | 0       | Seed offset of the scrambles and permutations       |

```xml
<sampler type="ldsampler">
    <integer name="sample_count" value="64"/>
</sampler>
```
)DOC";

#include <facet/plugin.h>
#include <facet/qmc.h>
#include <facet/sampler.h>

namespace facet {

class LowDiscrepancySampler final : public Sampler {
public:
    explicit LowDiscrepancySampler(const Properties &props)
        : Sampler(props), m_location(props.location()) {
        if (m_sample_count > MaxCount)
            FACET_THROW_AT(props.location("sample_count"),
                           "ldsampler: sample_count must be at most 2^31 = {} (it is rounded up "
                           "to a power of two), got {}",
                           MaxCount, m_sample_count);
        round_count();
    }

    std::unique_ptr<Sampler> clone() const override {
        return std::make_unique<LowDiscrepancySampler>(*this);
    }

    uint32_t set_sample_count(uint32_t spp) override {
        m_sample_count = spp;
        round_count();
        return m_sample_count;
    }

    void seed(uint64_t seed_value) override {
        m_pixel_seed = qmc::hash_combine(qmc::hash64(seed_value), uint32_t(m_base_seed));
        m_sample_index = 0;
        m_dimension = 0;
    }

    float next_1d() override {
        uint32_t p = qmc::hash_combine(m_pixel_seed, m_dimension++);
        uint32_t i = qmc::permute(m_sample_index % m_sample_count, m_sample_count, p);
        return qmc::bits_to_float(qmc::van_der_corput_bits(i, qmc::hash32(p ^ 0x68bc21ebU)));
    }

    Point2f next_2d() override {
        uint32_t p = qmc::hash_combine(m_pixel_seed, m_dimension++);
        uint32_t i = qmc::permute(m_sample_index % m_sample_count, m_sample_count, p);
        return {qmc::bits_to_float(qmc::van_der_corput_bits(i, qmc::hash32(p ^ 0x02e5be93U))),
                qmc::bits_to_float(qmc::sobol2_bits(i, qmc::hash32(p ^ 0x967a889bU)))};
    }

    std::string to_string() const override {
        return fmt::format("LowDiscrepancySampler[sample_count={}]", m_sample_count);
    }

private:
    /// The largest power of two of a uint32_t: the rounding of any larger count would overflow.
    static constexpr uint32_t MaxCount = uint32_t(1) << 31;

    void round_count() {
        if (m_sample_count > MaxCount)
            FACET_THROW_AT(m_location,
                           "ldsampler: the sample count must be at most 2^31 = {} (it is rounded "
                           "up to a power of two), got {}",
                           MaxCount, m_sample_count);
        uint32_t n = 1;
        while (n < m_sample_count) n <<= 1;
        m_sample_count = n;
    }

    Location m_location; ///< where the sampler is declared, for errors at render setup
    uint32_t m_pixel_seed = 0;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::LowDiscrepancySampler, Sampler, "ldsampler",
                          "Scrambled (0,2)-sequence low-discrepancy sampler", DOC,
                          ::facet::AllModes)
