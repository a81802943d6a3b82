static const char *DOC = R"DOC(
# stratified: jittered stratified sampler

Each dimension of a pixel's samples is split into `sample_count` strata (for 2D requests a
√N × √N grid, so `sample_count` is rounded up to a square); the strata are visited in an
independent random order per pixel and per dimension, and each sample is jittered inside its
stratum. Deterministic for a given `seed`.

| Parameter    | Type    | Default | Description                                             |
|--------------|---------|---------|---------------------------------------------------------|
| sample_count | integer | 4       | Samples per pixel; rounded up to the next square number (at most 65535²) |
| seed         | integer | 0       | Seed offset of the random permutations and jitter       |
| jitter       | boolean | true    | Jitter inside each stratum (false: stratum centres)     |

```xml
<sampler type="stratified">
    <integer name="sample_count" value="64"/>
</sampler>
```
)DOC";

#include <facet/plugin.h>
#include <facet/qmc.h>
#include <facet/sampler.h>

#include <cmath>

namespace facet {

class StratifiedSampler final : public Sampler {
public:
    explicit StratifiedSampler(const Properties &props)
        : Sampler(props), m_location(props.location()) {
        m_jitter = props.get_bool("jitter", true);
        if (m_sample_count > MaxCount)
            FACET_THROW_AT(props.location("sample_count"),
                           "stratified: sample_count must be at most 65535^2 = {} (it is rounded "
                           "up to a square), got {}",
                           MaxCount, m_sample_count);
        update_resolution();
    }

    std::unique_ptr<Sampler> clone() const override {
        return std::make_unique<StratifiedSampler>(*this);
    }

    uint32_t set_sample_count(uint32_t spp) override {
        m_sample_count = spp;
        update_resolution();
        return m_sample_count;
    }

    void seed(uint64_t seed_value) override {
        m_pixel_seed = qmc::hash_combine(qmc::hash64(seed_value), uint32_t(m_base_seed));
        m_sample_index = 0;
        m_dimension = 0;
    }

    float next_1d() override {
        uint32_t dim_seed = qmc::hash_combine(m_pixel_seed, m_dimension++);
        uint32_t stratum = qmc::permute(m_sample_index % m_sample_count, m_sample_count, dim_seed);
        float j = jitter(dim_seed, 0);
        return std::min((float(stratum) + j) / float(m_sample_count), OneMinusEpsilon);
    }

    Point2f next_2d() override {
        uint32_t dim_seed = qmc::hash_combine(m_pixel_seed, m_dimension++);
        uint32_t stratum = qmc::permute(m_sample_index % m_sample_count, m_sample_count, dim_seed);
        uint32_t sx = stratum % m_resolution, sy = stratum / m_resolution;
        float inv = 1.f / float(m_resolution);
        return {std::min((float(sx) + jitter(dim_seed, 1)) * inv, OneMinusEpsilon),
                std::min((float(sy) + jitter(dim_seed, 2)) * inv, OneMinusEpsilon)};
    }

    std::string to_string() const override {
        return fmt::format("StratifiedSampler[sample_count={}, jitter={}]", m_sample_count,
                           m_jitter);
    }

private:
    /// The largest square of a uint32_t: a larger count would round up to 65536^2 = 2^32.
    static constexpr uint32_t MaxCount = 65535u * 65535u;

    void update_resolution() {
        if (m_sample_count > MaxCount)
            FACET_THROW_AT(m_location,
                           "stratified: the sample count must be at most 65535^2 = {} (it is "
                           "rounded up to a square), got {}",
                           MaxCount, m_sample_count);
        m_resolution = uint32_t(std::ceil(std::sqrt(double(m_sample_count)) - 1e-9));
        m_sample_count = m_resolution * m_resolution;
    }

    float jitter(uint32_t dim_seed, uint32_t axis) const {
        if (!m_jitter) return 0.5f;
        return qmc::to_unit_float(
            qmc::hash_combine(qmc::hash_combine(dim_seed, m_sample_index), axis + 1));
    }

    Location m_location; ///< where the sampler is declared, for errors at render setup
    bool m_jitter = true;
    uint32_t m_resolution = 2;
    uint32_t m_pixel_seed = 0;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::StratifiedSampler, Sampler, "stratified",
                          "Jittered stratified sampler with per-pixel random stratum order", DOC,
                          ::facet::AllModes)
