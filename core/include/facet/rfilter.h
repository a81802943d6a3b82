#pragma once

#include <facet/object.h>

namespace facet {

/// Largest filter radius in pixels. Every image block keeps a border of the radius around its
/// pixels, so a radius of millions of pixels would allocate terabytes (and overflow the pixel
/// arithmetic); 64 is far above useful filters (it is the widest lanczos).
constexpr float MaxFilterRadius = 64.f;

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
    float m_radius = 0.5f;
    bool m_is_box = false; ///< set by the box filter only (its eval() must be box_eval())
};

} // namespace facet
