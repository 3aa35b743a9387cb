// Helpers shared by the follower tests.
#pragma once

#include "sim/strands/head.h"

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

}  // namespace hp::test
