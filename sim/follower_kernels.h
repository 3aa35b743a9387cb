// @brief Pure per-segment kernels of the follower strands (seed 000,
// Algorithm 1), testable without a groom or a frame.
//
// Conventions shared by every function here and by sim/followers.h:
// - A root frame is the matrix R = [t, n, t × n] of a SurfaceFrame (tangent,
//   normal, tangent × normal): local x = tangent, y = normal, z = t × n. So a
//   strand that is straight along the normal has local directions (0, 1, 0).
// - Quaternions are (w, x, y, z) with w the scalar part, unit length.
// - The rotation of guide segment y is expressed in that guide's root frame:
//   it takes the segment's rest direction to its current direction, with the
//   twist fixed by parallel transport along the strand (segmentRotation).
//
// Everything is inline and scalar: the follower update calls these inside
// loops over a strand's segments that the compiler vectorizes.
#pragma once

#include "sim/head.h"

#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>

namespace hp::follower {

// Force inlining: these run inside vectorized loops, also in the AVX2 build
// of the follower update, where an out-of-line call would stop vectorization.
#define HP_FOLLOWER_KERNEL inline __attribute__((always_inline))

// ---------------------------------------------------------------------------
// Algorithm 1's displacement: d_r = fixedOffset * d_f(y) + rand_xy * d_v.

/// Fixed offset of segment y of a strand of S segments:
///   d_f(y) = 1 - (y - qs)^2 / qs^2,   qs = (S - 1) / 2.
/// The seed writes qs = "half the segment count" with its 23 segments indexed
/// 0..22: in integer arithmetic 23 / 2 = 11 = (23 - 1) / 2, which gives
/// d_f(0) = d_f(2 qs) = d_f(22) = 0 (root and tip follow the nearest guide)
/// and d_f(11) = 1, the symmetric curve of its Figure 4.11. Writing qs as
/// (S - 1) / 2 keeps that symmetry for any segment count (for even S the peak
/// falls between the two middle segments). S < 2 gives 0.
HP_FOLLOWER_KERNEL float fixedOffsetCurve(float y, float segments) {
    if (segments < 2.f) return 0.f;
    const float qs = 0.5f * (segments - 1.f);
    const float u = (y - qs) / qs;
    return 1.f - u * u;
}

/// Variable offset: d_v = clamp(|v|, 0, maxVelocity), |v| in m/s (the seed
/// clamps the nearest guide's speed to [0, 0.1]).
HP_FOLLOWER_KERNEL float variableOffset(float speed, float maxVelocity) {
    return speed < maxVelocity ? (speed > 0.f ? speed : 0.f) : maxVelocity;
}

/// Resulting slerp weight of Algorithm 1: d_r = fixed * d_f + rand * d_v.
/// May leave [0, 1] (rand < 0 near root and tip); slerpWeights extrapolates
/// along the same great circle rather than clamping, so the variation stays
/// symmetric about the fixed-offset curve.
HP_FOLLOWER_KERNEL float variedWeight(float fixedOffset, float df, float random, float dv) {
    return fixedOffset * df + random * dv;
}

/// Interpolation mode's weight from the root distances to the nearest (d1)
/// and second nearest (d2) guide: t = d1 / (d1 + d2), in [0, 1/2]; 0 on top of
/// the nearest guide, 1/2 half way between the two.
HP_FOLLOWER_KERNEL float interpolationWeight(float d1, float d2) {
    const float sum = d1 + d2;
    return sum > 0.f ? d1 / sum : 0.f;
}

// ---------------------------------------------------------------------------
// rand_xy: a value in [-1, 1) fixed per (seed, follower, segment), made by
// hashing instead of storing 23 floats per follower or carrying RNG state.

/// MurmurHash3's 32-bit finaliser: a bijection with full avalanche.
HP_FOLLOWER_KERNEL uint32_t mix32(uint32_t h) {
    h ^= h >> 16;
    h *= 0x85ebca6bu;
    h ^= h >> 13;
    h *= 0xc2b2ae35u;
    h ^= h >> 16;
    return h;
}

/// Per-follower part of the hash (computed once per follower and update).
HP_FOLLOWER_KERNEL uint32_t followerHash(uint32_t seed, uint32_t follower) {
    return mix32(seed * 0x9e3779b9u ^ mix32(follower + 0x7f4a7c15u));
}

/// rand_xy for segment y of the follower with hash `base`: in [-1, 1).
HP_FOLLOWER_KERNEL float segmentRandom(uint32_t base, uint32_t y) {
    const uint32_t h = mix32(base + y * 0x27d4eb2fu);
    return float(int32_t(h)) * (1.f / 2147483648.f);
}

// ---------------------------------------------------------------------------
// Slerp, branch-free (Eberly 2011, "A fast and accurate algorithm for
// computing SLERP"): with x = cos θ >= 0,
//   slerp(q0, q1, t) = c0 q0 + c1 q1,   c0 = s(1 - t), c1 = s(t),
//   s(t) = sin(tθ) / sin θ = t Π_{i=1..8} (1 + (u_i t² - v_i)(x - 1)),
//   u_i = 1 / (i (2i + 1)), v_i = i / (2i + 1), the last pair scaled by
//   μ = 1.85298109 to absorb the truncated tail.
// The products are the nested form of the power series of s in (x - 1). No
// acos/sin: a few dozen multiply-adds that vectorize. Measured error of s
// against double precision for t in [-1, 2]: 2.4e-7 for x >= 0.7 (guides
// within 90° of each other), 1.2e-6 for x >= 0.5, 3e-5 at x = 0 (opposite
// rotations); followers renormalise each direction, so lengths stay exact.

HP_FOLLOWER_KERNEL float slerpSeries(float t, float xm1) {
    constexpr float mu = 1.85298109240830f;
    constexpr float u[8] = {1.f / (1 * 3), 1.f / (2 * 5), 1.f / (3 * 7),  1.f / (4 * 9),
                            1.f / (5 * 11), 1.f / (6 * 13), 1.f / (7 * 15), mu / (8 * 17)};
    constexpr float v[8] = {1.f / 3, 2.f / 5, 3.f / 7, 4.f / 9, 5.f / 11, 6.f / 13, 7.f / 15, mu * 8 / 17};
    const float t2 = t * t;
    float b = 1.f;
#pragma GCC unroll 8
    for (int i = 7; i >= 0; --i) b = 1.f + (u[i] * t2 - v[i]) * xm1 * b;
    return t * b;
}

/// Coefficients (c0, c1) of slerp(q0, q1, t) = c0 q0 + c1 q1, given
/// dot = q0 · q1. The shorter arc is taken: for dot < 0, c1 comes back negated
/// (as if q1 were -q1, the same rotation).
HP_FOLLOWER_KERNEL void slerpWeights(float dot, float t, float& c0, float& c1) {
    const float sign = dot < 0.f ? -1.f : 1.f;
    const float xm1 = dot * sign - 1.f;
    c0 = slerpSeries(1.f - t, xm1);
    c1 = slerpSeries(t, xm1) * sign;
}

/// Rotates v by the unit quaternion (w, x, y, z):
///   v' = v + w τ + u × τ,   τ = 2 u × v,   u = (x, y, z).
HP_FOLLOWER_KERNEL void rotate(float w, float x, float y, float z, float vx, float vy, float vz, float& ox, float& oy,
                   float& oz) {
    const float tx = 2.f * (y * vz - z * vy);
    const float ty = 2.f * (z * vx - x * vz);
    const float tz = 2.f * (x * vy - y * vx);
    ox = vx + w * tx + (y * tz - z * ty);
    oy = vy + w * ty + (z * tx - x * tz);
    oz = vz + w * tz + (x * ty - y * tx);
}

// ---------------------------------------------------------------------------
// Segment rotations of a guide (per guide and step, a few hundred flops).

/// A quaternion (w, x, y, z) in float, with the few operations the guide
/// tables need written out (Eigen's double quaternions cost 3x as much here).
struct Quat {
    float w = 1.f, x = 0.f, y = 0.f, z = 0.f;
};

/// Hamilton product a b (apply b, then a).
HP_FOLLOWER_KERNEL Quat operator*(const Quat& a, const Quat& b) {
    return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
            a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

HP_FOLLOWER_KERNEL Quat conjugate(const Quat& q) { return {q.w, -q.x, -q.y, -q.z}; }

/// The minimal rotation (swing) taking unit a to unit b:
///   q = (1 + a·b, a × b) / sqrt(2 (1 + a·b))
/// (the norm of (1 + c, a × b) is sqrt((1 + c)² + 1 - c²)). Opposite
/// vectors: a half turn about any axis perpendicular to a.
inline Quat swing(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
    const float c = a.dot(b);
    if (c < -1.f + 1e-6f) {
        const Eigen::Vector3f axis = a.unitOrthogonal();
        return {0.f, axis.x(), axis.y(), axis.z()};
    }
    const Eigen::Vector3f s = a.cross(b);
    const float k = 1.f / std::sqrt(2.f * (1.f + c));
    return {(1.f + c) * k, s.x() * k, s.y() * k, s.z() * k};
}

/// The same in double, for build-time frame comparisons.
inline Eigen::Quaterniond swing(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    const double c = a.dot(b);
    if (c < -1.0 + 1e-12) {
        const Eigen::Vector3d axis = a.unitOrthogonal();
        return Eigen::Quaterniond(0.0, axis.x(), axis.y(), axis.z());
    }
    const Eigen::Vector3d s = a.cross(b);
    const double k = 1.0 / std::sqrt(2.0 * (1.0 + c));
    return Eigen::Quaterniond((1.0 + c) * k, s.x() * k, s.y() * k, s.z() * k);
}

/// Parallel-transported frame of segment y of a polyline with unit
/// directions d_0..d_y in root-frame coordinates:
///   F_0 = swing(n, d_0),   F_y = swing(d_{y-1}, d_y) F_{y-1},   n = (0, 1, 0).
/// F_y takes the root normal to d_y and turns as little as possible along
/// the way; it is defined for any strand whose consecutive segments never
/// fold back completely, so it has no singular pose the way a rotation built
/// from a fixed axis would. Renormalised each step (23 float products would
/// otherwise drift by ~1e-6).
inline Quat transportStep(const Quat& previousFrame, const Eigen::Vector3f& previousDir, const Eigen::Vector3f& dir) {
    Quat f = swing(previousDir, dir) * previousFrame;
    const float k = 1.f / std::sqrt(f.w * f.w + f.x * f.x + f.y * f.y + f.z * f.z);
    return {f.w * k, f.x * k, f.y * k, f.z * k};
}

/// Rotation of a guide segment in its root frame: q_y = C_y P_y^{-1}, where
/// P_y and C_y are the transported frames of the rest and the current strand.
/// q_y takes the rest direction r_y to the current one c_y (P_y^{-1} r_y = n,
/// C_y n = c_y); at rest q_y = 1 for any rest shape, and its twist is the one
/// transport accumulates, the same for neighbouring guides that bend alike,
/// so slerping between two guides' q_y is meaningful.
HP_FOLLOWER_KERNEL Quat segmentRotation(const Quat& currentFrame, const Quat& restFrameInverse) {
    return currentFrame * restFrameInverse;
}

// ---------------------------------------------------------------------------
// Head collision after interpolation (follow-the-leader).

/// Moves vertex p, the end of a segment of `length` from `previous` (already
/// outside), out of the head when its signed distance `distance` (gradient
/// `normal`) is below `radius`, keeping the segment length: with c the point
/// pushed onto the offset surface, c = p + (radius - distance + ε) n, the
/// head's tangent plane there is approximated as the limit, and the segment
/// direction u nearest the current one with
///   n · (previous + length u - c) >= 0,  i.e.  n · u >= h = n · (c - previous) / length,
/// is u = h n + sqrt(1 - h²) t̂ (t̂ the current direction's part across n).
/// Exact for a plane, outside for a convex head; repeated for curved ones.
/// When the previous vertex is too deep to reach out (h > 1), or after the
/// rounds, p is pushed along n, giving up length rather than leaving a vertex
/// inside. Returns true if p moved.
inline bool projectSegmentOut(const Collider& head, const Eigen::Vector3f& previous, float length, float radius,
                              float distance, Eigen::Vector3f normal, Eigen::Vector3f& p) {
    if (distance >= radius) return false;
    const float margin = 1e-6f + 1e-3f * radius;
    for (int round = 0; round < 4 && distance < radius; ++round) {
        const Eigen::Vector3f c = p + (radius - distance + margin) * normal;
        const float h = normal.dot(c - previous) / length;
        if (h > 1.f || length <= 0.f) {
            p = c;
        } else {
            Eigen::Vector3f across = (p - previous) - normal * normal.dot(p - previous);
            if (across.squaredNorm() < 1e-24f) across = normal.unitOrthogonal();
            const float lift = std::max(h, -1.f);
            p = previous + length * (lift * normal + std::sqrt(1.f - lift * lift) * across.normalized());
        }
        distance = head.signedDistance(p, &normal);
    }
    if (distance < radius) p += (radius - distance + margin) * normal;
    return true;
}

}  // namespace hp::follower
