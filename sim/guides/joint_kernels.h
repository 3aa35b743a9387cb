// Bending kernels of the guides' rope (and, for measuring bends, every
// guide formulation): joint frames carried along a strand, the joint drive
// toward the (gravity pre-loaded) rest shape, the projection limit and the
// soft bend limits as spans. Pure functions on plain vectors, each with its
// governing equation, testable without a physics world (after
// PositionBasedDynamics). The rope formulation (sim/guides/rope_group.cpp)
// runs them at Bullet's solver extension point and after its step.
//
// Notation: x_i vertex positions (x_0 the root), l_i rest length of segment
// i = (x_i, x_{i+1}), h the Bullet step, m mass, κ angular stiffness.
#pragma once

#include "sim/solver/head_contact.h"

#include <Eigen/Geometry>

#include <cstddef>

namespace hp::strand {

using Mat3f = Eigen::Matrix3f;
using Quatf = Eigen::Quaternionf;

/// Compliance of an implicit spring in one XPBD iteration (Macklin 2016):
/// a constraint C with stiffness κ on a coordinate of inertia I is corrected by
///   Δ = -C · h²κ / (I + h²κ),
/// which is implicit Euler for the spring: stable for any κ, and the static
/// sag under a load τ is τ/κ whatever h. Returns the fraction h²κ/(I + h²κ).
float springFraction(float stiffness, float inertia, float h);

/// The rotation-minimising transport of a frame: the smallest rotation taking
/// unit vector `from` to unit vector `to` (parallel transport along a bend).
Quatf transport(const Vec3f& from, const Vec3f& to);

/// Angle between unit vectors, radians, accurate near 0 (atan2 of |a×b|, a·b).
float angleBetween(const Vec3f& a, const Vec3f& b);

/// Rotates unit `d` toward unit `axis` in their common plane so the angle
/// between them is exactly `angle` (radians):
///   d' = cos(angle)·axis + sin(angle)·normalize(d - (d·axis)·axis).
Vec3f rotateToAngle(const Vec3f& d, const Vec3f& axis, float angle);

/// Per-joint parameters of relaxJoints, for joint j (segment j relative to
/// its parent segment, or to the root frame for j = 0).
struct JointParams {
    const float* restLength;    ///< l_j
    const Vec3f* restDir;       ///< e_j: rest direction, root-local, unit
    const float* restBend;      ///< φ_j: rest angle between segments j-1 and j (0 for j = 0)
    const float* cosMostBend;   ///< cos(φ_j + limit + projection) (bendBounds)
    const float* cosLeastBend;  ///< cos(φ_j - limit - projection), or 2 when no lower bound (bendBounds)
    Vec3f* springDir;           ///< t_j: spring target direction, root-local, unit (e_j rotated by the pre-load)
    const float* spring;        ///< f_j = springFraction(κ, I_j, h), I_j = m_{j+1}·l_j²
    const float* limitSpring;   ///< the same for the limit spring
    float limit = 0.f;          ///< bend limit, radians
    float projection = 0.f;     ///< projection limit beyond it, radians
};

/// The rope's joint passes (see sim/guides/rope_group.cpp for where each runs).
enum class JointPass {
    Drive,         ///< on Bullet's prediction, before its link solve: springs, soft limits, lengths
    Finish,        ///< after Bullet's step: lengths, projection limit, head clearance
    SolvePreload,  ///< at rest: sets each spring target so that Drive lands on the rest shape
};

/// Per-joint rest bends φ_j and the cosines bounding the Finish pass's
/// projection limit, for a reach of limit + projection (radians).
void bendBounds(const Vec3f* restDir, int segments, float reach, float* restBend, float* cosMostBend,
                float* cosLeastBend);

/// One root-to-tip pass over a strand's joints. Joint j's frame Q_j is the
/// root frame R carried along the strand (Q_0 = R, Q_{j+1} =
/// transport(Q_j e_j → d_j)·Q_j), so springs and limits act on relative
/// bends. At joint j, with d the direction of segment j:
///  - Drive: the implicit spring moves the segment's end toward
///    x_j + l_j·Q_j t_j by the fraction f_j and renormalises — the XPBD step
///    of a joint drive κ on the segment (inertia I_j); the vertex is placed
///    at exactly l_j (follow-the-leader) and what hangs beyond is carried
///    rigidly with that turn (a joint drive moves its subtree). The soft
///    limits are not here but in the link iterations (limitSpan).
///  - Finish: no spring; the projection limit (the angle between consecutive
///    segments kept within φ_j ± (limit + projection), the vertex turned back
///    alone), exact length, and the head (placeSegment), which has the last
///    word.
///  - SolvePreload (the strand at rest, on the prediction of one step from
///    rest): t_j solves normalize((1-f_j)·d + f_j·t_j) = e_j (at most
///    2·limit from e_j), which makes the rest shape an equilibrium under
///    gravity (the pre-load); the vertices are put back on the rest shape.
/// `head`, `radius` and `contacts` (what the head did to vertex i; may be
/// null) concern Finish only.
void relaxJoints(JointPass pass, Vec3f* x, int vertexCount, const Mat3f& rootFrame, const JointParams& joints,
                 const HeadQuery* head, float radius, Contact* contacts);

/// The Drive pass of relaxJoints on `count` strands, x[k] the vertices of
/// strand k with root frame rootFrames[k] and parameters joints[k]: the same
/// values bit for bit as one relaxJoints call per strand, computed for four
/// strands at a time in SIMD lanes. A strand's pass is one long chain of
/// dependent operations (each joint waits on its parent's frame: quaternion
/// products, square roots, divisions); lanes run four chains for the price
/// of one.
void driveJoints(int count, Vec3f* const* x, int vertexCount, const Mat3f* rootFrames, const JointParams* joints);

/// Bend limits as spans: the angle between consecutive segments of lengths
/// l0, l1 fixes the distance between their outer ends,
///   D(φ) = sqrt(l0² + l1² + 2·l0·l1·cos φ),
/// which shrinks as the bend φ grows. A joint whose rest bend is φ_r stays
/// within ±limit of it iff D(φ_r + limit) ≤ |x_{j+1} - x_{j-1}| ≤
/// D(max(φ_r - limit, 0)) (the bend's magnitude; its plane is free). Fills
/// those spans for joints 0..segments-1; joint 0 pairs the root segment with
/// a virtual follicle segment on its own rest direction.
void bendLimitSpan(const float* restLength, const Vec3f* restDir, int segments, float limit, float* minSpan,
                   float* maxSpan);

/// Unilateral distance constraint (position-based, two-sided in its
/// masses): if |b - a| is outside [minSpan, maxSpan] the pair moves toward
/// the nearest bound by `fraction` of the excess, split by inverse masses
/// wa, wb. Run inside Bullet's link iterations, it is the soft bend limit:
/// both sides of the joint move, so the stop's reaction reaches the chain.
void limitSpan(Vec3f& a, Vec3f& b, float wa, float wb, float minSpan, float maxSpan, float fraction);

}  // namespace hp::strand
