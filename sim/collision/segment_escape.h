// Where the end of a segment hinged at its parent can go when sliding along
// one surface cannot bring it out: a pinch, two surfaces closing on the
// strand from two sides (the nape folding onto the neck; on a head that
// folds into itself, the head sphere tipping onto its own neck).
//
// The solid is what the strand collides with, φ its signed distance
// (negative inside; for a head of several parts the union's, φ = min_k φ_k,
// sim/collision/mesh_parts.h). The end of a segment of length L about the
// parent p is x(u) = p + L·u, |u| = 1, and the rule is
//   outside:  u* = argmax_{|u| = 1, φ(x(u)) >= r} u·u_w   (nearest the wanted direction u_w)
//   else:     u* = argmax_{|u| = 1} φ(x(u))             (the least deep place)
// Projecting along the normal of one part (the gradient of the part that
// holds the point deepest) pushes into the other part where two close on
// the strand; the places outside both are a thin band about the crease,
// the gap between them, which a lattice of directions alone can miss. So the
// search is: a fixed lattice of directions, then, when none is outside, a
// compass search on the sphere of directions climbing φ from the least
// deep lattice direction and from the wanted one (a direct search:
// φ = min_k φ_k has a kink along the crease, where a gradient step of one
// part oscillates), and bisection along the great circle toward u_w from
// the outside direction found. Deterministic: the same inputs give the same
// bits on every call and thread.
#pragma once

#include "sim/strands/head.h"

namespace hp {

/// What escapeSegment found.
struct SegmentEscape {
    Vec3f position = Vec3f::Zero();  ///< parent + L·u*, at the segment's exact length
    float distance = 0.f;            ///< φ at `position`
    bool outside = false;            ///< φ(position) >= r: a place outside was found
};

/// The end of the segment of `length` from `parent` by the rule above:
/// outside `collider` with clearance `radius` and nearest the direction of
/// `wanted`, else the least deep place. Whether a place outside is found,
/// and which, depends on the present alone (parent, length, wanted, the
/// collider). `held` (may be null): where a vertex with no place outside
/// would rather stay (its last place): the climb to the least deep place
/// then starts from its direction too, and keeps what it reaches unless
/// another start reaches a place less deep by more than 10 µm.
SegmentEscape escapeSegment(const Collider& collider, const Vec3f& parent, float length, float radius,
                            const Vec3f& wanted, const Vec3f* held);

}  // namespace hp
