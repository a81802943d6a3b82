#pragma once

#include <facet/object.h>
#include <facet/properties.h>
#include <facet/vector.h>

#include <memory>

namespace facet {

/// Source of sample values. The render loop clones one sampler per block, calls seed() once per
/// pixel with a value derived from (scene seed, pixel index) and advance() between the samples
/// of that pixel, so images do not depend on the thread count.
class Sampler : public Object {
public:
    /// Reads `sample_count` (default 4) and `seed` (default 0).
    explicit Sampler(const Properties &props);
    ObjectType type() const override { return ObjectType::Sampler; }

    virtual std::unique_ptr<Sampler> clone() const = 0;
    /// Starts a new pixel (sample index 0).
    virtual void seed(uint64_t seed_value) = 0;
    /// Moves to the next sample of the current pixel.
    virtual void advance() {
        ++m_sample_index;
        m_dimension = 0;
    }
    virtual float next_1d() = 0;
    virtual Point2f next_2d() = 0;

    uint32_t sample_count() const { return m_sample_count; }
    void set_sample_count(uint32_t spp) { m_sample_count = spp; }
    uint64_t base_seed() const { return m_base_seed; }
    void set_base_seed(uint64_t seed) { m_base_seed = seed; }

protected:
    Sampler(const Sampler &) = default;
    uint32_t m_sample_count = 4;
    uint64_t m_base_seed = 0;
    uint32_t m_sample_index = 0;
    uint32_t m_dimension = 0;
};

} // namespace facet
