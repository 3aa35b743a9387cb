// Strand-strand contact kernel of the guides (sim/guides/strand_contacts.cpp
// finds the pairs with Bullet; this resolves one): a pure function with its
// governing equation.
#pragma once

#include "sim/strands/strand.h"

namespace hp::strand {

/// Pushes two segments apart along `normal` (from B to A) by `depth` at the
/// parameters s (on A: a0→a1) and t (on B), weighted by inverse masses w:
///   Δa_k = +w_ak·α_k·λ·n, Δb_k = -w_bk·β_k·λ·n,  λ = depth / Σ w·(weight)²,
/// with α = (1-s, s), β = (1-t, t) (position-based edge-edge contact).
void separateSegments(Vec3f& a0, Vec3f& a1, Vec3f& b0, Vec3f& b1, float s, float t, const Vec3f& normal,
                      float depth, const float w[4]);

}  // namespace hp::strand
