#pragma once

#include <cstdint>

/// Stateless helpers for stratified and low-discrepancy samplers: hashing, random permutations
/// of an index range without tables, and the (0,2)-sequence in base 2.
namespace facet::qmc {

/// 32-bit integer hash (Wellons' lowbias32 finaliser).
inline uint32_t hash32(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}

inline uint32_t hash_combine(uint32_t a, uint32_t b) {
    return hash32(a ^ (hash32(b) + 0x9e3779b9U + (a << 6) + (a >> 2)));
}
inline uint32_t hash64(uint64_t v) { return hash_combine(uint32_t(v), uint32_t(v >> 32)); }

/// Uniform float in [0, 1) from a hash value (24 bits).
inline float to_unit_float(uint32_t h) { return float(h >> 8) * 0x1p-24f; }

/// A fixed divisor d ≥ 1 of 32-bit values, divided by multiplication instead of the processor's
/// division (Lemire, Kaser and Kurz 2019, "Faster remainder by direct computation"): with
/// c = ceil(2^64 / d), x / d is the high word of c·x and x % d that of (c·x mod 2^64)·d, exact
/// for every 32-bit x. Worth it where the same divisor serves many divisions on a dependent
/// chain (the samplers' per-draw index arithmetic).
class Divisor {
public:
    Divisor() : Divisor(1) {}
    explicit Divisor(uint32_t d) : m_d(d), m_c(~uint64_t(0) / (d ? d : 1) + 1) {}

    uint32_t value() const { return m_d; }
    uint32_t div(uint32_t x) const { return m_d == 1 ? x : uint32_t(high_word(m_c, x)); }
    uint32_t mod(uint32_t x) const { return uint32_t(high_word(m_c * x, m_d)); } // c = 0 for 1

private:
    static uint64_t high_word(uint64_t a, uint32_t b) {
        __extension__ using u128 = unsigned __int128;
        return uint64_t((u128(a) * b) >> 64);
    }
    uint32_t m_d;
    uint64_t m_c;
};

/// Kensler's invertible hash rounds on the bits of mask w (a power of two minus one).
inline uint32_t permute_bits(uint32_t i, uint32_t w, uint32_t seed) {
    i ^= seed;
    i *= 0xe170893dU;
    i ^= seed >> 16;
    i ^= (i & w) >> 4;
    i ^= seed >> 8;
    i *= 0x0929eb3fU;
    i ^= seed >> 23;
    i ^= (i & w) >> 1;
    i *= 1U | seed >> 27;
    i *= 0x6935fa69U;
    i ^= (i & w) >> 11;
    i *= 0x74dcb303U;
    i ^= (i & w) >> 2;
    i *= 0x9e501cc3U;
    i ^= (i & w) >> 2;
    i *= 0xc860a3dfU;
    i &= w;
    i ^= i >> 5;
    return i;
}

/// The smallest power of two minus one that is at least n - 1 (n ≥ 1).
inline uint32_t permute_mask(uint32_t n) {
    uint32_t w = n - 1;
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    return w;
}

/// Element i of a pseudo-random permutation of {0, ..., n-1} selected by `seed`: a bijection
/// built from invertible hash rounds on the next power of two, with cycle-walking to stay in
/// range (Kensler 2013, "Correlated Multi-Jittered Sampling", section 3).
inline uint32_t permute(uint32_t i, uint32_t n, uint32_t seed) {
    if (n <= 1) return 0;
    const uint32_t w = permute_mask(n);
    do i = permute_bits(i, w, seed);
    while (i >= n);
    return (i + seed) % n;
}

/// permute() over a range whose size is a fixed Divisor: the same element, without a division.
inline uint32_t permute(uint32_t i, const Divisor &n, uint32_t seed) {
    if (n.value() <= 1) return 0;
    const uint32_t w = permute_mask(n.value());
    do i = permute_bits(i, w, seed);
    while (i >= n.value());
    return n.mod(i + seed);
}

/// Radical inverse in base 2 of i, XOR-scrambled: the first component of the (0,2)-sequence.
inline uint32_t van_der_corput_bits(uint32_t i, uint32_t scramble) {
    i = (i << 16) | (i >> 16);
    i = ((i & 0x00ff00ffU) << 8) | ((i & 0xff00ff00U) >> 8);
    i = ((i & 0x0f0f0f0fU) << 4) | ((i & 0xf0f0f0f0U) >> 4);
    i = ((i & 0x33333333U) << 2) | ((i & 0xccccccccU) >> 2);
    i = ((i & 0x55555555U) << 1) | ((i & 0xaaaaaaaaU) >> 1);
    return i ^ scramble;
}

/// Second component of the (0,2)-sequence (Sobol's second generator matrix), XOR-scrambled.
inline uint32_t sobol2_bits(uint32_t i, uint32_t scramble) {
    for (uint32_t v = 1U << 31; i != 0; i >>= 1, v ^= v >> 1)
        if (i & 1) scramble ^= v;
    return scramble;
}

/// Bits to [0, 1) keeping the float strictly below one.
inline float bits_to_float(uint32_t bits) {
    float f = float(bits >> 8) * 0x1p-24f;
    return f;
}

} // namespace facet::qmc
