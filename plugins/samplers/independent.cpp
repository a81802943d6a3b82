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
        // TEA hashes decorrelate neighbouring values, the second one picks the stream. Samples
        // are mostly taken in order: the hashes of the next index run in the same register's
        // other two lanes (free) and are kept for the next call.
        if (!(index == m_next.index && m_pixel_seed == m_next.pixel_seed &&
              m_base_seed == m_next.base_seed && m_next.valid)) {
            const uint64_t v = weyl(index), w = weyl(index + 1);
            const uint32_t base_lo = uint32_t(m_base_seed), base_hi = uint32_t(m_base_seed >> 32);
            const uint32_t v0[4] = {uint32_t(v) ^ base_hi, uint32_t(v >> 32), uint32_t(w) ^ base_hi,
                                    uint32_t(w >> 32)};
            const uint32_t v1[4] = {base_lo, base_lo ^ 0x6a09e667u, base_lo, base_lo ^ 0x6a09e667u};
            uint64_t h[4];
            tea_hash4(v0, v1, h, 8);
            m_rng.seed(h[0], h[1] ^ v);
            m_next = {h[2], h[3] ^ w, m_pixel_seed, m_base_seed, index + 1, true};
        } else {
            m_rng.seed(m_next.state, m_next.seq);
        }
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
        : Sampler(other), m_rng(other.m_rng), m_pixel_seed(other.m_pixel_seed),
          m_next(other.m_next) {
        m_stream = other.m_stream ? &m_rng : nullptr; // not the original's generator
    }
    Independent &operator=(const Independent &) = delete;
    uint64_t weyl(uint32_t index) const {
        return m_pixel_seed ^ (uint64_t(index) * 0x9e3779b97f4a7c15ull);
    }
    PCG32 m_rng;
    uint64_t m_pixel_seed = 0;
    /// The seed of sample `index` (PCG32::seed's arguments), hashed with the previous one, for
    /// the pixel and base seeds it was hashed from.
    struct {
        uint64_t state = 0, seq = 0, pixel_seed = 0, base_seed = 0;
        uint32_t index = 0;
        bool valid = false;
    } m_next;
};

} // namespace facet

FACET_EXPORT_PLUGIN(facet::Independent, Sampler, "independent",
                    "Independent uniform random samples (PCG32)", DOC)
