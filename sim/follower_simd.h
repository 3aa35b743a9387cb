// @brief 8-lane float and integer vectors for the follower update (GCC vector
// extensions) and the few shuffles it needs: a prefix sum across lanes and
// the interleave of x, y, z lanes into x y z triples.
//
// Internal to sim/follower_*.cpp. Why vector extensions rather than
// intrinsics: the same source compiles to AVX2 (one instruction per
// operation) in the x86-64-v3 build of the follower update and to pairs of
// SSE2 instructions in the baseline build, with no per-ISA code. Every
// function is forced inline: a 32-byte vector passed to an out-of-line
// function of the baseline build would go through memory (GCC's -Wpsabi note).
#pragma once

#include <cstdint>
#include <cstring>

namespace hp::follower::simd {

#define HP_SIMD inline __attribute__((always_inline))

typedef float f8 __attribute__((vector_size(32)));
typedef int32_t i8 __attribute__((vector_size(32)));
typedef uint32_t u8 __attribute__((vector_size(32)));

HP_SIMD f8 load(const float* p) {
    f8 v;
    std::memcpy(&v, p, sizeof v);  // unaligned load
    return v;
}
HP_SIMD void store(float* p, f8 v) { std::memcpy(p, &v, sizeof v); }
// Broadcasts as a permutation of lane 0, which GCC emits as one broadcast
// instruction; an initializer list of copies (or x - f8{}) it often
// assembles lane by lane.
HP_SIMD f8 splat(float x) { return __builtin_shuffle(f8{x}, i8{}); }
HP_SIMD u8 splat(uint32_t x) { return __builtin_shuffle(u8{x}, i8{}); }
HP_SIMD f8 select(i8 mask, f8 a, f8 b) { return mask ? a : b; }

/// A 32-bit hash read as a signed integer, times 2^-31: [-1, 1).
HP_SIMD f8 toSignedUnit(u8 h) { return __builtin_convertvector(i8(h), f8) * (1.f / 2147483648.f); }

/// Inclusive prefix sum across the lanes plus `carry` (a splat), in three
/// shift-and-add rounds; `carry` becomes the last lane for the next block.
HP_SIMD f8 prefixSum(f8 x, f8& carry) {
    const f8 zero{};
    x += __builtin_shuffle(x, zero, i8{8, 0, 1, 2, 3, 4, 5, 6});
    x += __builtin_shuffle(x, zero, i8{8, 8, 0, 1, 2, 3, 4, 5});
    x += __builtin_shuffle(x, zero, i8{8, 8, 8, 8, 0, 1, 2, 3});
    x += carry;
    carry = __builtin_shuffle(x, i8{7, 7, 7, 7, 7, 7, 7, 7});
    return x;
}

/// Lanes x0..x7, y0..y7, z0..z7 as x0 y0 z0 x1 y1 z1 ... z7 (24 floats) in
/// out[0..2]: each output vector takes three lane-repeating permutations and
/// two blends.
HP_SIMD void interleave3(f8 x, f8 y, f8 z, f8* out) {
    const i8 p0{0, 0, 0, 1, 1, 1, 2, 2}, p1{2, 3, 3, 3, 4, 4, 4, 5}, p2{5, 5, 6, 6, 6, 7, 7, 7};
    // Output lane i holds component i mod 3 (offset by the vector's start).
    const i8 xy0{0, 9, 2, 3, 12, 5, 6, 15}, xy1{8, 1, 10, 11, 4, 13, 14, 7};
    const f8 a0 = __builtin_shuffle(x, p0), b0 = __builtin_shuffle(y, p0), c0 = __builtin_shuffle(z, p0);
    const f8 a1 = __builtin_shuffle(x, p1), b1 = __builtin_shuffle(y, p1), c1 = __builtin_shuffle(z, p1);
    const f8 a2 = __builtin_shuffle(x, p2), b2 = __builtin_shuffle(y, p2), c2 = __builtin_shuffle(z, p2);
    // Vector 0: x y z x y z x y;  1: z x y z x y z x;  2: y z x y z x y z.
    out[0] = __builtin_shuffle(__builtin_shuffle(a0, b0, xy0), c0, i8{0, 1, 10, 3, 4, 13, 6, 7});
    out[1] = __builtin_shuffle(__builtin_shuffle(a1, b1, xy1), c1, i8{8, 1, 2, 11, 4, 5, 14, 7});
    out[2] = __builtin_shuffle(__builtin_shuffle(b2, c2, i8{0, 9, 2, 3, 12, 5, 6, 15}), a2, i8{0, 1, 10, 3, 4, 13, 6, 7});
}

}  // namespace hp::follower::simd
