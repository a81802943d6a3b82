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

protected:
    float m_radius = 0.5f;
};

} // namespace facet
