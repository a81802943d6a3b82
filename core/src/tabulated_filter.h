#pragma once

#include <facet/rfilter.h>

#include <cmath>

namespace facet {

/// A reconstruction filter as the image blocks apply it (ReconstructionFilter::weight()): not
/// evaluated per sample but looked up in a table of `Resolution` values taken at
/// |x| = radius·i/Resolution, piecewise constant (each interval keeps the value at its end
/// nearer to 0, as Mitsuba 3's scalar image block does), with eval() itself at exactly ±radius
/// and 0 beyond.
class TabulatedFilter {
public:
    static constexpr int Resolution = 31;

    explicit TabulatedFilter(const ReconstructionFilter &filter);

    float operator()(float x) const {
        const float s = std::abs(x) * m_scale;
        // NaN fails the comparison too, and then every test below: weight 0.
        if (s < float(Resolution)) return m_values[int(s)];
        return x == -m_radius ? m_at_minus_radius : x == m_radius ? m_at_radius : 0.f;
    }

    /// Non-zero when every sample counts for exactly the one pixel it lies in, with this
    /// weight along each axis: the weight is this constant on [-1/2, 1/2) and 0 elsewhere.
    float single_pixel_weight() const { return m_single_pixel_weight; }

private:
    float m_values[Resolution] = {};
    float m_scale = 1.f, m_radius = 0.f;
    float m_at_minus_radius = 0.f, m_at_radius = 0.f;
    float m_single_pixel_weight = 0.f;
};

} // namespace facet
