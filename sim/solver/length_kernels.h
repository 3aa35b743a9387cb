// Length kernels every strand model shares: pure functions that put a
// strand's segments back at their rest lengths (position-based, after
// PositionBasedDynamics), and the stretch measure the statistics report.
//
// Notation: x_i vertex positions (x_0 the root), l_i rest length of segment
// i = (x_i, x_{i+1}).
#pragma once

#include "sim/strands/strand.h"

#include <cmath>
#include <cstddef>

namespace hp::strand {

/// Follow-the-leader (Müller et al. 2012): places the child at exactly the rest
/// length from its already-placed parent, along the current direction:
///   x_{i+1} ← x_i + l_i · (x_{i+1} - x_i)/|x_{i+1} - x_i|.
Vec3f followTheLeader(const Vec3f& parent, const Vec3f& child, float length);

/// Follow-the-leader along a whole strand, root fixed. `correction[i]` (may
/// be null) receives x_i(after) - x_i(before), used for the velocity update.
void followTheLeader(Vec3f* x, const float* restLength, size_t vertexCount, Vec3f* correction = nullptr);

/// Follow-the-leader on compressed segments only: where |x_{i+1} - x_i| < l_i
/// the child is pushed out to l_i along the segment, root to tip; stretched
/// segments are left alone. Run before a mass-weighted link solve so that it
/// only sees tension: Gauss-Seidel on a compressed limp chain folds it into a
/// zig-zag (measured: 8° kinks at the root of a standing strand), whereas a
/// hair resists buckling through its bending stiffness.
void relieveCompression(Vec3f* x, const float* restLength, size_t vertexCount);

/// Stretch of segment (a, b): |l/l_rest - 1|, l = |b - a|.
inline float stretch(const Vec3f& a, const Vec3f& b, float rest) { return std::abs((b - a).norm() / rest - 1.f); }

}  // namespace hp::strand
