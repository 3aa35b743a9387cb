// Helpers shared by the follower tests.
#pragma once

#include "sim/strands/head.h"
#include "sim/strands/synthetic_groom.h"

#include <vector>

namespace hp::test {

/// A surface frame at `position` with unit `normal` and `tangent` made
/// orthogonal to it.
inline SurfaceFrame frameAt(const Vec3f& position, const Vec3f& normal, const Vec3f& tangent) {
    SurfaceFrame f;
    f.position = position;
    f.normal = normal.normalized();
    f.tangent = (tangent - f.normal * f.normal.dot(tangent)).normalized();
    return f;
}

/// A sphere groom (the synthetic_groom defaults) with `guides` guides and
/// `followers` followers.
inline FollowerGroom sphereGroom(size_t guides, size_t followers) {
    SphereGroomSettings s;
    s.guides = guides;
    s.followers = followers;
    return makeSphereGroom(s);
}

/// The follower tests' sphere scene at time t: a sphere groom of `guides`
/// guides and `followers` followers, its guides as SyntheticGuides draws
/// them (lying over the head, differing a lot between neighbours at the
/// crown) and the follower roots turned with the head.
struct SphereScene {
    FollowerGroom groom;
    StrandFrame guides;
    std::vector<SurfaceFrame> guideRoots, followerRoots;

    SphereScene(size_t guideCount, size_t followerCount, double t) {
        groom = sphereGroom(guideCount, followerCount);
        const SyntheticGuides motion(groom, {});
        motion.sample(t, guides, guideRoots);
        rotateRoots(groom.followerRoots, motion.headRotation(t), followerRoots);
    }
};

}  // namespace hp::test
