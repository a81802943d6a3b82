#pragma once

#include <facet/logger.h>
#include <facet/object.h>
#include <facet/properties.h>

#include <atomic>
#include <cmath>

namespace facet {

/// Largest filter radius in pixels. Every image block keeps a border of the radius around its
/// pixels, so a radius of millions of pixels would allocate terabytes (and overflow the pixel
/// arithmetic); 64 is far above useful filters (it is the widest lanczos).
constexpr float MaxFilterRadius = 64.f;
/// Smallest filter radius in pixels: a narrower filter gives almost every sample the weight 0,
/// so the image comes out black.
constexpr float MinFilterRadius = 1.f / 64.f;
/// Largest magnitude of a filter weight (eval()). A sample's weight is the product of two, and
/// the film sums them over every sample of a pixel: huge weights overflow to infinity and NaN.
constexpr float MaxFilterWeight = 1000.f;

class TabulatedFilter;

/// Separable pixel reconstruction filter: weight(x, y) = w(x)·w(y), zero beyond radius().
///
/// A filter only describes its weight: eval(x) at the offset x (in pixels) from a pixel centre,
/// the same at -x and x (eval(-radius) and eval(radius) may differ, for a filter whose support
/// is half-open). The image blocks never call eval() per sample: libfacet tabulates it once
/// (weight()) and applies the table to every filter alike.
class ReconstructionFilter : public Object {
public:
    ReconstructionFilter() = default;
    ~ReconstructionFilter() override;
    ObjectType type() const override { return ObjectType::ReconstructionFilter; }
    virtual float eval(float x) const = 0;
    float radius() const { return m_radius; }
    /// The weight the image blocks apply at offset x: eval() taken once at |x| = radius·i/31
    /// for i = 0..30, each value kept over [radius·i/31, radius·(i+1)/31) (as Mitsuba 3's
    /// scalar image block applies every filter), eval() itself at exactly -radius and radius
    /// (so a sample on a pixel edge counts for one pixel only when the support is half-open),
    /// and 0 beyond. Built on the first call, after the constructor.
    float weight(float x) const;

protected:
    /// Throws, at the filter's place in the scene, unless eval() is finite and within
    /// ±MaxFilterWeight on [-radius, radius] and integrates to a positive number there (the
    /// film divides by the sum of the weights). Sampled on a fine grid; every filter calls it
    /// at the end of its constructor, so parameters that slip through its own checks fail here.
    void check_weights(const Properties &props) const {
        constexpr int n = 4096;
        double integral = 0.0;
        for (int i = -n; i <= n; ++i) {
            const float x = m_radius * float(i) / float(n), w = eval(x);
            if (!std::isfinite(w) || std::abs(w) > MaxFilterWeight)
                FACET_THROW_AT(props.location(),
                               "{}: the weight at {} pixels is {}: the parameters must keep every "
                               "weight finite and within +-{}",
                               to_string(), x, w, MaxFilterWeight);
            integral += double(w);
        }
        if (!(integral > 0.0))
            FACET_THROW_AT(props.location(),
                           "{}: the weights sum to {} over the radius: the parameters must keep "
                           "the sum positive (the film divides by it)",
                           to_string(), integral * double(m_radius) / n);
    }

    float m_radius = 0.5f;

private:
    friend class ImageBlock;
    /// weight()'s table, built by the first caller (any thread).
    const TabulatedFilter &table() const;
    mutable std::atomic<const TabulatedFilter *> m_table{nullptr};
};

} // namespace facet
