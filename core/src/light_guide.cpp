#include "light_guide.h"

#include <algorithm>
#include <cmath>

namespace facet::detail {

LightGuide::LightGuide(const BoundingBox3f &bounds, size_t emitters) {
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
    if (emitters > 1 && emitters <= MaxChoiceEmitters) {
        m_emitters = emitters;
        while (m_choice_level + 1 < m_levels.size() &&
               std::max({m_levels[m_choice_level].dims[0], m_levels[m_choice_level].dims[1],
                         m_levels[m_choice_level].dims[2]}) > ChoiceCells)
            ++m_choice_level;
    }
    for (size_t l = 0; l < m_levels.size(); ++l) {
        Level &level = m_levels[l];
        const size_t cells = size_t(level.dims[0]) * size_t(level.dims[1]) * size_t(level.dims[2]);
        level.records.assign(cells, 0);
        level.useful.assign(cells, 0);
        if (m_emitters > 0 && l >= m_choice_level)
            level.contribution.assign(cells * m_emitters, 0.0);
    }
    m_probability.assign(m_levels[0].records.size(), 1.f);
}

void LightGuide::record(const Point3f &p, bool useful, size_t emitter, float contribution) {
    int c[3];
    coordinates(p, c);
    const bool counts =
        useful && emitter < m_emitters && contribution > 0.f && std::isfinite(contribution);
    for (size_t l = 0; l < m_levels.size(); ++l) {
        Level &level = m_levels[l];
        const size_t i = index(level, c, int(l));
        ++level.records[i];
        if (useful) ++level.useful[i];
        if (counts && l >= m_choice_level)
            level.contribution[i * m_emitters + emitter] += double(contribution);
    }
}

size_t LightGuide::finish(const std::vector<float> &fixed, const OwnChoice &own) {
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
    if (m_emitters > 0) changed += finish_choice(fixed, own);
    // The counts are not needed any more.
    for (Level &level : m_levels) {
        level.records = {};
        level.useful = {};
        level.contribution = {};
    }
    return changed;
}

BoundingBox3f LightGuide::cell_box(size_t l, const int (&c)[3]) const {
    BoundingBox3f box;
    for (int a = 0; a < 3; ++a) {
        const float size = 1.f / m_inv_cell[a], margin = 1e-3f * size;
        box.min[a] = m_origin[a] + float(c[a] << l) * size - margin;
        box.max[a] = m_origin[a] + float((c[a] + 1) << l) * size + margin;
    }
    return box;
}

size_t LightGuide::finish_choice(const std::vector<float> &fixed, const OwnChoice &own) {
    const Level &base = m_levels[m_choice_level];
    const size_t E = m_emitters;
    // The probability the learned emitters share, and how many there are: fewer than two
    // leave nothing to choose.
    auto is_fixed = [&](size_t e) { return e < fixed.size() && fixed[e] >= 0.f; };
    double free_share = 1.0;
    size_t learned = 0;
    for (size_t e = 0; e < E; ++e) {
        if (is_fixed(e))
            free_share -= double(fixed[e]);
        else
            ++learned;
    }
    if (learned < 2 || !(free_share > 0.0)) return 0;
    m_choice_offset.assign(base.records.size(), -1);
    std::vector<float> learnt(E), own_choice(E);
    size_t chosen = 0;
    int c[3];
    for (c[2] = 0; c[2] < base.dims[2]; ++c[2])
        for (c[1] = 0; c[1] < base.dims[1]; ++c[1])
            for (c[0] = 0; c[0] < base.dims[0]; ++c[0]) {
                // Coordinates of the finest level, as index() shifts them.
                const int shift = int(m_choice_level);
                int f[3] = {c[0] << shift, c[1] << shift, c[2] << shift};
                for (size_t l = m_choice_level; l < m_levels.size(); ++l) {
                    const Level &level = m_levels[l];
                    const size_t i = index(level, f, int(l));
                    if (level.records[i] < MinChoiceRecords) continue;
                    // Each emitter in proportion to the square root of its second moment,
                    // which minimises the variance of a one-emitter sample of their sum.
                    double total = 0.0;
                    for (size_t e = 0; e < E; ++e)
                        if (!is_fixed(e)) total += std::sqrt(level.contribution[i * E + e]);
                    if (!(total > 0.0) || !std::isfinite(total)) continue;
                    ++chosen;
                    for (size_t e = 0; e < E; ++e)
                        learnt[e] = is_fixed(e)
                                        ? fixed[e]
                                        : float(free_share *
                                                std::sqrt(level.contribution[i * E + e]) / total);
                    // The own rule for the base cell's points, normalised (where the hierarchy
                    // finds no emitter that reaches the cell, the others take its share).
                    double own_total = 0.0;
                    if (own) {
                        own(cell_box(m_choice_level, c), own_choice.data());
                        for (size_t e = 0; e < E; ++e)
                            own_total += std::max(double(own_choice[e]), 0.0);
                    } else {
                        std::fill(own_choice.begin(), own_choice.end(), 1.f);
                        own_total = double(E);
                    }
                    const size_t start = m_choice.size();
                    m_choice_offset[index(base, c, 0)] = int32_t(start);
                    m_choice.resize(start + 2 * E);
                    float sum = 0.f;
                    for (size_t e = 0; e < E; ++e) {
                        const float o =
                            own_total > 0.0 && std::isfinite(own_total)
                                ? float(std::max(double(own_choice[e]), 0.0) / own_total)
                                : learnt[e];
                        m_choice[start + e] =
                            OwnChoiceShare * o + (1.f - OwnChoiceShare) * learnt[e];
                        sum += m_choice[start + e];
                        m_choice[start + E + e] = sum;
                    }
                    break;
                }
            }
    if (chosen == 0) m_choice_offset.clear();
    return chosen;
}

} // namespace facet::detail
