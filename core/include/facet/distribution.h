#pragma once

#include <facet/assert.h>
#include <facet/vector.h>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace facet {

/// Discrete distribution over n entries from non-negative weights, sampled by inverting the CDF.
class DiscreteDistribution {
public:
    DiscreteDistribution() = default;
    explicit DiscreteDistribution(const std::vector<float> &weights) {
        build(weights.data(), weights.size());
    }
    DiscreteDistribution(const float *weights, size_t n) { build(weights, n); }

    void build(const float *weights, size_t n) {
        m_cdf.assign(n + 1, 0.0);
        for (size_t i = 0; i < n; ++i) m_cdf[i + 1] = m_cdf[i] + double(std::max(weights[i], 0.f));
        m_sum = m_cdf[n];
        if (m_sum > 0.0)
            for (double &c : m_cdf) c /= m_sum;
        build_guide();
    }

    size_t size() const { return m_cdf.empty() ? 0 : m_cdf.size() - 1; }
    /// Sum of the weights before normalisation.
    double sum() const { return m_sum; }
    float pmf(size_t i) const {
        FACET_ASSERT(i < size());
        return float(m_cdf[i + 1] - m_cdf[i]);
    }

    /// Index for u in [0,1); `u` is rescaled to a fresh uniform variate within the entry.
    size_t sample_reuse(float &u) const {
        size_t n = size();
        FACET_ASSERT(n > 0 && u >= 0.f && u <= 1.f);
        // The first entry whose CDF exceeds u, searched between the guide's entries for the two
        // multiples of 1/K around u: the same entry as a search of the whole table.
        auto first = m_cdf.begin() + 1, last = m_cdf.end();
        if (!m_guide.empty()) {
            const size_t k = std::min(size_t(double(u) * double(m_guide.size() - 1)),
                                      m_guide.size() - 2); // exact: K is a power of two
            first += m_guide[k];
            last = m_cdf.begin() + 1 + m_guide[k + 1]; // not found before it: m_guide[k + 1]
        }
        auto it = std::upper_bound(first, last, double(u));
        size_t i = std::min(size_t(it - m_cdf.begin()) - 1, n - 1);
        // Skip zero-probability entries that upper_bound may land on at the boundaries.
        while (i + 1 < n && pmf(i) == 0.f) ++i;
        double lo = m_cdf[i], w = m_cdf[i + 1] - m_cdf[i];
        u = w > 0.0 ? std::min(float((double(u) - lo) / w), OneMinusEpsilon) : 0.f;
        return i;
    }

private:
    /// The guide table of the cut-point method: m_guide[k], k = 0..K, is the entry sampled for
    /// u = k / K (the first whose CDF exceeds it, or n), with K the largest power of two not
    /// above n. The entry of any u in [k/K, (k+1)/K) lies between m_guide[k] and m_guide[k+1],
    /// so a search of the whole table (about log2 n dependent loads across it) becomes one of a
    /// few entries. Empty for a single entry or more than 2^32.
    void build_guide() {
        m_guide.clear();
        const size_t n = size();
        if (n < 2 || n > size_t(UINT32_MAX)) return;
        size_t K = 1;
        while (K <= n / 2) K *= 2;
        m_guide.resize(K + 1);
        size_t i = 0; // a merge of the thresholds k / K into the CDF
        for (size_t k = 0; k <= K; ++k) {
            const double threshold = double(k) / double(K);
            while (i < n && !(m_cdf[i + 1] > threshold)) ++i;
            m_guide[k] = uint32_t(i);
        }
    }

    std::vector<double> m_cdf;
    std::vector<uint32_t> m_guide;
    double m_sum = 0.0;
};

} // namespace facet
