// @brief Deterministic, hash-based sample generation for the reference renderer.
//
// Every random number of a render is a pure function of (seed, frame, pixel,
// sample index, dimension): there is no generator state shared between pixels
// or threads, so an image is bit-identical whatever the thread count or tile
// order. Sample points are Owen-scrambled Sobol' (0,2)-sequences with shuffled
// indices (Burley 2020, "Practical Hash-based Owen Scrambling"), which gives
// stratified pixel positions for any sample count (perfectly stratified when
// the count is a power of two) and stratified pairs in every later dimension.
//
// Two layouts (SamplerType):
// - independent (default): a sequence per pixel, seeded by a hash of the
//   pixel, so the pixels' errors are independent (white noise);
// - zsobol: one sequence for the whole image, pixels taking blocks of it in
//   shuffled Morton order (render/reference/zsobol.h), so that neighbouring
//   pixels' samples are stratified together and their errors form blue
//   noise where neighbouring pixels see similar integrands. Hair pixels see
//   different fibres, and on the hair shots it bought no FLIP at equal time
//   (docs/benchmarks.md, B-converge), hence not the default.
//
// With adaptive sampling, pixels stop at different counts, so a ZSobol layout
// of one fixed count per pixel would either leave neighbours that stop early
// without the blocks that complete their quad's net, or (with a layout sized
// for the largest count) give each pixel's first samples blocks far apart in
// the sequence, whose points nearly coincide. The samples are therefore split
// into levels, one per sampling pass: level 0 is the first pass's `first`
// samples, level j ≥ 1 the `first · 2^(j−1)` samples that double the count
// (indices first · 2^(j−1) ... first · 2^j − 1). Each level is a ZSobol layout
// of its own count with its own scrambles, so every pass's samples are blue
// noise across the pixels that take them, and the two half-buffers of the
// adaptive estimate (render/reference/adaptive_sampling.h) are each whole
// levels: stratified sets, and independent of each other.
#pragma once

#include "core/hash.h"
#include "render/reference/zsobol.h"

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
/// The second dimension's generator matrix applied a byte at a time: entry
/// [b][k] is the XOR of the matrix columns of the bits set in byte value k
/// at byte b of the index. Column j is v_j, v_0 = 2^31, v_(j+1) = v_j ⊕ (v_j >> 1).
struct Sobol1Table {
    uint32_t bytes[4][256];
};
constexpr Sobol1Table makeSobol1Table() {
    Sobol1Table t{};
    uint32_t columns[32] = {};
    columns[0] = 1u << 31;
    for (int j = 1; j < 32; ++j) columns[j] = columns[j - 1] ^ (columns[j - 1] >> 1);
    for (int b = 0; b < 4; ++b)
        for (uint32_t k = 0; k < 256; ++k) {
            uint32_t r = 0;
            for (int bit = 0; bit < 8; ++bit)
                if (k & (1u << bit)) r ^= columns[8 * b + bit];
            t.bytes[b][k] = r;
        }
    return t;
}
inline constexpr Sobol1Table kSobol1 = makeSobol1Table();
inline uint32_t sobol1(uint32_t i) {
    return kSobol1.bytes[0][i & 255u] ^ kSobol1.bytes[1][(i >> 8) & 255u] ^ kSobol1.bytes[2][(i >> 16) & 255u] ^
           kSobol1.bytes[3][i >> 24];
}

/// [0, 1) float from the top 24 bits.
inline float toUnit(uint32_t x) { return float(x >> 8) * (1.f / 16777216.f); }

/// How the pixels' samples are laid out in the sequences (see the file comment).
enum class SamplerType { ZSobol, Independent };

/// "zsobol" / "independent".
inline const char* samplerName(SamplerType type) { return type == SamplerType::ZSobol ? "zsobol" : "independent"; }

/// What the pixel samplers of one image share.
struct SamplerLayout {
    SamplerType type = SamplerType::Independent;
    uint64_t seed = 1;
    int frame = 0;
    uint32_t first = 1;      ///< zsobol: samples of level 0 (the first pass)
    int log2Resolution = 0;  ///< zsobol: log2 of the larger image side rounded up to a power of two

    static SamplerLayout make(SamplerType type, uint64_t seed, int frame, int width, int height, uint32_t first) {
        SamplerLayout l{type, seed, frame, std::max(first, 1u), 0};
        while ((1 << l.log2Resolution) < std::max(width, height)) ++l.log2Resolution;
        return l;
    }
};

/// Random numbers of one pixel sample. Dimensions are consumed in pairs; the
/// same (pixel key, sample index, call order) always gives the same numbers.
class PixelSampler {
  public:
    /// The independent layout: `seed` and `frame` select the sequence; (x, y) the pixel.
    PixelSampler(uint64_t seed, int frame, int x, int y)
        : PixelSampler(SamplerLayout{SamplerType::Independent, seed, frame}, x, y) {}

    PixelSampler(const SamplerLayout& layout, int x, int y)
        : layout_(layout),
          key_(hashCombine(mix64(layout.seed), uint64_t(uint32_t(layout.frame)))),
          morton_(encodeMorton2(uint32_t(x), uint32_t(y))) {
        // Independent: the pixel's own key. ZSobol: one key for the image
        // (the pixel's place is its Morton code), distinct from any pixel's.
        key_ = layout.type == SamplerType::Independent
                   ? hashCombine(hashCombine(key_, uint64_t(uint32_t(x))), uint64_t(uint32_t(y)))
                   : hashCombine(key_, kZSobol);
        levelKey_ = key_;
    }

    /// Starts sample `index` of the pixel (dimension counter back to 0).
    void start(uint32_t index) {
        index_ = index;
        dimension_ = 0;
        side_ = 0;
        if (layout_.type == SamplerType::ZSobol) startLevel(index);
    }

    /// The next stratified 2D point in [0, 1)^2.
    Eigen::Vector2f next2D() {
        const uint64_t h = hashCombine(levelKey_, dimension_++);
        const uint32_t i = shuffledIndex(h);
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
        const uint64_t h = hashCombine(levelKey_, kSide | side_++);
        return toUnit(owenScramble(sobol0(shuffledIndex(h)), uint32_t(h >> 32)));
    }

  private:
    /// The sample's index into the Sobol' sequence of dimension hash h.
    uint32_t shuffledIndex(uint64_t h) const {
        if (layout_.type == SamplerType::Independent) return owenScramble(index_, uint32_t(h));
        return zsobolIndex(mortonIndex_, log2Count_, digits_, h);
    }

    /// The level of sample `index` (see the file comment): its place in the
    /// level's layout and the level's scrambles.
    void startLevel(uint32_t index) {
        uint32_t level = 0, begin = 0, count = layout_.first;
        if (index >= layout_.first) {
            for (level = 1, count = layout_.first; index - count >= count; count *= 2) ++level;
            begin = count;
        }
        log2Count_ = 0;
        while ((1u << log2Count_) < count) ++log2Count_;
        mortonIndex_ = (morton_ << log2Count_) | uint64_t(index - begin);
        digits_ = zsobolDigits(layout_.log2Resolution, log2Count_);
        levelKey_ = hashCombine(key_, level);
    }

    SamplerLayout layout_;
    uint64_t key_;
    uint64_t morton_;
    uint64_t levelKey_;  ///< independent: the pixel's key; zsobol: the level's
    uint64_t mortonIndex_ = 0;
    int log2Count_ = 0, digits_ = 0;
    uint32_t index_ = 0;
    uint64_t dimension_ = 0;
    uint64_t side_ = 0;
    static constexpr uint64_t kSide = 1ull << 63;  ///< side dimensions never meet the main ones
    static constexpr uint64_t kZSobol = 0x7a736f626f6cull;
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
