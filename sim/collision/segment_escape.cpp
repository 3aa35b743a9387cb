// The pinch search of segment_escape.h. Rare: only vertices that sliding
// leaves inside come here, so it favours robustness over speed (a few
// hundred collider queries a vertex).
#include "sim/collision/segment_escape.h"

#include "sim/strands/fibonacci.h"

#include <array>
#include <cmath>
#include <limits>

namespace hp {

namespace {

/// Directions tried first: the Fibonacci lattice (about 13° apart, 2 mm at
/// the end of a 1 cm segment), fixed so results are the same bits on every
/// call and thread.
constexpr size_t kDirections = 192;

const std::array<Vec3f, kDirections>& latticeDirections() {
    static const std::array<Vec3f, kDirections> dirs = [] {
        std::array<Vec3f, kDirections> d;
        for (size_t i = 0; i < kDirections; ++i) d[i] = fibonacciPoint(i, kDirections);
        return d;
    }();
    return dirs;
}

/// Bisection steps between an outside direction and the wanted one:
/// 13° / 2^8, a few hundredths of a millimetre at the segment's end.
constexpr int kRefine = 8;

/// The compass search: first step 0.2 rad (about the lattice's spacing),
/// halved when no neighbour climbs, down to 1e-3 rad (10 µm at 1 cm);
/// at most kClimbRounds moves or halvings.
constexpr float kClimbStart = 0.2f, kClimbEnd = 1e-3f;
constexpr int kClimbRounds = 64, kClimbNeighbours = 8;

/// A tie between two least deep places, m: within it the held one is kept.
constexpr float kTie = 1e-5f;
/// The least climb a compass move must make, m: above float rounding of φ,
/// so a flat φ (a pocket as deep everywhere) leaves the start where it is.
constexpr float kClimbGain = 1e-7f;

/// Unit direction at fraction t of the great circle from a to b (|a| = |b| = 1, a ≠ -b).
Vec3f along(const Vec3f& a, const Vec3f& b, float t) {
    const float angle = std::atan2(a.cross(b).norm(), a.dot(b));
    const float s = std::sin(angle);
    if (s < 1e-6f) return a;
    const Vec3f d = (std::sin((1.f - t) * angle) / s) * a + (std::sin(t * angle) / s) * b;
    return d.normalized();
}

struct Climb {
    Vec3f dir;
    float phi;
};

/// Climbs f(u) = φ(p + L·u) on the unit sphere from `u` by compass search:
/// the kNeighbours directions u + tan(δ)(cos θ_k t1 + sin θ_k t2) about u
/// (t1, t2 ⊥ u), the best one taken if it climbs, else δ halved. Stops once
/// f >= goal (a place outside is found).
template <class F>
Climb climb(const F& f, Vec3f u, float phi, float goal) {
    float step = kClimbStart;
    for (int round = 0; round < kClimbRounds && step > kClimbEnd && phi < goal; ++round) {
        const Vec3f t1 = u.unitOrthogonal(), t2 = u.cross(t1);
        const float reach = std::tan(step);
        Vec3f bestDir = u;
        float best = phi;
        for (int k = 0; k < kClimbNeighbours; ++k) {
            const float theta = 2.f * float(M_PI) * float(k) / float(kClimbNeighbours);
            const Vec3f d = (u + reach * (std::cos(theta) * t1 + std::sin(theta) * t2)).normalized();
            const float v = f(d);
            if (v > best) best = v, bestDir = d;
        }
        if (best > phi + kClimbGain) u = bestDir, phi = best;
        else step *= 0.5f;
    }
    return {u, phi};
}

}  // namespace

SegmentEscape escapeSegment(const Collider& collider, const Vec3f& parent, float length, float radius,
                            const Vec3f& wanted, const Vec3f* held) {
    Vec3f u = wanted - parent;
    const float n = u.norm();
    u = n > 0.f ? Vec3f(u / n) : Vec3f::UnitY();
    auto at = [&](const Vec3f& dir) { return Vec3f(parent + length * dir); };
    auto phi = [&](const Vec3f& dir) { return collider.signedDistance(at(dir)); };

    // The outside lattice direction nearest u; the least deep one.
    int best = -1, deepest = 0;
    float bestCos = -2.f, bestDepth = -std::numeric_limits<float>::infinity();
    const std::array<Vec3f, kDirections>& dirs = latticeDirections();
    for (size_t i = 0; i < kDirections; ++i) {
        const float d = phi(dirs[i]);
        const float c = dirs[i].dot(u);
        if (d >= radius && c > bestCos) best = int(i), bestCos = c;
        if (d > bestDepth) deepest = int(i), bestDepth = d;
    }
    Vec3f outsideDir = best >= 0 ? dirs[size_t(best)] : Vec3f::Zero();
    Climb least{dirs[size_t(deepest)], bestDepth};
    if (best < 0) {
        // None outside: climb φ from the least deep lattice direction, then
        // from the wanted one; the first to get out gives the direction.
        // Neither depends on `held`, so whether a place outside exists, and
        // which, is a function of the present alone (followers rebuilt from
        // the cache record only where the pinned vertices were held).
        const Climb fromLattice = climb(phi, least.dir, least.phi, radius);
        const Climb fromWanted = fromLattice.phi >= radius ? fromLattice : climb(phi, u, phi(u), radius);
        if (fromLattice.phi >= radius) outsideDir = fromLattice.dir;
        else if (fromWanted.phi >= radius) outsideDir = fromWanted.dir;
        least = fromWanted.phi > fromLattice.phi ? fromWanted : fromLattice;
        // No place outside: the least deep place climbed to from the held
        // one, unless another is less deep by more than a tie.
        if (outsideDir.squaredNorm() == 0.f && held && (*held - parent).norm() > 0.f) {
            const Vec3f h = (*held - parent).normalized();
            const Climb fromHeld = climb(phi, h, phi(h), radius);
            if (fromHeld.phi + kTie >= least.phi) least = fromHeld;
        }
    }
    SegmentEscape out;
    if (outsideDir.squaredNorm() > 0.f) {
        // Refine toward u along the great circle: lo stays outside.
        Vec3f lo = outsideDir;
        if (outsideDir.dot(u) > -0.99f) {
            float tLo = 0.f, tHi = 1.f;
            for (int k = 0; k < kRefine; ++k) {
                const float t = 0.5f * (tLo + tHi);
                const Vec3f d = along(outsideDir, u, t);
                if (phi(d) >= radius) tLo = t, lo = d;
                else tHi = t;
            }
        }
        out.position = at(lo);
        out.distance = collider.signedDistance(out.position);
        out.outside = true;
        return out;
    }
    out.position = at(least.dir);
    out.distance = least.phi;
    return out;
}

}  // namespace hp
