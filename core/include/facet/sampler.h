#pragma once

#include <facet/object.h>
#include <facet/properties.h>
#include <facet/random.h>
#include <facet/vector.h>

#include <memory>

namespace facet {

/// Source of sample values. The render loop clones one sampler per thread, calls seed() once per
/// pixel with a value derived from (scene seed, pixel index), then set_sample_index() with the
/// index of each sample it takes (or advance() between consecutive ones). The values of sample
/// `i` of a pixel depend only on (pixel seed, i, sample_count), never on which samples were
/// taken before: a render may take any sub-range of a pixel's samples (passes, parts of a
/// distributed render) and the union is the same estimator, whatever the thread count.
class Sampler : public Object {
public:
    /// Reads `sample_count` (default 4) and `seed` (default 0).
    explicit Sampler(const Properties &props);
    ObjectType type() const override { return ObjectType::Sampler; }

    virtual std::unique_ptr<Sampler> clone() const = 0;
    /// Starts a new pixel (sample index 0).
    virtual void seed(uint64_t seed_value) = 0;
    /// Moves to sample `index` of the current pixel (dimension 0). Samplers with per-sample
    /// state (the independent sampler's random stream) override it and call this one.
    virtual void set_sample_index(uint32_t index) {
        m_sample_index = index;
        m_dimension = 0;
    }
    /// Moves to the next sample of the current pixel.
    void advance() { set_sample_index(m_sample_index + 1); }
    uint32_t sample_index() const { return m_sample_index; }
    virtual float next_1d() = 0;
    virtual Point2f next_2d() = 0;
    /// next_1d() and next_2d(), for the callers that draw many values (the render loop, the
    /// integrators). The contract: a sampler whose values are the successive floats of one PCG32
    /// generator per sample (random.h) may expose that generator by pointing m_stream at it;
    /// its next_1d() and next_2d() must then draw from it exactly as these do, and its values
    /// may not depend on the dimension (which these leave as it is). Any sampler may leave
    /// m_stream null: these then call next_1d() and next_2d(), and the values are the same.
    float draw_1d() {
        if (!m_stream) return next_1d();
        return m_stream->next_float();
    }
    Point2f draw_2d() {
        if (!m_stream) return next_2d();
        float x = m_stream->next_float();
        float y = m_stream->next_float();
        return {x, y};
    }

    /// Samples per pixel of the sampler's pattern.
    uint32_t sample_count() const { return m_sample_count; }
    /// Sets the samples per pixel of the pattern to `spp` or, for a sampler whose pattern needs
    /// a particular count (a square, a power of two), to the count it rounds `spp` to, and
    /// returns the count set. The render calls it once, on its own copy, before seeding; a
    /// sampler that cannot take `spp` samples throws.
    virtual uint32_t set_sample_count(uint32_t spp) {
        m_sample_count = spp;
        return m_sample_count;
    }
    uint64_t base_seed() const { return m_base_seed; }

protected:
    Sampler(const Sampler &) = default;
    uint32_t m_sample_count = 4;
    uint64_t m_base_seed = 0;
    uint32_t m_sample_index = 0;
    uint32_t m_dimension = 0;
    /// The sampler's own generator when its values are plain PCG32 draws (set by the sampler;
    /// a copy must point it at the copy's generator), else nullptr.
    PCG32 *m_stream = nullptr;
};

} // namespace facet
