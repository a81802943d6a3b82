#pragma once

#include <cmath>

namespace facet {

/// A reconstruction filter as Mitsuba 3's scalar image block applies it: not evaluated per
/// sample but looked up in a table of `Resolution` values taken at x = radius·i/Resolution,
/// piecewise constant (each interval keeps the value at its left end; from the radius on the
/// weight is 0). For filters with negative lobes and a wide radius (lanczos) this differs
/// visibly from the exact function at sharp edges, so the filters that must match Mitsuba's
/// images evaluate through it.
class FilterTable {
public:
    static constexpr int Resolution = 31;

    /// Tabulates `f` (|x| -> weight) over [0, radius).
    template <typename F> void init(float radius, F &&f) {
        m_scale = float(Resolution) / radius;
        for (int i = 0; i < Resolution; ++i) m_values[i] = f((radius * float(i)) / Resolution);
        m_values[Resolution] = 0.f;
    }

    float lookup(float x) const {
        const float s = std::abs(x) * m_scale;
        // NaN fails the comparison too and gets the zero entry.
        const int i = s < float(Resolution) ? int(s) : Resolution;
        return m_values[i];
    }

private:
    float m_values[Resolution + 1] = {};
    float m_scale = 1.f;
};

} // namespace facet
