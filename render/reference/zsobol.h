// @brief ZSobol: one Owen-scrambled Sobol' sequence shared by all pixels of
// the image, each pixel taking a block of it in a shuffled Morton order
// (Ahmed and Wonka 2020, "Screen-space blue-noise diffusion of Monte Carlo
// sampling error via hierarchical ordering of pixels"; pbrt-v4's
// ZSobolSampler is the same design).
//
// Why: with a sequence per pixel (a hash of the pixel seeding it) the
// pixels' errors are independent, white noise. Here the 2×2 pixels of a
// Morton quad take four consecutive blocks of one sequence, and the four
// blocks together are a Sobol' net of four times the points: the quad's
// samples are stratified as a set, so where one pixel's points fall high in
// a stratum its neighbours' fall low, their errors are negatively
// correlated, and the error moves to high screen frequencies (blue noise),
// which the eye, and FLIP's contrast sensitivity filter, see less of. The
// same holds at every level of the Morton hierarchy (4×4 pixels, ...).
//
// The index of pixel (x, y)'s sample i among `count` samples a pixel is
//   m = Morton(x, y) · count + i,
// whose base-4 digits are then each permuted by one of the 24 permutations
// of {0, 1, 2, 3}, chosen by a hash of the digits above it and of the
// dimension: a random nested permutation that keeps every aligned block of
// indices an aligned block, so
// - a pixel's `count` samples are one aligned block of 2^k Sobol' points, a
//   (0, k, 2)-net (stratified in every elementary interval), and
// - the four pixels of a quad take the four blocks of an aligned block of
//   4 · 2^k points, a (0, k + 2, 2)-net,
// while which pixel of the quad takes which block changes from quad to quad
// and dimension to dimension (a binary scramble would always pair the
// horizontal neighbours, and the noise would be anisotropic). With an odd
// log2(count), the lowest bit is a digit of its own (flipped by a hash), so
// the base-4 digits stay aligned with the Morton digits (x bit, y bit).
#pragma once

#include <cstdint>

namespace hp::sampling {

/// Morton (Z-order) code: the bits of x and y interleaved, x in the even bits.
uint64_t encodeMorton2(uint32_t x, uint32_t y);

/// The shuffled index (low 32 bits: those the 32-bit Sobol' points use) of
/// `mortonIndex` = Morton(x, y) · 2^log2Count + i, which has `digits` base-4
/// digits above an odd log2Count's single bit; `dimensionHash` selects the
/// permutations (a different one for each dimension and seed).
uint32_t zsobolIndex(uint64_t mortonIndex, int log2Count, int digits, uint64_t dimensionHash);

/// Base-4 digits of Morton(x, y) · 2^log2Count for an image whose larger
/// side, rounded up to a power of two, is 2^log2Resolution (with an odd
/// log2Count they start at bit 1 and the last one ends at the top bit).
inline int zsobolDigits(int log2Resolution, int log2Count) { return log2Resolution + (log2Count + 1) / 2; }

}  // namespace hp::sampling
