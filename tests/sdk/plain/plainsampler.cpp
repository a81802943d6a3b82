static const char *DOC = R"DOC(
# plainsampler: the independent sampler's values through the Sampler interface alone

The values of facet's `independent` sampler (one PCG32 stream per sample, seeded from a hash of
the pixel seed, the sample index and `seed`), written only against the Sampler interface: it
does not expose its generator (m_stream stays null), so every value is asked through next_1d()
and next_2d(). Built out of tree by facet's SDK test.

| Parameter | Type | Default | Description |
|-----------|------|---------|-------------|
| sample_count | integer | 4 | Samples per pixel |
| seed | integer | 0 | Base seed |
)DOC";

#include <facet/plugin.h>
#include <facet/random.h>
#include <facet/sampler.h>

#include <fmt/format.h>

namespace facet {

class PlainSampler final : public Sampler {
public:
    explicit PlainSampler(const Properties &props) : Sampler(props) {}

    std::unique_ptr<Sampler> clone() const override {
        return std::unique_ptr<Sampler>(new PlainSampler(*this));
    }

    void seed(uint64_t seed_value) override {
        m_pixel_seed = seed_value;
        set_sample_index(0);
    }

    void set_sample_index(uint32_t index) override {
        Sampler::set_sample_index(index);
        const uint64_t v = m_pixel_seed ^ (uint64_t(index) * 0x9e3779b97f4a7c15ull) ^
                           (m_base_seed * 0xd1b54a32d192ed03ull);
        m_rng.seed(mix64(v), mix64(v ^ 0x6a09e667f3bcc908ull));
    }

    float next_1d() override { return m_rng.next_float(); }

    Point2f next_2d() override {
        const float x = m_rng.next_float();
        const float y = m_rng.next_float();
        return {x, y};
    }

    std::string to_string() const override {
        return fmt::format("PlainSampler[sample_count={}]", m_sample_count);
    }

private:
    PlainSampler(const PlainSampler &) = default;
    PCG32 m_rng;
    uint64_t m_pixel_seed = 0;
};

} // namespace facet

FACET_EXPORT_PLUGIN(facet::PlainSampler, Sampler, "plainsampler",
                    "Independent samples through next_1d/next_2d (SDK test)", DOC)
