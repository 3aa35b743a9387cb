// Bending and pinning of follower vertices caught in a pinch
// (sim/followers/follower_pinch.h has the rule; the search is
// sim/collision/segment_escape.h's).
#include "sim/followers/follower_pinch.h"

#include "sim/collision/segment_escape.h"

namespace hp::follower {

PinchPlace placePinched(const Collider& collider, const Vec3f& parent, float length, float radius,
                        const Vec3f& wanted, const Vec3f* last) {
    const SegmentEscape e = escapeSegment(collider, parent, length, radius, wanted, last);
    PinchPlace out;
    out.position = e.position;
    out.distance = e.distance;
    out.pinned = !e.outside;
    return out;
}

}  // namespace hp::follower
