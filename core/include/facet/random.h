#pragma once

#include <cstdint>
#include <utility>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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

/// A 64-bit bijective mixer with full avalanche: the finaliser of SplitMix64 (Stafford's
/// "Mix13" constants). Two multiplications: cheap enough to hash a seed at every sample.
inline uint64_t mix64(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

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

/// Four TEA hashes at once: out[i] = tea_hash(v0[i], v1[i], rounds), bit for bit. With SSE2 the
/// four run in the lanes of one register, for the instructions of one scalar hash.
inline void tea_hash4(const uint32_t (&v0_in)[4], const uint32_t (&v1_in)[4], uint64_t (&out)[4],
                      int rounds = 4) {
#if defined(__SSE2__)
    __m128i v0 = _mm_loadu_si128(reinterpret_cast<const __m128i *>(v0_in));
    __m128i v1 = _mm_loadu_si128(reinterpret_cast<const __m128i *>(v1_in));
    const __m128i k0 = _mm_set1_epi32(int(0xa341316cu)), k1 = _mm_set1_epi32(int(0xc8013ea4u)),
                  k2 = _mm_set1_epi32(int(0xad90777du)), k3 = _mm_set1_epi32(int(0x7e95761eu)),
                  delta = _mm_set1_epi32(int(0x9e3779b9u));
    __m128i sum = _mm_setzero_si128();
    for (int i = 0; i < rounds; ++i) {
        sum = _mm_add_epi32(sum, delta);
        v0 = _mm_add_epi32(v0, _mm_xor_si128(_mm_xor_si128(_mm_add_epi32(_mm_slli_epi32(v1, 4), k0),
                                                           _mm_add_epi32(v1, sum)),
                                             _mm_add_epi32(_mm_srli_epi32(v1, 5), k1)));
        v1 = _mm_add_epi32(v1, _mm_xor_si128(_mm_xor_si128(_mm_add_epi32(_mm_slli_epi32(v0, 4), k2),
                                                           _mm_add_epi32(v0, sum)),
                                             _mm_add_epi32(_mm_srli_epi32(v0, 5), k3)));
    }
    // Interleave the (v0, v1) pairs: the 64-bit results (v1 << 32) | v0 of lanes 0-1 and 2-3.
    _mm_storeu_si128(reinterpret_cast<__m128i *>(out), _mm_unpacklo_epi32(v0, v1));
    _mm_storeu_si128(reinterpret_cast<__m128i *>(out + 2), _mm_unpackhi_epi32(v0, v1));
#else
    for (int i = 0; i < 4; ++i) out[i] = tea_hash(v0_in[i], v1_in[i], rounds);
#endif
}

/// Two TEA hashes at once: {tea_hash(a0, a1, rounds), tea_hash(b0, b1, rounds)}, bit for bit.
inline std::pair<uint64_t, uint64_t> tea_hash_pair(uint32_t a0, uint32_t a1, uint32_t b0,
                                                   uint32_t b1, int rounds = 4) {
    const uint32_t v0[4] = {a0, b0, 0, 0}, v1[4] = {a1, b1, 0, 0};
    uint64_t out[4];
    tea_hash4(v0, v1, out, rounds);
    return {out[0], out[1]};
}

} // namespace facet
