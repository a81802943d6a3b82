#pragma once

#include <facet/assert.h>
#include <facet/vector.h>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace facet {

/// Starts loading the cache line of p, for a read that is coming. An asm statement rather than
/// __builtin_prefetch: compilers remove a loop whose only statements are that builtin.
inline void prefetch_line(const void *p) {
#if defined(__x86_64__) || defined(__i386__)
    asm volatile("prefetcht0 %0" : : "m"(*static_cast<const char *>(p)));
#else
    __builtin_prefetch(p);
#endif
}

/// Discrete distribution over n entries from non-negative weights, sampled by inverting the CDF.
///
/// The CDF has two levels, so that a sample of a large table (an environment map's two million
/// cells) waits for as few cache misses as possible: the entries are grouped in blocks of
/// BlockSize. A CDF over the blocks (double) picks the block; the block's line (64 bytes) holds
/// where it starts in that CDF, its width and its own CDF relative to it (float), which pick the
/// entry. An entry's probability is its block's width times its share of the block, both as
/// stored: sampling and pmf() agree on it.
class DiscreteDistribution {
public:
    static constexpr size_t BlockSize = 12;
    /// Up to this many candidate blocks are compared directly rather than searched.
    static constexpr size_t ShortRange = 8;

    DiscreteDistribution() = default;
    explicit DiscreteDistribution(const std::vector<float> &weights) {
        build(weights.data(), weights.size());
    }
    DiscreteDistribution(const float *weights, size_t n) { build(weights, n); }

    void build(const float *weights, size_t n) {
        m_size = n;
        const size_t blocks = (n + BlockSize - 1) / BlockSize;
        m_block_cdf.assign(blocks + 1, 0.0);
        m_blocks.assign(blocks, Block{});
        for (size_t b = 0; b < blocks; ++b) {
            // Running sums in double, each divided by the block's sum: the last entry of weight
            // reads exactly 1 and the values never decrease. Padding and an empty block read 1.
            double partial[BlockSize];
            double s = 0.0;
            for (size_t j = 0; j < BlockSize; ++j) {
                const size_t i = b * BlockSize + j;
                if (i < n) s += double(std::max(weights[i], 0.f));
                partial[j] = s;
            }
            for (size_t j = 0; j < BlockSize; ++j)
                m_blocks[b].cdf[j] = s > 0.0 ? float(partial[j] / s) : 1.f;
            m_block_cdf[b + 1] = m_block_cdf[b] + s;
        }
        m_sum = m_block_cdf[blocks];
        if (m_sum > 0.0)
            for (double &c : m_block_cdf) c /= m_sum;
        for (size_t b = 0; b < blocks; ++b) {
            m_blocks[b].start = m_block_cdf[b];
            m_blocks[b].width = m_block_cdf[b + 1] - m_block_cdf[b];
        }
        build_guide();
    }

    size_t size() const { return m_size; }
    /// Sum of the weights before normalisation.
    double sum() const { return m_sum; }
    /// Probability of entry i, as sample_reuse() picks it.
    float pmf(size_t i) const {
        FACET_ASSERT(i < size());
        const Block &block = m_blocks[i / BlockSize];
        const size_t j = i % BlockSize;
        const double share = double(block.cdf[j]) - (j > 0 ? double(block.cdf[j - 1]) : 0.0);
        return float(block.width * share);
    }

    /// The CDF before entry i (i < size()): sample_reuse() picks i or a later entry exactly
    /// for u at or above it.
    double cdf_before(size_t i) const {
        FACET_ASSERT(i < size());
        const Block &block = m_blocks[i / BlockSize];
        const size_t j = i % BlockSize;
        return block.start + (j > 0 ? block.width * double(block.cdf[j - 1]) : 0.0);
    }

    /// Index for u in [0,1); `u` is rescaled to a fresh uniform variate within the entry.
    size_t sample_reuse(float &u) const {
        return sample_reuse(u, [](size_t, size_t) {});
    }

    /// The same, calling `about_to_pick(first, last)` with the range of entries (first and last
    /// included) the pick will come from as soon as it is known, before the block's line is
    /// read: the caller can prefetch what it will read for them, so that both misses overlap.
    template <typename Hint> size_t sample_reuse(float &u, Hint &&about_to_pick) const {
        const size_t n = size();
        FACET_ASSERT(n > 0 && u >= 0.f && u <= 1.f);
        const size_t blocks = m_blocks.size();
        size_t b = 0;
        if (blocks > 1) {
            // The first block whose CDF exceeds u, searched between the guide's entries for the
            // two multiples of 1/K around u: the same block as a search of the whole table, and
            // no search at all when both name the same block.
            size_t lo = 0, hi = blocks;
            if (!m_guide.empty()) {
                const size_t k = std::min(size_t(double(u) * double(m_guide.size() - 1)),
                                          m_guide.size() - 2); // exact: K is a power of two
                lo = m_guide[k];
                hi = std::min(size_t(m_guide[k + 1]) + 1, blocks);
            }
            if (hi - lo > 1 && hi - lo <= ShortRange) {
                // A few candidates: their lines are loaded together, and the start of each
                // next block (its CDF value) decides, so the pick waits for one miss, not two.
                for (size_t c = lo; c < hi; ++c) prefetch_line(&m_blocks[c]);
                b = lo;
                while (b + 1 < hi && !(m_blocks[b + 1].start > double(u))) ++b; // hi <= blocks
            } else if (hi - lo > 1) {
                auto it = std::upper_bound(m_block_cdf.begin() + 1 + lo,
                                           m_block_cdf.begin() + 1 + hi, double(u));
                b = std::min(size_t(it - m_block_cdf.begin()) - 1, blocks - 1);
            } else {
                // One block holds all of [k/K, (k+1)/K): u is inside it, so it has weight.
                b = std::min(lo, blocks - 1);
            }
        }
        // The first block whose CDF exceeds u has CDF(b) <= u < CDF(b + 1): it has weight. Only
        // past the end (u = 1, or nothing to sample) can it have none.
        about_to_pick(b * BlockSize, std::min(b * BlockSize + BlockSize, n) - 1);
        const Block &block = m_blocks[b];
        if (!(block.width > 0.0)) { // nothing to sample: the last entry
            u = 0.f;
            return n - 1;
        }
        // Within the block: the first entry whose share reaches past v (a count over the line).
        const float v =
            std::clamp(float((double(u) - block.start) / block.width), 0.f, OneMinusEpsilon);
        size_t j = 0;
        for (size_t k = 0; k < BlockSize; ++k) j += block.cdf[k] <= v ? 1 : 0;
        j = std::min(j, BlockSize - 1); // v < 1 = the last entry of weight; kept safe
        const float c0 = j > 0 ? block.cdf[j - 1] : 0.f;
        const float width = block.cdf[j] - c0;
        u = width > 0.f ? std::clamp((v - c0) / width, 0.f, OneMinusEpsilon) : 0.f;
        return std::min(b * BlockSize + j, n - 1);
    }

private:
    /// One block: where it starts in the block CDF, its width, and its CDF relative to it.
    struct alignas(64) Block {
        double start = 0.0, width = 0.0;
        float cdf[BlockSize] = {};
    };
    static_assert(sizeof(Block) == 64, "a block is one cache line");

    /// The guide table of the cut-point method over the blocks: m_guide[k], k = 0..K, is the
    /// block sampled for u = k / K (the first whose CDF exceeds it, or the block count), with K
    /// the largest power of two not above a quarter of the count (at least 1). The block of any
    /// u in [k/K, (k+1)/K) lies between m_guide[k] and m_guide[k+1], so a search of the whole
    /// table (about log2 n dependent loads across it) becomes one of a few entries. A guide this
    /// size stays in cache more often than one entry per block, which every sample would wait
    /// for (the living room's sky: 3% of the render). Empty for a single block or 2^32 blocks or
    /// more.
    void build_guide() {
        m_guide.clear();
        const size_t n = m_blocks.size();
        if (n < 2 || n > size_t(UINT32_MAX)) return;
        size_t K = 1;
        while (K <= n / 8) K *= 2;
        m_guide.resize(K + 1);
        size_t i = 0; // a merge of the thresholds k / K into the CDF
        for (size_t k = 0; k <= K; ++k) {
            const double threshold = double(k) / double(K);
            while (i < n && !(m_block_cdf[i + 1] > threshold)) ++i;
            m_guide[k] = uint32_t(i);
        }
    }

    size_t m_size = 0;
    std::vector<double> m_block_cdf; ///< blocks + 1 values, normalised
    std::vector<Block> m_blocks;
    std::vector<uint32_t> m_guide;
    double m_sum = 0.0;
};

} // namespace facet
