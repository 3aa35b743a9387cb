#include "sim/solver/length_kernels.h"

namespace hp::strand {

Vec3f followTheLeader(const Vec3f& parent, const Vec3f& child, float length) {
    const Vec3f e = child - parent;
    const float len = e.norm();
    // A collapsed segment keeps its length along an arbitrary (deterministic) axis.
    return len > 1e-12f ? Vec3f(parent + e * (length / len)) : Vec3f(parent + Vec3f::UnitY() * length);
}

void followTheLeader(Vec3f* x, const float* restLength, size_t vertexCount, Vec3f* correction) {
    if (correction && vertexCount > 0) correction[0] = Vec3f::Zero();
    for (size_t i = 0; i + 1 < vertexCount; ++i) {
        const Vec3f placed = followTheLeader(x[i], x[i + 1], restLength[i]);
        if (correction) correction[i + 1] = placed - x[i + 1];
        x[i + 1] = placed;
    }
}

void relieveCompression(Vec3f* x, const float* restLength, size_t vertexCount) {
    for (size_t i = 0; i + 1 < vertexCount; ++i)
        if ((x[i + 1] - x[i]).squaredNorm() < restLength[i] * restLength[i])
            x[i + 1] = followTheLeader(x[i], x[i + 1], restLength[i]);
}

}  // namespace hp::strand
