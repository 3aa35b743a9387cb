// The rod step's linear system (sim/guides/rod_step.cpp): J W Jᵀ + α̃ of one
// strand's constraint rows, banded and symmetric positive definite, solved
// by LDLᵀ for four strands at once, one per SIMD lane (sim/guides/rod_lanes.h).
//
// Layout: rows ordered (bend a, bend b, stretch) per joint; lane-major band,
// the four strands' A(r, r-k) (k = 0..kBand) at band[r·kRowLen + k].
#pragma once

#include "sim/guides/rod_lanes.h"

#include <algorithm>

namespace hp::rod {

/// Bandwidth: joints j and k share a vertex iff |j - k| ≤ 2, so A(r, s) = 0
/// for |r - s| > 3·2 + 2.
constexpr int kBand = 8;
constexpr int kRowLen = kBand + 1;

/// First column of row i's envelope: a bend row of joint j shares vertex
/// j-1 with the rows of joint j-2 (first column 3(j-2)); a stretch row
/// (vertices j, j+1) meets joint j-1 at the earliest (3(j-1)). LDLᵀ fills
/// only inside this envelope, so the factorization skips the zeros of the
/// band (the same sums, without the terms that are exactly zero).
inline int envelopeStart(int i) {
    const int j = i / 3;
    return std::max(0, i - 3 * j == 2 ? 3 * j - 3 : 3 * j - 6);
}

/// Banded LDLᵀ in place for the four lanes' systems of n rows: L(i, i-k)
/// (k > 0) replaces A(i, i-k), invD receives 1/D(i), then L D Lᵀ z = rhs is
/// solved in place:
///   D_i = A_ii - Σ_m L_im² D_m,  L_ij = (A_ij - Σ_m L_im D_m L_jm) / D_j,
/// the sums over the envelope (envelopeStart), in increasing m.
void bandedSolve(lanes::D4* band, lanes::D4* invD, lanes::D4* rhs, int n);
/// bandedSolve's two halves: the factorization (band, invD), then the
/// substitutions with it, as often as wanted (the holonomy's iterations,
/// rod_holonomy.cpp, precondition with it).
void bandedFactor(lanes::D4* band, lanes::D4* invD, int n);
void bandedSubstitute(const lanes::D4* band, const lanes::D4* invD, lanes::D4* rhs, int n);
/// bandedSubstitute with the back substitution's sums in the opposite order
/// (its rounding differs, its latency is a quarter): the holonomy's
/// preconditioner, where no result depends on that order's bits.
void bandedPrecondition(const lanes::D4* band, const lanes::D4* invD, lanes::D4* rhs, int n);

}  // namespace hp::rod
