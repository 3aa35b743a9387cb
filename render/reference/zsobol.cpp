#include "render/reference/zsobol.h"

#include "core/hash.h"

namespace hp::sampling {

namespace {

/// The 24 permutations of {0, 1, 2, 3}, in lexicographic order.
constexpr uint8_t kPermutations[24][4] = {
    {0, 1, 2, 3}, {0, 1, 3, 2}, {0, 2, 1, 3}, {0, 2, 3, 1}, {0, 3, 1, 2}, {0, 3, 2, 1},
    {1, 0, 2, 3}, {1, 0, 3, 2}, {1, 2, 0, 3}, {1, 2, 3, 0}, {1, 3, 0, 2}, {1, 3, 2, 0},
    {2, 0, 1, 3}, {2, 0, 3, 1}, {2, 1, 0, 3}, {2, 1, 3, 0}, {2, 3, 0, 1}, {2, 3, 1, 0},
    {3, 0, 1, 2}, {3, 0, 2, 1}, {3, 1, 0, 2}, {3, 1, 2, 0}, {3, 2, 0, 1}, {3, 2, 1, 0}};

/// Spreads the low 32 bits of v to the even bits of the result.
uint64_t spreadBits(uint64_t v) {
    v &= 0xffffffffull;
    v = (v | (v << 16)) & 0x0000ffff0000ffffull;
    v = (v | (v << 8)) & 0x00ff00ff00ff00ffull;
    v = (v | (v << 4)) & 0x0f0f0f0f0f0f0f0full;
    v = (v | (v << 2)) & 0x3333333333333333ull;
    v = (v | (v << 1)) & 0x5555555555555555ull;
    return v;
}

/// A permutation's choice from the digits above it and the dimension's hash
/// (itself a full splitmix64 hash): one multiply and one xorshift, a third
/// of splitmix64's cost, which this loop pays once per digit and dimension.
uint64_t digitHash(uint64_t higher, uint64_t dimensionHash) {
    uint64_t h = (higher ^ dimensionHash) * 0xbf58476d1ce4e5b9ull;
    return h ^ (h >> 29);
}

}  // namespace

uint64_t encodeMorton2(uint32_t x, uint32_t y) { return (spreadBits(y) << 1) | spreadBits(x); }

uint32_t zsobolIndex(uint64_t mortonIndex, int log2Count, int digits, uint64_t dimensionHash) {
    // Digit i covers bits 2i − odd and 2i − odd + 1 (odd = log2Count & 1):
    // with an odd count the digits start at bit 1, and bit 0, alone, is
    // flipped after the loop.
    const int odd = log2Count & 1;
    uint64_t index = 0;
    for (int i = digits - 1; i >= odd; --i) {
        const int shift = 2 * i - odd;
        if (shift >= 32) continue;  // above the bits a 32-bit Sobol' point uses; only hashed below
        const uint64_t digit = (mortonIndex >> shift) & 3u;
        // The unpermuted digits above this one pick its permutation: a
        // nested (Owen-style) permutation of the base-4 index tree.
        const uint64_t higher = mortonIndex >> (shift + 2);
        const uint64_t h = digitHash(higher, dimensionHash);
        index |= uint64_t(kPermutations[((h >> 32) * 24u) >> 32][digit]) << shift;  // 24 · [0, 1)
    }
    if (odd) {
        const uint64_t h = digitHash(mortonIndex >> 1, dimensionHash);
        index |= (mortonIndex & 1u) ^ (h >> 63);
    }
    return uint32_t(index);
}

}  // namespace hp::sampling
