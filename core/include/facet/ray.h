#pragma once

#include <facet/color.h>
#include <facet/vector.h>

namespace facet {

/// Ray segment o + t·d for t in [mint, maxt].
struct Ray {
    Point3f o;
    Vector3f d;
    float mint = 0.f;
    float maxt = Infinity;
    float time = 0.f;
    /// The path's wavelengths in nm, one per channel, in the spectral modes (sampled with the
    /// camera ray, carried to every interaction and every ray spawned from one); zero and unused
    /// in rgb and mono.
    Wavelengths wavelengths;

    Ray() = default;
    Ray(const Point3f &o_, const Vector3f &d_, float mint_ = 0.f, float maxt_ = Infinity)
        : o(o_), d(d_), mint(mint_), maxt(maxt_) {}
    Point3f operator()(float t) const { return o + d * t; }
};

} // namespace facet
