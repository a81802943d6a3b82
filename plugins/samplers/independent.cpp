static const char *DOC = R"DOC(
# independent

Independent uniform random numbers from a PCG32 generator. Each sample of each pixel gets its
own stream, seeded from a hash of the sampler's `seed`, the pixel and the sample index, so images
do not depend on the order in which pixels are rendered, and samples [a, b) of a pixel are the
same whether they are taken in one render or in several passes or parts.

| Parameter | Type | Default | Description |
|---|---|---|---|
| sample_count | integer | 4 | Samples per pixel (must be > 0) |
| seed | integer | 0 | Base seed; different seeds give statistically independent images |

```xml
<sampler type="independent">
    <integer name="sample_count" value="64"/>
</sampler>
```
)DOC";

#include <facet/plugin.h>
#include <facet/random.h>
#include <facet/sampler.h>

namespace facet {

class Independent final : public Sampler {
public:
    explicit Independent(const Properties &props) : Sampler(props) { m_stream = &m_rng; }

    std::unique_ptr<Sampler> clone() const override {
        return std::unique_ptr<Sampler>(new Independent(*this));
    }

    void seed(uint64_t seed_value) override {
        m_pixel_seed = seed_value;
        // Sample 0's stream is hashed when it is first drawn from, not here: the render loop
        // moves to the sample it takes right after seeding, which hashes anyway. Until then the
        // draws go through next_1d() and next_2d(), which hash first.
        Sampler::set_sample_index(0);
        m_stream = nullptr;
    }

    void set_sample_index(uint32_t index) override {
        Sampler::set_sample_index(index);
        // The sample index moves the pixel seed along a Weyl sequence (sample 0 keeps it); two
        // 64-bit mixes of it with the sampler's seed, told apart by a constant, give PCG32 its
        // state and its stream, decorrelated from those of the neighbouring indices and pixels.
        // The seed is multiplied first: the render loop's pixel seeds hold its high word as
        // is, which a plain XOR would cancel.
        const uint64_t v = m_pixel_seed ^ (uint64_t(index) * 0x9e3779b97f4a7c15ull) ^
                           (m_base_seed * 0xd1b54a32d192ed03ull);
        m_rng.seed(mix64(v), mix64(v ^ 0x6a09e667f3bcc908ull));
        m_stream = &m_rng;
    }

    // Sampler::draw_1d() and draw_2d() draw from m_rng directly, as these do.
    float next_1d() override {
        if (!m_stream) set_sample_index(m_sample_index); // seeded, not yet hashed
        return m_rng.next_float();
    }

    Point2f next_2d() override {
        if (!m_stream) set_sample_index(m_sample_index);
        float x = m_rng.next_float();
        float y = m_rng.next_float();
        return {x, y};
    }

    std::string to_string() const override {
        return fmt::format("Independent[sample_count={}, seed={}]", m_sample_count, m_base_seed);
    }

private:
    Independent(const Independent &other)
        : Sampler(other), m_rng(other.m_rng), m_pixel_seed(other.m_pixel_seed) {
        m_stream = other.m_stream ? &m_rng : nullptr; // not the original's generator
    }
    Independent &operator=(const Independent &) = delete;
    PCG32 m_rng;
    uint64_t m_pixel_seed = 0;
};

} // namespace facet

FACET_EXPORT_PLUGIN_MODES(facet::Independent, Sampler, "independent",
                          "Independent uniform random samples (PCG32)", DOC, ::facet::AllModes)
