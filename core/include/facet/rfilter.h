#pragma once

#include <facet/object.h>

namespace facet {

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
