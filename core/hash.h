// @brief Integer hash finalisers of the xorshift-multiply family, shared by
// the renderer's sample hashing (render/reference/sampling.h) and the followers' and
// groom modifiers' per-strand randomness (sim/followers/follower_kernels.h).
//
// Both finalisers in use are the same three xorshifts around two odd
// multiplications,
//   h ^= h >> s1;  h *= m1;  h ^= h >> s2;  h *= m2;  h ^= h >> s3,
// a bijection whose constants were searched for full avalanche (each input
// bit flips each output bit with probability about 1/2). Only the constants
// differ, so they are named here and the shape is written once. The bits of
// both feed outputs that must not change (sample positions, follower
// offsets), so the constants are the published ones, exactly.
#pragma once

#include <cstdint>

namespace hp::hash {

/// @brief The constants of one xorshift-multiply finaliser (see the file
/// comment): three right-shift amounts and two odd multipliers.
template <typename Word>
struct XorShiftMultiply {
    int s1, s2, s3;
    Word m1, m2;
};

/// splitmix64's output function (Steele, Lea and Flood 2014, "Fast
/// Splittable Pseudorandom Number Generators"; the constants of Vigna's
/// splitmix64.c, from Stafford's "Mix13" variant).
inline constexpr XorShiftMultiply<uint64_t> kSplitMix64{30, 27, 31, 0xbf58476d1ce4e5b9ull, 0x94d049bb133111ebull};

/// MurmurHash3's 32-bit finaliser fmix32 (Appleby, MurmurHash3.cpp).
inline constexpr XorShiftMultiply<uint32_t> kMurmur3Fmix32{16, 13, 16, 0x85ebca6bu, 0xc2b2ae35u};

/// @brief The xorshift-multiply finaliser with constants `K`.
/// @tparam K  kSplitMix64 or kMurmur3Fmix32 (a compile-time constant, so the
///            shifts and multipliers are immediates, as when written out).
/// @tparam U  the constants' word type, or a GCC vector of it (the follower
///            update hashes 8 lanes at once: sim/followers/follower_simd.h).
/// @param h   the value to mix.
template <const auto& K, typename U>
inline __attribute__((always_inline)) U xorShiftMultiply(U h) {
    h ^= h >> K.s1;
    h *= K.m1;
    h ^= h >> K.s2;
    h *= K.m2;
    h ^= h >> K.s3;
    return h;
}

/// splitmix64's finaliser: a bijective 64-bit avalanche mix.
inline uint64_t splitMix64(uint64_t x) { return xorShiftMultiply<kSplitMix64>(x); }

/// MurmurHash3's fmix32. U: uint32_t or a GCC vector of them.
template <typename U>
inline __attribute__((always_inline)) U murmur3Fmix32(U h) {
    return xorShiftMultiply<kMurmur3Fmix32>(h);
}

}  // namespace hp::hash
