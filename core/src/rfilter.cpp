#include "tabulated_filter.h"

namespace facet {

TabulatedFilter::TabulatedFilter(const ReconstructionFilter &filter) {
    const float radius = filter.radius();
    m_radius = radius;
    m_scale = float(Resolution) / radius;
    bool constant = true;
    for (int i = 0; i < Resolution; ++i) {
        m_values[i] = filter.eval((radius * float(i)) / float(Resolution));
        constant = constant && m_values[i] == m_values[0];
    }
    m_at_minus_radius = filter.eval(-radius);
    m_at_radius = filter.eval(radius);
    // With these weights a sample's footprint has one non-zero weight per axis, at floor(pos)
    // (see ImageBlock::put()).
    if (radius == 0.5f && constant && m_at_minus_radius == m_values[0] && m_at_radius == 0.f &&
        m_values[0] != 0.f && std::isfinite(m_values[0]))
        m_single_pixel_weight = m_values[0];
}

ReconstructionFilter::~ReconstructionFilter() { delete m_table.load(std::memory_order_acquire); }

const TabulatedFilter &ReconstructionFilter::table() const {
    const TabulatedFilter *table = m_table.load(std::memory_order_acquire);
    if (table) return *table;
    // Built once; a thread that loses the race to publish its table drops it.
    auto *built = new TabulatedFilter(*this);
    if (m_table.compare_exchange_strong(table, built, std::memory_order_acq_rel)) return *built;
    delete built;
    return *table;
}

float ReconstructionFilter::weight(float x) const { return table()(x); }

} // namespace facet
