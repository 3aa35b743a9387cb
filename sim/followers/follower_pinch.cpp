// Bending and pinning of follower vertices caught in a pinch
// (sim/followers/follower_pinch.h has the rule). Rare: only vertices the
// slide left inside come here, so this favours robustness over speed (about
// two hundred collider queries a vertex).
#include "sim/followers/follower_pinch.h"

#include "sim/strands/fibonacci.h"

#include <array>
#include <cmath>
#include <limits>

namespace hp::follower {

namespace {

/// Directions tried for a bent segment: the Fibonacci lattice (about 13°
/// apart, 2 mm at the end of a 1 cm segment), fixed so results are the same
/// bits on every call and thread.
constexpr size_t kDirections = 192;

const std::array<Vec3f, kDirections>& latticeDirections() {
    static const std::array<Vec3f, kDirections> dirs = [] {
        std::array<Vec3f, kDirections> d;
        for (size_t i = 0; i < kDirections; ++i) d[i] = fibonacciPoint(i, kDirections);
        return d;
    }();
    return dirs;
}

/// Bisection steps between a valid lattice direction and the wanted one:
/// 13° / 2^8, a few hundredths of a millimetre at the segment's end.
constexpr int kRefine = 8;

/// Unit direction at fraction t of the great circle from a to b (|a| = |b| = 1, a ≠ -b).
Vec3f along(const Vec3f& a, const Vec3f& b, float t) {
    const float angle = std::atan2(a.cross(b).norm(), a.dot(b));
    const float s = std::sin(angle);
    if (s < 1e-6f) return a;
    const Vec3f d = (std::sin((1.f - t) * angle) / s) * a + (std::sin(t * angle) / s) * b;
    return d.normalized();
}

}  // namespace

PinchPlace placePinched(const Collider& collider, const Vec3f& parent, float length, float radius,
                        const Vec3f& wanted, const Vec3f* last) {
    Vec3f u = wanted - parent;
    const float n = u.norm();
    u = n > 0.f ? Vec3f(u / n) : Vec3f::UnitY();
    auto at = [&](const Vec3f& dir) { return Vec3f(parent + length * dir); };

    // Bend: the valid lattice direction nearest u, least deep as a fallback.
    int best = -1, deepest = 0;
    float bestCos = -2.f, bestDepth = -std::numeric_limits<float>::infinity();
    const std::array<Vec3f, kDirections>& dirs = latticeDirections();
    for (size_t i = 0; i < kDirections; ++i) {
        const float d = collider.signedDistance(at(dirs[i]));
        const float c = dirs[i].dot(u);
        if (d >= radius && c > bestCos) best = int(i), bestCos = c;
        if (d > bestDepth) deepest = int(i), bestDepth = d;
    }
    PinchPlace out;
    if (best >= 0) {
        // Refine toward u along the great circle: lo stays outside.
        const Vec3f b = dirs[size_t(best)];
        Vec3f lo = b;
        if (bestCos > -0.99f) {
            float tLo = 0.f, tHi = 1.f;
            for (int k = 0; k < kRefine; ++k) {
                const float t = 0.5f * (tLo + tHi);
                const Vec3f d = along(b, u, t);
                if (collider.signedDistance(at(d)) >= radius) tLo = t, lo = d;
                else tHi = t;
            }
        }
        out.position = at(lo);
        out.distance = collider.signedDistance(out.position);
        return out;
    }
    // Pin: no direction is outside. Held at its length toward its last place
    // (the previous frame), else toward the least deep direction.
    out.pinned = true;
    out.position = at(dirs[size_t(deepest)]);
    out.distance = bestDepth;
    if (last) {
        const Vec3f toward = *last - parent;
        const float m = toward.norm();
        if (m > 0.f) {
            out.position = at(toward / m);
            out.distance = collider.signedDistance(out.position);
        }
    }
    return out;
}

}  // namespace hp::follower
