// @brief Pure per-segment kernels of the follower strands (Gomes 2024,
// Algorithm 1), testable without a groom or a frame.
//
// Conventions shared by every function here and by sim/followers/followers.h:
// - A root frame is the matrix R = [t, n, t × n] of a SurfaceFrame (tangent,
//   normal, tangent × normal): local x = tangent, y = normal, z = t × n. So a
//   strand that is straight along the normal has local directions (0, 1, 0).
// - Quaternions are (w, x, y, z) with w the scalar part, unit length.
// - The rotation of guide segment y is expressed in that guide's root frame:
//   it takes the segment's rest direction to its current direction, with the
//   twist fixed by parallel transport along the strand (segmentRotation).
//
// Everything is inline. The follower update runs these over 8 segments at a
// time: templates take float or an 8-lane vector (sim/followers/follower_simd.h) with
// the same arithmetic; the float-only ones run inside loops over segments
// that the compiler vectorizes.
#pragma once

#include "core/hash.h"
#include "sim/strands/head.h"

#include <Eigen/Geometry>

#include <algorithm>
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
/// Gomes 2024 writes qs = "half the segment count" with its 23 segments indexed
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

/// Variable offset: d_v = clamp(|v|, 0, maxVelocity), |v| in m/s (Gomes 2024
/// clamps the nearest guide's speed to [0, 0.1]).
HP_FOLLOWER_KERNEL float variableOffset(float speed, float maxVelocity) {
    return speed < maxVelocity ? (speed > 0.f ? speed : 0.f) : maxVelocity;
}

/// Resulting slerp weight of Algorithm 1: d_r = fixed * d_f + rand * d_v.
/// May leave [0, 1] (rand < 0 near root and tip); the slerp (1) extrapolates
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

/// MurmurHash3's 32-bit finaliser (fmix32, core/hash.h): a bijection with
/// full avalanche. U: uint32_t or a vector of them.
template <typename U>
HP_FOLLOWER_KERNEL U mix32(U h) {
    return hash::murmur3Fmix32(h);
}

/// Per-follower part of the hash (computed once per follower and update).
HP_FOLLOWER_KERNEL uint32_t followerHash(uint32_t seed, uint32_t follower) {
    return mix32(seed * 0x9e3779b9u ^ mix32(follower + 0x7f4a7c15u));
}

/// The hash of segment y of the follower with hash `base`.
template <typename U>
HP_FOLLOWER_KERNEL U segmentHash(U base, U y) {
    return mix32(base + y * 0x27d4eb2fu);
}

/// rand_xy for segment y of the follower with hash `base`: in [-1, 1)
/// (the hash read as a signed integer, times 2^-31).
HP_FOLLOWER_KERNEL float segmentRandom(uint32_t base, uint32_t y) {
    return float(int32_t(segmentHash(base, y))) * (1.f / 2147483648.f);
}

// ---------------------------------------------------------------------------
/// A quaternion (w, x, y, z) in float, with the few operations the guide
/// tables need written out (Eigen's double quaternions cost 3x as much here).
struct Quat {
    float w = 1.f, x = 0.f, y = 0.f, z = 0.f;
};

// ---------------------------------------------------------------------------
// Slerp by its arc (per guide pair and segment, once per step) and a
// polynomial sine and cosine (per follower and segment).
//
// With a, b unit quaternions, a · b = cos θ >= 0 (b negated otherwise: the
// same rotation, the shorter arc), and e the unit quaternion orthogonal to a
// in their plane, e = (b - (a · b) a) / |b - (a · b) a|:
//   slerp(a, b, t) = cos(tθ) a + sin(tθ) e,                           (1)
// for any t (outside [0, 1] it extrapolates along the same great circle).
// θ and e depend on the two guides only, so a step computes them once per
// guide pair and segment; a follower then needs one sine and one cosine of
// φ = tθ. The templates below take float or an 8-lane vector
// (sim/followers/follower_simd.h) alike; the arithmetic is the same.
// Error bound (tests/test_follower_kernels.cpp, 20k random pairs from equal
// to opposite rotations, t in [-0.5, 1.5], against double precision):
// |q - slerp| < 1e-6 (measured 3.4e-7) and the rotated direction of (2)
// within 2e-6 (measured 7.6e-7); Eberly's series used before was 2.4e-7
// only for cos θ >= 0.7 and 3e-5 toward opposite rotations. (sin, cos) stay
// on the unit circle to 3e-7, so directions need no renormalisation.

/// Polynomials for |x| <= π/2 (Chebyshev fits of (sin x / x - 1) / x² and
/// (cos x - 1) / x², degree 9 and 10): absolute error < 3e-8 before float
/// rounding; sin 0 = 0 and cos 0 = 1 exactly, so t = 0 gives guide 1's
/// rotation bit for bit.
template <typename T>
HP_FOLLOWER_KERNEL void sinCos(T x, T& s, T& c) {
    const T z = x * x;
    const T ps = ((2.634756392e-6f * z - 1.982273949e-4f) * z + 8.333242135e-3f) * z - 1.666666596e-1f;
    const T pc = (((-2.629751742e-7f * z + 2.477457975e-5f) * z - 1.388865165e-3f) * z + 4.166665936e-2f) * z -
                 4.999999996e-1f;
    s = x + (x * z) * ps;
    c = 1.f + z * pc;
}

/// x - kπ for the nearest integer k, in [-π/2, π/2]; π in three parts
/// (Cody-Waite) so kπ is exact for |k| < 2^15. For the rotations of (1) the
/// sign change of (sin, cos) is immaterial: q and -q are the same rotation
/// and everything below is quadratic in (sin, cos). |x| < 2^22 π.
template <typename T>
HP_FOLLOWER_KERNEL T reduceHalfTurns(T x) {
    constexpr float kRound = 12582912.f;  // 1.5 · 2^23: adding it rounds to an integer
    const T k = (x * 0.318309886f + kRound) - kRound;
    return ((x - k * 3.140625f) - k * 9.67025756835937500e-4f) - k * 6.27711415e-7f;
}

/// atan2(y, x) for x, y >= 0, in [0, π/2]: reduced to |u| <= tan(π/8) by
/// atan(n/m) = π/4 + atan((n - m)/(n + m)) and the complement π/2 - atan(m/n),
/// then u + u³ P(u²) (Chebyshev fit, error < 4e-8). One division, no
/// branches: per guide pair and segment in a loop the compiler vectorizes.
HP_FOLLOWER_KERNEL float atan2Positive(float y, float x) {
    const bool yBig = y > x;
    const float n = yBig ? x : y, m = yBig ? y : x;  // n <= m
    const bool half = n > 0.414213562f * m;
    const float den = half ? n + m : m;
    const float u = (half ? n - m : n) / (den > 0.f ? den : 1.f);  // x = y = 0: 0
    const float z = u * u;
    const float p = ((8.520492036e-2f * z - 1.402414284e-1f) * z + 1.999123774e-1f) * z - 3.333328656e-1f;
    const float a = (u + (u * z) * p) + (half ? 0.785398163f : 0.f);
    return yBig ? 1.570796327f - a : a;
}

/// The arc of slerp (1) from a to b: θ and e. With r = b - (a · b) a
/// (b negated when a · b < 0), sin θ = |r|, cos θ = a · b, e = r / |r|,
/// θ = atan2(|r|, a · b) (accurate for small θ, unlike acos). For |r| -> 0
/// (equal rotations) e = 0, so every t gives a.
HP_FOLLOWER_KERNEL void slerpArc(const Quat& a, Quat b, float& theta, Quat& e) {
    float d = a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z;
    const float sign = d < 0.f ? -1.f : 1.f;
    d *= sign;
    const float rw = b.w * sign - d * a.w, rx = b.x * sign - d * a.x;
    const float ry = b.y * sign - d * a.y, rz = b.z * sign - d * a.z;
    const float sinTheta = std::sqrt(rw * rw + rx * rx + ry * ry + rz * rz);
    // Divide unconditionally, then select: a division under a condition
    // could trap, and the compiler would not vectorize the loop around it.
    const float reciprocal = 1.f / std::max(sinTheta, 1e-20f);
    const float inv = sinTheta > 1e-20f ? reciprocal : 0.f;
    e = {rw * inv, rx * inv, ry * inv, rz * inv};
    theta = atan2Positive(sinTheta, d);
}

/// q v q* for any quaternion q = (w, u) (unit or not):
///   (w² - u·u) v + 2 (u·v) u + 2 w (u × v)   (scaled by |q|² for non-unit q).
HP_FOLLOWER_KERNEL Eigen::Vector3f sandwich(const Quat& q, const Eigen::Vector3f& v) {
    const Eigen::Vector3f u(q.x, q.y, q.z);
    return (q.w * q.w - u.dot(u)) * v + (2.f * u.dot(v)) * u + (2.f * q.w) * u.cross(v);
}

/// Rest direction f turned by slerp (1), as a function of φ = tθ: with
/// q = c a + s e (c = cos φ, s = sin φ), q f q* is quadratic in (c, s):
///   q f q* = c² A + s² B + cs D,  A = a f a*,  B = e f e*,
///   D = a f e* + e f a* = (a + e) f (a + e)* - A - B.
/// With c² = 1 - s²:   q f q* = A + s² (B - A) + cs D.                (2)
/// Outputs A, B - A and D; a follower then needs 8 multiply-adds per
/// segment instead of a quaternion blend and rotation.
HP_FOLLOWER_KERNEL void slerpedDirection(const Quat& a, const Quat& e, const Eigen::Vector3f& f, Eigen::Vector3f& A,
                                         Eigen::Vector3f& BminusA, Eigen::Vector3f& D) {
    A = sandwich(a, f);
    const Eigen::Vector3f B = sandwich(e, f);
    D = sandwich({a.w + e.w, a.x + e.x, a.y + e.y, a.z + e.z}, f) - A - B;
    BminusA = B - A;
}

/// Rotates v by the unit quaternion (w, x, y, z):
///   v' = v + w τ + u × τ,   τ = 2 u × v,   u = (x, y, z).
template <typename T>
HP_FOLLOWER_KERNEL void rotate(T w, T x, T y, T z, T vx, T vy, T vz, T& ox, T& oy, T& oz) {
    const T tx = 2.f * (y * vz - z * vy);
    const T ty = 2.f * (z * vx - x * vz);
    const T tz = 2.f * (x * vy - y * vx);
    ox = vx + w * tx + (y * tz - z * ty);
    oy = vy + w * ty + (z * tx - x * tz);
    oz = vz + w * tz + (x * ty - y * tx);
}

// ---------------------------------------------------------------------------
// Segment rotations of a guide (per guide and step, a few hundred flops).

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
/// When the previous vertex is too deep to reach out (h > 1), p goes as far
/// out as the segment reaches, toward the pushed point c:
///   p = previous + length (c - previous) / |c - previous|,
/// and so after the rounds if p is still inside: the segment keeps its
/// length and the vertex may stay inside rather than the strand stretching
/// to reach out (issue 20: a follower pushed out of the head must not
/// stretch); the caller then bends the segment or pins the vertex
/// (sim/followers/follower_pinch.h). Returns the signed distance of p
/// afterwards; `radius` or more when it did not move.
inline float projectSegmentOut(const Collider& head, const Eigen::Vector3f& previous, float length, float radius,
                               float distance, Eigen::Vector3f normal, Eigen::Vector3f& p) {
    if (distance >= radius) return distance;
    const float margin = 1e-6f + 1e-3f * radius;
    // The reachable point toward c, at the segment's length.
    auto toward = [&](const Eigen::Vector3f& c) {
        const Eigen::Vector3f d = c - previous;
        const float n = d.norm();
        return n > 0.f ? Eigen::Vector3f(previous + (length / n) * d) : c;
    };
    for (int round = 0; round < 4 && distance < radius; ++round) {
        const Eigen::Vector3f c = p + (radius - distance + margin) * normal;
        const float h = normal.dot(c - previous) / length;
        if (h > 1.f || length <= 0.f) {
            p = toward(c);
        } else {
            Eigen::Vector3f across = (p - previous) - normal * normal.dot(p - previous);
            if (across.squaredNorm() < 1e-24f) across = normal.unitOrthogonal();
            const float lift = std::max(h, -1.f);
            p = previous + length * (lift * normal + std::sqrt(1.f - lift * lift) * across.normalized());
        }
        distance = head.signedDistance(p, &normal);
    }
    if (distance < radius) {
        p = toward(p + (radius - distance + margin) * normal);
        distance = head.signedDistance(p);
    }
    return distance;
}

}  // namespace hp::follower
