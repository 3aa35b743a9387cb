// @brief Where a follower vertex goes when sliding along the surface cannot
// bring it out of the colliders at its segment length: a pinch (the nape
// folding onto the neck closes on the strand from two sides) or a parent
// vertex too close to a fold (issue 20).
//
// The order is the issue's: slide (follower::projectSegmentOut, run first by
// the caller), then bend, never stretch:
//   bend: the segment turns about its parent to the direction nearest the
//         one it wanted whose end is outside every collider,
//           u* = argmax_{|u| = 1, φ(x_p + L u) >= r} u · u_wanted,
//         found on a fixed lattice of directions, else by climbing φ on the
//         sphere of directions (the gap of a pinch can be thinner than the
//         lattice's spacing), and refined by bisection along the great
//         circle toward u_wanted (sim/collision/segment_escape.h);
//   pin:  when no direction is outside, the vertex is held at its length
//         at the least deep place the climb finds from its last place (its
//         position in the previous frame) and from the least deep lattice
//         direction, the last place's on a tie; counted as pinned (and as
//         inside, with its depth, when it is).
// The segment length is exact in every case: x = x_p + L u with |u| = 1.
#pragma once

#include "sim/strands/head.h"

namespace hp::follower {

/// What placePinched did with a vertex.
struct PinchPlace {
    Vec3f position = Vec3f::Zero();
    float distance = 0.f;  ///< signed distance at `position` (< 0: still inside)
    bool pinned = false;   ///< no place outside at the segment's length
};

/// Places the end of the segment of `length` from `parent` outside
/// `collider` (signed distance >= `radius`), bending the segment as little
/// as possible away from `wanted` (the end's position before collision).
/// `last` (may be null): the vertex's position in the previous frame, where
/// a pinned vertex is held. Deterministic: the same inputs give the same bits.
PinchPlace placePinched(const Collider& collider, const Vec3f& parent, float length, float radius,
                        const Vec3f& wanted, const Vec3f* last);

}  // namespace hp::follower
