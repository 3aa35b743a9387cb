// @brief Deterministic, hash-based sample generation for the reference renderer.
//
// Every random number of a render is a pure function of (seed, frame, pixel,
// sample index, dimension): there is no generator state shared between pixels
// or threads, so an image is bit-identical whatever the thread count or tile
// order. Sample points are Owen-scrambled Sobol' (0,2)-sequences with shuffled
// indices (Burley 2020, "Practical Hash-based Owen Scrambling"), which gives
// stratified pixel positions for any sample count (perfectly stratified when
// the count is a power of two) and stratified pairs in every later dimension.
#pragma once

#include "core/hash.h"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace hp::sampling {

/// 64-bit finaliser (splitmix64, core/hash.h): a bijective avalanche mix.
inline uint64_t mix64(uint64_t x) { return hash::splitMix64(x); }

/// Order-dependent combination of a hash with one more value.
inline uint64_t hashCombine(uint64_t h, uint64_t v) { return mix64(h ^ (v + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2))); }

inline uint32_t reverseBits(uint32_t x) {
    x = (x << 16) | (x >> 16);
    x = ((x & 0x00ff00ffu) << 8) | ((x & 0xff00ff00u) >> 8);
    x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
    x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
    x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
    return x;
}

/// Laine-Karras style hash that only lets each bit depend on lower bits:
/// applied to bit-reversed values it is an Owen (nested uniform) scramble.
inline uint32_t laineKarras(uint32_t x, uint32_t seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

inline uint32_t owenScramble(uint32_t x, uint32_t seed) { return reverseBits(laineKarras(reverseBits(x), seed)); }

/// First two Sobol' dimensions (van der Corput and its (0,2) partner).
inline uint32_t sobol0(uint32_t i) { return reverseBits(i); }
inline uint32_t sobol1(uint32_t i) {
    uint32_t r = 0;
    for (uint32_t v = 1u << 31; i; i >>= 1, v ^= v >> 1)
        if (i & 1u) r ^= v;
    return r;
}

/// [0, 1) float from the top 24 bits.
inline float toUnit(uint32_t x) { return float(x >> 8) * (1.f / 16777216.f); }

/// Random numbers of one pixel sample. Dimensions are consumed in pairs; the
/// same (pixel key, sample index, call order) always gives the same numbers.
class PixelSampler {
  public:
    /// `seed` and `frame` select the sequence; (x, y) the pixel.
    PixelSampler(uint64_t seed, int frame, int x, int y)
        : key_(hashCombine(hashCombine(hashCombine(mix64(seed), uint64_t(uint32_t(frame))), uint64_t(uint32_t(x))),
                           uint64_t(uint32_t(y)))) {}

    /// Starts sample `index` of the pixel (dimension counter back to 0).
    void start(uint32_t index) {
        index_ = index;
        dimension_ = 0;
        side_ = 0;
    }

    /// The next stratified 2D point in [0, 1)^2.
    Eigen::Vector2f next2D() {
        const uint64_t h = hashCombine(key_, dimension_++);
        const uint32_t i = owenScramble(index_, uint32_t(h));
        return {toUnit(owenScramble(sobol0(i), uint32_t(h >> 32))),
                toUnit(owenScramble(sobol1(i), uint32_t(mix64(h) >> 32)))};
    }

    /// The next number in [0, 1) (one dimension of a fresh pair).
    float next1D() { return next2D().x(); }

    /// The next number of a second, independent dimension sequence, for
    /// decisions that are made only sometimes (shadow-ray roulette): drawing
    /// them here leaves the main dimensions where they would be without
    /// them, so switching such a decision on or off changes nothing else.
    float nextSide() {
        const uint64_t h = hashCombine(key_, kSide | side_++);
        return toUnit(owenScramble(sobol0(owenScramble(index_, uint32_t(h))), uint32_t(h >> 32)));
    }

  private:
    uint64_t key_;
    uint32_t index_ = 0;
    uint64_t dimension_ = 0;
    uint64_t side_ = 0;
    static constexpr uint64_t kSide = 1ull << 63;  ///< side dimensions never meet the main ones
};

/// Cosine-weighted direction on the hemisphere around +Z (pdf cos(theta)/pi).
inline Eigen::Vector3f cosineHemisphere(const Eigen::Vector2f& u) {
    const float r = std::sqrt(u.x());
    const float phi = 2.f * float(M_PI) * u.y();
    return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.f, 1.f - u.x()))};
}

/// Any orthonormal pair (b1, b2) completing unit `n` (Duff et al. 2017).
inline void orthonormalBasis(const Eigen::Vector3f& n, Eigen::Vector3f* b1, Eigen::Vector3f* b2) {
    const float sign = std::copysign(1.f, n.z());
    const float a = -1.f / (sign + n.z());
    const float b = n.x() * n.y() * a;
    *b1 = Eigen::Vector3f(1.f + sign * n.x() * n.x() * a, sign * b, -sign * n.x());
    *b2 = Eigen::Vector3f(b, sign + n.y() * n.y() * a, -n.y());
}

}  // namespace hp::sampling
