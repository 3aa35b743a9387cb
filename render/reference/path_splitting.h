// @brief Efficiency-aware Russian roulette and splitting of the indirect path
// at the camera hit: how many independent indirect paths a pixel's camera
// samples continue with, chosen per pixel from the variance and the cost its
// first samples measured.
//
// After Vorba and Křivánek 2016, "Adjoint-driven Russian roulette and
// splitting in light transport simulation", and Rath, Yazici, Grittmann,
// Georgiev and Slusallek 2022, "EARS: Efficiency-aware Russian roulette and
// splitting", reduced to one decision a pixel at the first vertex: a camera
// sample X = D + I is its camera ray, first-hit shading and direct light D
// (cost c0) plus the indirect estimate I (cost c1). Continuing N indirect
// paths from the first hit, N drawn with E[N] = r independently of the
// paths, each weighted 1/r, keeps E[X] (E[Σ_k I_k / r] = E[N] E[I] / r).
// The rate that minimises variance × cost (the inverse efficiency) differs
// between pixels: shadowed hair is mostly indirect light, lit skin mostly
// direct, a background pixel has no first hit at all.
#pragma once

#include <cstdint>
#include <vector>

namespace hp {

/// Per-pixel sums over the training samples. Each training sample traces
/// two indirect paths from its camera hit, with estimates I₁ and I₂ (R + G +
/// B); Y = D + I₁ is then what a one-path sample would have been (D: the
/// camera hit's own light sampling), I = I₁ its indirect part, and
/// (I₁ − I₂)² / 2 has the mean E[Var(I | first hit)], the part of I's
/// variance that more paths from the same hit average out (the first hit's
/// own randomness, which fibre and where across it, they share). Costs are
/// of a one-path sample, whole and indirect part, in ray units
/// (render/reference/reference_shading.h, SampleResult::cost).
/// devY is the sum of squared deviations of Y from the pixel's own mean,
/// filled by centre(): pooled over several pixels it adds up the pixels'
/// variances, where raw sums of squares would add the differences between
/// the pixels' means (an edge between hair and skin) as if it were noise.
struct SplitStats {
    double n = 0.0;
    double sumY = 0.0, sumY2 = 0.0;
    double sumI2 = 0.0;       ///< Σ I²
    double sumSplit = 0.0;    ///< Σ (I₁ − I₂)² / 2
    double cost = 0.0, costIndirect = 0.0;
    double devY = 0.0;

    void add(double y, double i1, double i2, double cost, double indirectCost);
    void add(const SplitStats& o);
    /// Sets devY from this pixel's sums.
    void centre();
};

/// The rate r of indirect paths a camera sample continues with (r < 1:
/// Russian roulette of the indirect part; r > 1: splitting), clamped to
/// [minRate, maxRate]. With V = Var(Y) = devY / n (within pixels, after
/// centre()), M = E[I²] = sumI2 / n, W = E[Var(I | first hit)] =
/// sumSplit / n, c1 the indirect cost and c0 the rest:
/// - roulette (r ≤ 1): Var_r = V + M (1 − r) / r exactly (I survives with
///   probability r, weighted 1/r); Var_r (c0 + r c1) is least at
///   r = √(M c0 / ((V − M) c1)).
/// - splitting (r ≥ 1): Var_r = (V − W) + W / r for whole r (the paths are
///   independent given the first hit), least at r = √(W c0 / ((V − W) c1)).
/// Roulette is chosen when its optimum is below 1, else splitting when its
/// optimum is above 1, else 1. No indirect light or no samples: 1.
float efficientSplitRate(const SplitStats& s, float minRate, float maxRate);

/// The number of paths for rate r > 0: ⌊r⌋, plus one with probability
/// r − ⌊r⌋ (u uniform in [0, 1)), so that E[N] = r.
int splitCount(float rate, float u);

/// Each pixel's stats, centred, summed over the (2·radius + 1)² pixels around it
/// (clipped at the border): the rate is a property of a region, and 8
/// samples of one pixel are too few to estimate a variance ratio.
std::vector<SplitStats> poolSplitStats(const std::vector<SplitStats>& stats, int width, int height, int radius);

}  // namespace hp
