#pragma once

#include <facet/logger.h>
#include <facet/object.h>
#include <facet/properties.h>

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

/// Separable pixel reconstruction filter: weight(x, y) = eval(x)·eval(y), zero beyond radius().
class ReconstructionFilter : public Object {
public:
    ObjectType type() const override { return ObjectType::ReconstructionFilter; }
    virtual float eval(float x) const = 0;
    float radius() const { return m_radius; }
    /// True for the `box` filter, whose weight the image blocks compute inline with box_eval()
    /// (no virtual call per pixel of a sample's footprint).
    bool is_box() const { return m_is_box; }
    /// The box filter's weight: half-open [-0.5, 0.5), so a sample on a pixel boundary belongs
    /// to exactly one pixel.
    static float box_eval(float x) { return (x >= -0.5f && x < 0.5f) ? 1.f : 0.f; }

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
    bool m_is_box = false; ///< set by the box filter only (its eval() must be box_eval())
};

} // namespace facet
