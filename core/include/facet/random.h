#pragma once

#include <cstdint>

namespace facet {

/// PCG32 random number generator (O'Neill 2014), 64-bit state, selectable stream.
class PCG32 {
public:
    PCG32(uint64_t initstate = 0x853c49e6748fea9bULL, uint64_t initseq = 0xda3e39cb94b95bdbULL) {
        seed(initstate, initseq);
    }
    void seed(uint64_t initstate, uint64_t initseq = 1) {
        m_state = 0u;
        m_inc = (initseq << 1u) | 1u;
        next_uint32();
        m_state += initstate;
        next_uint32();
    }
    uint32_t next_uint32() {
        uint64_t old = m_state;
        m_state = old * 0x5851f42d4c957f2dULL + m_inc;
        uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
        uint32_t rot = uint32_t(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31));
    }
    /// Uniform in [0, 1): 23 random mantissa bits.
    float next_float() {
        union {
            uint32_t u;
            float f;
        } x;
        x.u = (next_uint32() >> 9) | 0x3f800000u;
        return x.f - 1.f;
    }
    double next_double() {
        uint64_t hi = next_uint32(), lo = next_uint32();
        return double(((hi << 32) | lo) >> 11) * (1.0 / 9007199254740992.0);
    }
    uint32_t next_uint32(uint32_t bound) {
        uint32_t threshold = (~bound + 1u) % bound;
        for (;;) {
            uint32_t r = next_uint32();
            if (r >= threshold) return r % bound;
        }
    }

private:
    uint64_t m_state, m_inc;
};

/// Tiny Encryption Algorithm as a hash of two words (used to decorrelate seeds).
inline uint64_t tea_hash(uint32_t v0, uint32_t v1, int rounds = 4) {
    uint32_t sum = 0;
    for (int i = 0; i < rounds; ++i) {
        sum += 0x9e3779b9;
        v0 += ((v1 << 4) + 0xa341316c) ^ (v1 + sum) ^ ((v1 >> 5) + 0xc8013ea4);
        v1 += ((v0 << 4) + 0xad90777d) ^ (v0 + sum) ^ ((v0 >> 5) + 0x7e95761e);
    }
    return (uint64_t(v1) << 32) | v0;
}

} // namespace facet
