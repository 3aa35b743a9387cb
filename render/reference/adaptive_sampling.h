// @brief Adaptive sampling to a noise target, after Cycles (Blender's
// renderer): every pixel keeps the sum of all its samples and the sum of the
// first half of them; the difference of the two means estimates the pixel's
// error, and a pixel stops when that error is below the threshold.
//
// Why two half-buffers and not the sample variance: a firefly that has not
// happened yet leaves no trace in a variance, but two independent halves that
// disagree show it; and the estimate measures the error of the pixel's *mean*,
// which is what the image shows (Dammertz et al. 2010, "A hierarchical
// automatic stopping condition for Monte Carlo global illumination", §2.1).
//
// Why the *first* half: the sampler is an Owen-scrambled Sobol' sequence
// (render/reference/sampling.h), whose first 2^k points and whose next 2^k
// points are each a stratified net over the pixel. Even- and odd-indexed
// samples (Cycles' split for its own patterns) would each cover only half of
// the pixel here, and their disagreement would be coverage, not noise. So
// sample counts grow in powers of two, and after a pass to n samples the
// first n/2 are the previous pass's sum.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace hp {

/// Cycles' per-pixel error from the mean of all n samples I and the mean of
/// the first n/2 samples A (RGB, linear):
///   e = (|I_r − A_r| + |I_g − A_g| + |I_b − A_b|) / (10⁻⁴ + √(I_r + I_g + I_b)).
/// |I − A| = |B − A| / 2 for the two halves' means A and B: half their
/// distance, the standard error of I for Gaussian noise. Dividing by √I makes
/// it an error relative to the square root of the brightness, about what the
/// eye sees after a display transform; noise_threshold is this quantity.
float pixelError(const Eigen::Vector3d& meanAll, const Eigen::Vector3d& meanFirstHalf);

/// Marks as active every pixel within `radius` pixels (a square) of an
/// active one, as Cycles' filter passes do: a pixel beside unconverged ones
/// keeps sampling, which keeps error estimates that happen to be low by
/// chance from stopping a noisy region's pixels one by one.
/// `active` is width × height, row-major, 0 or 1.
void dilateActive(std::vector<uint8_t>& active, int width, int height, int radius = 1);

/// Smallest power of two ≥ n (n ≥ 1).
uint32_t ceilPowerOfTwo(uint32_t n);
inline bool isPowerOfTwo(uint32_t n) { return n && !(n & (n - 1)); }

}  // namespace hp
