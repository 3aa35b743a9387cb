#include "sim/solver/strand_state.h"

#include <algorithm>

namespace hp::strand {

Mat3f rootRotation(const SurfaceFrame& frame) {
    const float nl = frame.normal.norm();
    const Vec3f n = nl > 1e-12f ? Vec3f(frame.normal / nl) : Vec3f::UnitY();
    Vec3f t = frame.tangent - n * n.dot(frame.tangent);
    t = t.squaredNorm() > 1e-12f ? Vec3f(t.normalized()) : Vec3f(n.unitOrthogonal());
    Mat3f r;
    r.col(0) = t;
    r.col(1) = n;
    r.col(2) = t.cross(n);
    return r;
}

}  // namespace hp::strand

namespace hp::solver {

void StrandState::resize(const std::vector<SurfaceFrame>& roots, int vertexCount) {
    count = roots.size();
    vertices = vertexCount;
    const size_t n = count * size_t(vertices);
    x.assign(n, Vec3f::Zero());
    v.assign(n, Vec3f::Zero());
    rootPos0.resize(count);
    rootPos1.resize(count);
    rootRot0.resize(count);
    rootRot1.resize(count);
    setRoots(roots, true);
}

void StrandState::setRoots(const std::vector<SurfaceFrame>& roots, bool start) {
    for (size_t g = 0; g < count; ++g) {
        rootPos1[g] = roots[g].position;
        rootRot1[g] = strand::Quatf(strand::rootRotation(roots[g]));
        if (start) {
            rootPos0[g] = rootPos1[g];
            rootRot0[g] = rootRot1[g];
        }
    }
}

float StrandState::rootJump() const {
    float jump = 0.f;
    for (size_t g = 0; g < count; ++g) jump = std::max(jump, (rootPos1[g] - rootPos0[g]).norm());
    return jump;
}

void StrandState::advanceRoots() {
    for (size_t g = 0; g < count; ++g) {
        rootPos0[g] = rootPos1[g];
        rootRot0[g] = rootRot1[g];
    }
}

void StrandState::save(BlobWriter& w) const {
    w.array(x);
    w.array(v);
    w.array(xPrev);
    w.array(vPrev);
    w.array(rootPos0);
    w.array(rootPos1);
    w.array(rootRot0);
    w.array(rootRot1);
}

void StrandState::restore(BlobReader& r) {
    const size_t n = count * size_t(vertices);
    r.array(x, n);
    r.array(v, n);
    r.array(xPrev, n);
    r.array(vPrev, n);
    r.array(rootPos0, count);
    r.array(rootPos1, count);
    r.array(rootRot0, count);
    r.array(rootRot1, count);
}

}  // namespace hp::solver
