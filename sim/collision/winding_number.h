// Inside and outside of a closed mesh that may cross itself: the generalized
// winding number (Jacobson, Kavan & Sorkine-Hornung 2013, "Robust
// inside-outside segmentation using generalized winding numbers").
//
// Why: the sign of the closest triangle's pseudonormal (Bærentzen & Aanæs
// 2005) is exact only for a surface that does not cross itself. A skinned
// neck bent over its blend folds through itself, and there the closest
// triangle may be a sheet the fold buried, facing the wrong way. The winding
// number counts how many layers of the surface wrap a point: 0 outside, 1
// inside, 2 in the pocket a fold laps over, whatever the closest triangle is.
#pragma once

#include "sim/strands/head.h"

namespace hp {

class MeshQuery;

/// @brief Solid angle of triangle (a, b, c) seen from q, signed by its
/// winding (positive when q sees its back, i.e. q lies behind the face):
/// Van Oosterom & Strackee 1983, "The solid angle of a plane triangle",
/// with a = a - q, b = b - q, c = c - q:
///   tan(Ω/2) = a·(b × c) / (|a||b||c| + (a·b)|c| + (b·c)|a| + (c·a)|b|).
double solidAngle(const Vec3f& q, const Vec3f& a, const Vec3f& b, const Vec3f& c);

/// @brief The generalized winding number of `mesh` at q:
///   w(q) = Σ_t Ω_t(q) / 4π.
/// For a closed, outward-wound surface: 0 outside, 1 inside, n where n layers
/// wrap q (a fold), ½ on the surface. Exact, O(triangles).
double windingNumber(const TriangleMesh& mesh, const Vec3f& q);

/// @brief windingNumber, answered cheaply where a ray proves it is 0: a ray
/// from q along `direction` (unit) that leaves `query`'s BVH of `mesh`
/// without a hit crosses the closed surface no time, so w(q) = 0 (the
/// winding number of a closed surface changes only across it: Jordan-Brouwer).
/// Otherwise the exact sum. `query` is a MeshQuery over `mesh` as posed.
double windingNumber(const TriangleMesh& mesh, const MeshQuery& query, const Vec3f& q, const Vec3f& direction);

}  // namespace hp
