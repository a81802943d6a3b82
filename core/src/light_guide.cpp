#include "light_guide.h"

#include <algorithm>
#include <cmath>

namespace facet::detail {

LightGuide::LightGuide(const BoundingBox3f &bounds) {
    const Vector3f extent = bounds.valid() ? bounds.max - bounds.min : Vector3f(0.f);
    const float longest = std::max({extent.x, extent.y, extent.z});
    // Cubic cells, MaxCells along the longest axis; a flat axis gets one.
    const float size = longest > 0.f && std::isfinite(longest) ? longest / float(MaxCells) : 1.f;
    m_origin = bounds.valid() ? bounds.min : Point3f(0.f);
    Level finest;
    for (int a = 0; a < 3; ++a) {
        // Clamped as a float: a huge or non-finite extent never reaches the conversion.
        const float cells = std::ceil(extent[a] / size);
        finest.dims[a] = cells >= 1.f ? int(std::min(cells, float(MaxCells))) : 1;
        m_inv_cell[a] = 1.f / size;
    }
    m_levels.push_back(finest);
    while (m_levels.back().dims[0] > 1 || m_levels.back().dims[1] > 1 ||
           m_levels.back().dims[2] > 1) {
        Level next;
        for (int a = 0; a < 3; ++a) next.dims[a] = (m_levels.back().dims[a] + 1) / 2;
        m_levels.push_back(next);
    }
    for (Level &level : m_levels) {
        const size_t cells = size_t(level.dims[0]) * size_t(level.dims[1]) * size_t(level.dims[2]);
        level.records.assign(cells, 0);
        level.useful.assign(cells, 0);
    }
    m_probability.assign(m_levels[0].records.size(), 1.f);
}

void LightGuide::coordinates(const Point3f &p, int (&c)[3]) const {
    for (int a = 0; a < 3; ++a) {
        const float x = (p[a] - m_origin[a]) * m_inv_cell[a];
        const float last = float(m_levels[0].dims[a] - 1);
        c[a] = x >= 0.f ? int(std::min(x, last)) : 0; // NaN compares false: cell 0
    }
}

size_t LightGuide::index(const Level &level, const int (&c)[3], int shift) const {
    return (size_t(c[2] >> shift) * size_t(level.dims[1]) + size_t(c[1] >> shift)) *
               size_t(level.dims[0]) +
           size_t(c[0] >> shift);
}

void LightGuide::record(const Point3f &p, bool useful) {
    int c[3];
    coordinates(p, c);
    for (size_t l = 0; l < m_levels.size(); ++l) {
        Level &level = m_levels[l];
        const size_t i = index(level, c, int(l));
        ++level.records[i];
        if (useful) ++level.useful[i];
    }
}

size_t LightGuide::finish() {
    const Level &finest = m_levels[0];
    size_t changed = 0;
    int c[3];
    for (c[2] = 0; c[2] < finest.dims[2]; ++c[2])
        for (c[1] = 0; c[1] < finest.dims[1]; ++c[1])
            for (c[0] = 0; c[0] < finest.dims[0]; ++c[0]) {
                float q = 1.f;
                // The finest level with enough records decides; none: every sample is taken.
                for (size_t l = 0; l < m_levels.size(); ++l) {
                    const size_t i = index(m_levels[l], c, int(l));
                    const uint32_t n = m_levels[l].records[i];
                    if (n < MinRecords) continue;
                    const float rate = float(m_levels[l].useful[i]) / float(n);
                    q = std::clamp(rate / FullRate, MinProbability, 1.f);
                    break;
                }
                m_probability[index(finest, c, 0)] = q;
                if (q < 1.f) ++changed;
            }
    // The counts are not needed any more.
    for (Level &level : m_levels) {
        level.records = {};
        level.useful = {};
    }
    return changed;
}

} // namespace facet::detail
