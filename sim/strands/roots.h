// Hair root placement on the scalp of a rest-pose mesh.
//
// Roots are SurfacePoints (triangle + barycentrics), so evaluate(pose.mesh,
// root) puts them on the deformed surface of every frame with a frame that
// turns with it. Two methods:
// - Fibonacci (Gomes 2024): the Fibonacci sphere lattice around a centre inside
//   the head, each direction projected radially onto the outermost surface
//   (a ray from outside toward the centre); directions whose hit is not on
//   the scalp are dropped, and the lattice is sized so that exactly `count`
//   land on it. Even in angle, so denser where the scalp is closer to the centre.
// - Blue noise: area-uniform candidates thinned by weighted sample
//   elimination (Yuksel 2015, "Sample Elimination for Generating Poisson
//   Disk Sample Sets"): even in area, no two roots close together.
// Guides and followers are placed by separate calls (independently).
// Both are deterministic for a seed and independent of the thread count.
#pragma once

#include "sim/strands/head.h"

#include <cstdint>
#include <optional>
#include <vector>

namespace hp {

/// @brief How roots are spread over the scalp: Gomes 2024's Fibonacci lattice,
/// or blue noise (Yuksel's sample elimination).
enum class RootMethod { Fibonacci, BlueNoise };

/// @brief Where and how many roots (scene keys hair.roots.*; pipeline/head/head_setup.h rootSettings).
struct RootSettings {
    RootMethod method = RootMethod::Fibonacci;
    size_t count = 0;
    uint64_t seed = 1;  ///< blue noise candidates (the Fibonacci lattice has no randomness)
    /// Fibonacci: centre of the lattice sphere; default: a least-squares
    /// sphere fitted to the scalp (the skull's centre for a cap-like scalp).
    std::optional<Vec3f> center;
    /// Fibonacci: the lattice's pole; default: the mean direction of the scalp
    /// from the centre (a scalp cap's own axis makes the lattice Gomes 2024's).
    std::optional<Vec3f> axis;
    /// Blue noise: candidates per root (Yuksel uses 3-5; more is slower and slightly more even).
    float candidateRatio = 4.f;
};

/// @brief Places `settings.count` roots on the triangles of `mesh` whose
/// `scalp` entry is non-zero (all when `scalp` is empty); Fibonacci roots
/// come in lattice order, blue-noise roots in candidate order.
/// Throws Error when the scalp is empty or the lattice cannot reach it.
std::vector<SurfacePoint> placeRoots(const TriangleMesh& mesh, const std::vector<uint8_t>& scalp,
                                     const RootSettings& settings);

/// Total area of the masked triangles (all when `mask` is empty), m².
double surfaceArea(const TriangleMesh& mesh, const std::vector<uint8_t>& mask = {});

/// @brief Least-squares sphere through `points` (algebraic fit: solve
/// 2 c·p + k = |p|² for c and k, r² = k + |c|²). False when degenerate
/// (coplanar or too few points).
bool fitSphere(const std::vector<Vec3f>& points, Vec3f& center, float& radius);

}  // namespace hp
