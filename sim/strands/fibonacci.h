// The Fibonacci sphere lattice (González 2010), the root placement of Gomes 2024:
// n nearly uniform points on the unit sphere from the golden angle, of which
// a cap (the "scalp" of a sphere head) can be kept.
#pragma once

#include "sim/strands/strand.h"

#include <vector>

namespace hp {

/// The i-th of n lattice points on the unit sphere, i in [0, n): heights are
/// evenly spaced from +Y (i = 0) to -Y, longitudes step by the golden angle.
Vec3f fibonacciPoint(size_t i, size_t n);

/// `count` lattice directions inside the cap around `axis` with
/// dot(direction, axis) >= minCosine (minCosine = 0: the hemisphere). The
/// lattice is built over the whole sphere with enough points that exactly
/// `count` fall inside the cap, so the cap is covered as evenly as the sphere.
std::vector<Vec3f> fibonacciCap(size_t count, const Vec3f& axis = Vec3f::UnitY(), float minCosine = 0.f);

}  // namespace hp
