// @brief 8-lane float and integer vectors for the follower update (GCC vector
// extensions) and the one shuffle it needs, an 8 × 8 transpose (lanes are
// followers; tables and outputs are per follower).
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

/// The same vector at float alignment: what load and store access through
/// (a 32-byte memcpy into an array element is split into 16-byte moves).
typedef float f8u __attribute__((vector_size(32), aligned(4), may_alias));

HP_SIMD f8 load(const float* p) { return *reinterpret_cast<const f8u*>(p); }
HP_SIMD void store(float* p, f8 v) { *reinterpret_cast<f8u*>(p) = v; }
// Broadcasts as a permutation of lane 0, which GCC emits as one broadcast
// instruction; an initializer list of copies (or x - f8{}) it often
// assembles lane by lane.
HP_SIMD f8 splat(float x) { return __builtin_shuffle(f8{x}, i8{}); }
HP_SIMD u8 splat(uint32_t x) { return __builtin_shuffle(u8{x}, i8{}); }
HP_SIMD f8 select(i8 mask, f8 a, f8 b) { return mask ? a : b; }

/// A 32-bit hash read as a signed integer, times 2^-31: [-1, 1).
HP_SIMD f8 toSignedUnit(u8 h) { return __builtin_convertvector(i8(h), f8) * (1.f / 2147483648.f); }

HP_SIMD bool anyLane(i8 m) {
    uint64_t q[4];
    std::memcpy(q, &m, sizeof q);
    return (q[0] | q[1] | q[2] | q[3]) != 0;
}

/// A 4 × 4 transpose in each 128-bit half of four vectors (the first two
/// rounds of an 8 × 8 transpose): lane i of half h of c_k is lane k of half
/// h of r_i. 8 shuffles.
HP_SIMD void transposeHalves(f8 r0, f8 r1, f8 r2, f8 r3, f8& c0, f8& c1, f8& c2, f8& c3) {
    const i8 lo{0, 8, 1, 9, 4, 12, 5, 13}, hi{2, 10, 3, 11, 6, 14, 7, 15};
    const i8 lo2{0, 1, 8, 9, 4, 5, 12, 13}, hi2{2, 3, 10, 11, 6, 7, 14, 15};
    const f8 t0 = __builtin_shuffle(r0, r1, lo), t1 = __builtin_shuffle(r0, r1, hi);
    const f8 t2 = __builtin_shuffle(r2, r3, lo), t3 = __builtin_shuffle(r2, r3, hi);
    c0 = __builtin_shuffle(t0, t2, lo2);
    c1 = __builtin_shuffle(t0, t2, hi2);
    c2 = __builtin_shuffle(t1, t3, lo2);
    c3 = __builtin_shuffle(t1, t3, hi2);
}

/// Half of an 8 × 8 transpose: the 4 floats at p[k] (k = 0..7, the lanes)
/// as 4 vectors, c_i lane k = p[k][i]. Two 4-float loads per 128-bit half,
/// then a 4 × 4 transpose in each half: 12 shuffles for 4 outputs, and only
/// those 4 live, where a full transpose keeps 8 registers busy.
HP_SIMD void transpose8x4(const float* const* p, f8& c0, f8& c1, f8& c2, f8& c3) {
    typedef float f4u __attribute__((vector_size(16), aligned(4), may_alias));
    const f8 r0 = __builtin_shufflevector(*reinterpret_cast<const f4u*>(p[0]), *reinterpret_cast<const f4u*>(p[4]), 0, 1, 2, 3, 4, 5, 6, 7);
    const f8 r1 = __builtin_shufflevector(*reinterpret_cast<const f4u*>(p[1]), *reinterpret_cast<const f4u*>(p[5]), 0, 1, 2, 3, 4, 5, 6, 7);
    const f8 r2 = __builtin_shufflevector(*reinterpret_cast<const f4u*>(p[2]), *reinterpret_cast<const f4u*>(p[6]), 0, 1, 2, 3, 4, 5, 6, 7);
    const f8 r3 = __builtin_shufflevector(*reinterpret_cast<const f4u*>(p[3]), *reinterpret_cast<const f4u*>(p[7]), 0, 1, 2, 3, 4, 5, 6, 7);
    transposeHalves(r0, r1, r2, r3, c0, c1, c2, c3);
}

/// Lane-wise square root (a loop GCC turns into one vector instruction;
/// vector extensions have no sqrt of their own).
HP_SIMD f8 sqrt8(f8 x) {
    f8 r;
    for (int k = 0; k < 8; ++k) r[k] = __builtin_sqrtf(x[k]);
    return r;
}

/// 8 × 8 transpose in place: afterwards lane i of r_k is the former lane k
/// of r_i. Three rounds (unpack pairs, combine pairs, swap 128-bit halves):
/// 24 shuffles, each one instruction in the AVX2 build. Separate variables,
/// not an array: GCC keeps those in registers.
HP_SIMD void transpose8(f8& r0, f8& r1, f8& r2, f8& r3, f8& r4, f8& r5, f8& r6, f8& r7) {
    const i8 lowHalves{0, 1, 2, 3, 8, 9, 10, 11}, highHalves{4, 5, 6, 7, 12, 13, 14, 15};
    f8 u0, u1, u2, u3, u4, u5, u6, u7;
    transposeHalves(r0, r1, r2, r3, u0, u1, u2, u3);
    transposeHalves(r4, r5, r6, r7, u4, u5, u6, u7);
    r0 = __builtin_shuffle(u0, u4, lowHalves);
    r1 = __builtin_shuffle(u1, u5, lowHalves);
    r2 = __builtin_shuffle(u2, u6, lowHalves);
    r3 = __builtin_shuffle(u3, u7, lowHalves);
    r4 = __builtin_shuffle(u0, u4, highHalves);
    r5 = __builtin_shuffle(u1, u5, highHalves);
    r6 = __builtin_shuffle(u2, u6, highHalves);
    r7 = __builtin_shuffle(u3, u7, highHalves);
}

}  // namespace hp::follower::simd
