// Deterministic sample generation: every random number is a pure function of
// (seed, pixel, sample index, dimension), so an image never depends on the thread count or on
// the order in which pixels are processed.
//
// Dimensions are consumed in pairs. Each pair is the first two dimensions of the Sobol sequence
// with hash-based nested uniform (Owen) scrambling and an Owen-scrambled index shuffle, as in
// Burley, "Practical Hash-based Owen Scrambling", JCGT 9(4), 2020. Each pair is a (0,2)-sequence
// in base 2: any power-of-two prefix of a pixel's samples is stratified in every elementary
// interval, and the sequence is progressive, which adaptive sampling needs (it appends samples
// to a pixel without knowing the final count in advance).
//
// The camera's four dimensions (pixel position and lens position) are instead drawn jointly as
// Sobol dimensions 0-3 of one shuffled index (get4DBatch): a defocused edge is a discontinuity in
// that 4D space, and joint stratification lowers its variance where independent pairs only
// stratify each 2D projection (1.3-1.8x lower on a toy defocused edge at 16-128 samples). Dimensions
// 0-1 stay a (0,2)-sequence, dimensions 2-3 are a (1,2)-sequence, and every power-of-two prefix
// of at least 16 points has one point in each of the 16 half-space boxes of the 4D cube.
#pragma once

#include <array>
#include <cstdint>

#include "core/math.h"

namespace wedge {

/// 32-bit integer hash (Wellons' "lowbias32" finaliser): good avalanche, cheap.
constexpr uint32_t hash32(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}
constexpr uint32_t hashCombine(uint32_t a, uint32_t b) { return hash32(a ^ (hash32(b) + 0x9e3779b9U + (a << 6) + (a >> 2))); }

constexpr uint32_t reverseBits32(uint32_t x) {
    x = __builtin_bswap32(x);  // bytes, then bits within bytes
    x = ((x >> 1) & 0x55555555U) | ((x & 0x55555555U) << 1);
    x = ((x >> 2) & 0x33333333U) | ((x & 0x33333333U) << 2);
    return ((x >> 4) & 0x0f0f0f0fU) | ((x & 0x0f0f0f0fU) << 4);
}

/// Laine-Karras style permutation that only lets lower bits affect higher ones; applied to the
/// bit-reversed value it is a nested uniform scramble (Burley 2020, improved constants).
inline uint32_t laineKarras(uint32_t x, uint32_t seed) {
    x ^= x * 0x3d20adeaU;
    x += seed;
    x *= (seed >> 16) | 1U;
    x ^= x * 0x05526c56U;
    x ^= x * 0x53a22864U;
    return x;
}
inline uint32_t nestedUniformScramble(uint32_t x, uint32_t seed) {
    return reverseBits32(laineKarras(reverseBits32(x), seed));
}

/// Sobol dimension 0 (van der Corput) and dimension 1 (generator matrix = Pascal matrix mod 2).
inline uint32_t sobol0(uint32_t index) { return reverseBits32(index); }
inline uint32_t sobol1(uint32_t index) {
    uint32_t r = 0;
    for (uint32_t v = 1U << 31; index; index >>= 1, v ^= v >> 1)
        if (index & 1U) r ^= v;
    return r;
}
/// Dimension 1 with its bits reversed (Burley's "sobol_reversed"): the scramble works on
/// reversed values, so generating them directly saves two bit reversals per point.
inline uint32_t sobol1Reversed(uint32_t index) {
    uint32_t r = 0;
    for (uint32_t v = 1U; index; index >>= 1, v ^= v << 1)
        if (index & 1U) r ^= v;
    return r;
}

/// Reversed direction numbers of a Sobol dimension from its primitive polynomial (degree s,
/// inner coefficients a) and initial m_1..m_s (Joe and Kuo's table, "new-joe-kuo-6.21201"):
/// m_k = m_{k-s} ^ (m_{k-s} << s) ^ sum_j a_j (m_{k-j} << j), v_k = m_k / 2^k.
constexpr std::array<uint32_t, 32> sobolReversedDirections(int s, uint32_t a, std::array<uint32_t, 3> init) {
    std::array<uint32_t, 33> m{};
    for (int k = 1; k <= s; ++k) m[k] = init[k - 1];
    for (int k = s + 1; k <= 32; ++k) {
        uint32_t v = m[k - s] ^ (m[k - s] << s);
        for (int j = 1; j < s; ++j)
            if ((a >> (s - 1 - j)) & 1U) v ^= m[k - j] << j;
        m[k] = v;
    }
    std::array<uint32_t, 32> r{};
    for (int k = 1; k <= 32; ++k) r[k - 1] = reverseBits32(m[k] << (32 - k));
    return r;
}
/// Sobol dimensions 1, 2 and 3 (Joe-Kuo d = 2, 3, 4: s = 1, 2, 3; a = 0, 1, 1; m = {1}, {1, 3},
/// {1, 3, 1}), reversed.
inline constexpr std::array<std::array<uint32_t, 32>, 3> kSobolReversed = {
    sobolReversedDirections(1, 0, {1, 0, 0}), sobolReversedDirections(2, 1, {1, 3, 0}),
    sobolReversedDirections(3, 1, {1, 3, 1})};

/// Sobol dimension d (1..3) of `index`, bits reversed.
inline uint32_t sobolReversed(uint32_t index, int d) {
    uint32_t r = 0;
    for (int b = 0; index; ++b, index >>= 1)
        if (index & 1U) r ^= kSobolReversed[d - 1][b];
    return r;
}

inline float toUnitFloat(uint32_t x) {
    // 24 high bits -> [0, 1), never exactly 1.
    return float(x >> 8) * 0x1p-24f;
}

/// The sample generator for one pixel. Cheap to construct; holds no mutable state, so the same
/// (pixel, index, pair) always yields the same point.
///
/// `independent`: independent uniform numbers instead (a hash of the pixel's key, the index,
/// the pair and the dimension), with none of the stratification above: for measuring what the
/// stratification is worth (`wedge render --sampler independent`; docs/maaf.md, "Stratified
/// samples"). The same (seed, pixel, index, pair) still gives the same point.
class PixelSampler {
public:
    static constexpr uint32_t kPairs = 8;  // dimension pairs a path sample may use

    PixelSampler(uint32_t seed, uint32_t pixelIndex, bool independent = false) : m_independent(independent) {
        uint32_t key = hashCombine(hash32(seed), pixelIndex);
        for (uint32_t p = 0; p < kPairs; ++p) m_pairKey[p] = hashCombine(key, p);
    }
    bool independent() const { return m_independent; }

    /// The 2D point of dimension pair `pair` (dimensions 2*pair and 2*pair+1) for sample `index`.
    /// nestedUniformScramble(sobol_d(i)) = reverse(laineKarras(reversed sobol_d(i))), and the
    /// reversed dimension 0 is the index itself.
    Vec2f get2D(uint32_t index, uint32_t pair) const {
        if (m_independent) return uniform(index, pair, 0);
        const Keys key = keys(pair);
        uint32_t shuffled = nestedUniformScramble(index, key.shuffle);
        return {scrambled(shuffled, key.dim[0]), scrambled(sobol1Reversed(shuffled), key.dim[1])};
    }
    float get1D(uint32_t index, uint32_t pair) const { return get2D(index, pair).x; }

    /// get2D for `count` (<= 16) consecutive indices at once, as flat loops over the 16 lanes
    /// that the compiler vectorises (one pixel's batch of samples).
    void get2DBatch(uint32_t first, uint32_t count, uint32_t pair, Vec2f* out) const {
        if (m_independent) {
            for (uint32_t k = 0; k < count; ++k) out[k] = uniform(first + k, pair, 0);
            return;
        }
        const Keys key = keys(pair);
        alignas(64) uint32_t sh[16], r[16];
        shuffleLanes(first, key.shuffle, sh);
        sobolLanes(sh, 1, r);
        for (uint32_t k = 0; k < count; ++k) out[k] = {scrambled(sh[k], key.dim[0]), scrambled(r[k], key.dim[1])};
    }

    /// The 4D point of Sobol dimensions 0-3 for sample `index`, scrambled by pair `pair`'s key:
    /// `a` (dimensions 0-1) is exactly get2D(index, pair); `b` (dimensions 2-3) shares its
    /// shuffled index, so (a, b) is jointly stratified. Replaces pair `pair + 1`.
    void get4D(uint32_t index, uint32_t pair, Vec2f& a, Vec2f& b) const { get4DBatch(index, 1, pair, &a, &b); }
    void get4DBatch(uint32_t first, uint32_t count, uint32_t pair, Vec2f* outA, Vec2f* outB) const {
        if (m_independent) {
            for (uint32_t k = 0; k < count; ++k) outA[k] = uniform(first + k, pair, 0), outB[k] = uniform(first + k, pair, 1);
            return;
        }
        const Keys key = keys(pair);
        alignas(64) uint32_t sh[16], r1[16], r2[16], r3[16];
        shuffleLanes(first, key.shuffle, sh);
        sobolLanes(sh, 1, r1);
        sobolLanes(sh, 2, r2);
        sobolLanes(sh, 3, r3);
        for (uint32_t k = 0; k < count; ++k) {
            outA[k] = {scrambled(sh[k], key.dim[0]), scrambled(r1[k], key.dim[1])};
            outB[k] = {scrambled(r2[k], key.dim[2]), scrambled(r3[k], key.dim[3])};
        }
    }

private:
    /// Two independent uniform numbers for sample `index` of pair `pair` (`half` 1: its
    /// dimensions 2-3 in get4DBatch).
    Vec2f uniform(uint32_t index, uint32_t pair, uint32_t half) const {
        const uint32_t h = hashCombine(hashCombine(m_pairKey[pair % kPairs] ^ 0x68bc21ebU, index), half);
        return {toUnitFloat(h), toUnitFloat(hash32(h ^ 0x5bd1e995U))};
    }
    /// A pair's seeds: the index shuffle and one nested uniform scramble per Sobol dimension
    /// (dimensions 0-1 are the ones get2D uses).
    struct Keys {
        uint32_t shuffle, dim[4];
    };
    Keys keys(uint32_t pair) const {
        const uint32_t pairKey = m_pairKey[pair % kPairs];
        return {pairKey ^ 0xa511e9b3U,
                {pairKey * 0x63d83595U + 1U, pairKey * 0x9c0ee1d3U + 3U, hashCombine(pairKey, 0x2c1b3c6dU),
                 hashCombine(pairKey, 0x297a2d39U)}};
    }
    /// The shuffled indices of first .. first+15, bits reversed (= reversed Sobol dimension 0).
    static void shuffleLanes(uint32_t first, uint32_t seed, uint32_t* sh) {
        for (uint32_t k = 0; k < 16; ++k) sh[k] = reverseBits32(laineKarras(reverseBits32(first + k), seed));
    }
    /// Reversed Sobol dimension d (1..3) of 16 shuffled indices, as masked XORs the compiler vectorises.
    static void sobolLanes(const uint32_t* sh, int d, uint32_t* r) {
        for (uint32_t k = 0; k < 16; ++k) r[k] = 0;
        for (int bit = 0; bit < 32; ++bit)
            for (uint32_t k = 0; k < 16; ++k) r[k] ^= kSobolReversed[d - 1][bit] & (0U - ((sh[k] >> bit) & 1U));
    }
    /// A reversed Sobol value through its nested uniform scramble, as a float in [0, 1).
    static float scrambled(uint32_t reversed, uint32_t seed) { return toUnitFloat(reverseBits32(laineKarras(reversed, seed))); }

    uint32_t m_pairKey[kPairs];
    bool m_independent = false;
};

}  // namespace wedge
