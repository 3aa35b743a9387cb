// Solver kernels for guide strands: pure functions on plain vectors, each
// with its governing equation, testable without a physics world (after
// PositionBasedDynamics). The rope formulation (sim/guides/rope_group.cpp) runs them
// after every Bullet step; the rigid formulation uses the collision and
// measurement kernels.
//
// Notation: x_i vertex positions (x_0 the root), l_i rest length of segment
// i = (x_i, x_{i+1}), h the Bullet step, m mass, κ angular stiffness.
#pragma once

#include "sim/strands/head.h"

#include <Eigen/Geometry>

#include <cmath>
#include <cstddef>

namespace hp::strand {

using Mat3f = Eigen::Matrix3f;
using Quatf = Eigen::Quaternionf;

/// The root's orthonormal, right-handed frame as a rotation: columns
/// (tangent, normal, tangent × normal), the tangent re-orthogonalised against
/// the normal. Rest shapes are stored in these root-local coordinates.
Mat3f rootRotation(const SurfaceFrame& frame);

/// Compliance of an implicit spring in one XPBD iteration (Macklin 2016):
/// a constraint C with stiffness κ on a coordinate of inertia I is corrected by
///   Δ = -C · h²κ / (I + h²κ),
/// which is implicit Euler for the spring: stable for any κ, and the static
/// sag under a load τ is τ/κ whatever h. Returns the fraction h²κ/(I + h²κ).
float springFraction(float stiffness, float inertia, float h);

/// Velocity damping over a time h: v ← v·exp(-c·h). Applying it n times with
/// h/n gives the same decay, so damping does not depend on the step size.
float dampingFactor(float rate, float h);

/// The rotation-minimising transport of a frame: the smallest rotation taking
/// unit vector `from` to unit vector `to` (parallel transport along a bend).
Quatf transport(const Vec3f& from, const Vec3f& to);

/// Angle between unit vectors, radians, accurate near 0 (atan2 of |a×b|, a·b).
float angleBetween(const Vec3f& a, const Vec3f& b);

/// Rotates unit `d` toward unit `axis` in their common plane so the angle
/// between them is exactly `angle` (radians):
///   d' = cos(angle)·axis + sin(angle)·normalize(d - (d·axis)·axis).
Vec3f rotateToAngle(const Vec3f& d, const Vec3f& axis, float angle);

/// Follow-the-leader (Müller et al. 2012): places the child at exactly the rest
/// length from its already-placed parent, along the current direction:
///   x_{i+1} ← x_i + l_i · (x_{i+1} - x_i)/|x_{i+1} - x_i|.
Vec3f followTheLeader(const Vec3f& parent, const Vec3f& child, float length);

/// Follow-the-leader along a whole strand, root fixed. `correction[i]` (may
/// be null) receives x_i(after) - x_i(before), used for the velocity update.
void followTheLeader(Vec3f* x, const float* restLength, size_t vertexCount, Vec3f* correction = nullptr);

/// Follow-the-leader on compressed segments only: where |x_{i+1} - x_i| < l_i
/// the child is pushed out to l_i along the segment, root to tip; stretched
/// segments are left alone. Run before a mass-weighted link solve so that it
/// only sees tension: Gauss-Seidel on a compressed limp chain folds it into a
/// zig-zag (measured: 8° kinks at the root of a standing strand), whereas a
/// hair resists buckling through its bending stiffness.
void relieveCompression(Vec3f* x, const float* restLength, size_t vertexCount);

/// The head during one Bullet step, as the kernels see it. The collider is
/// posed at the end of the outer step; `toCollider` maps a world point at the
/// end of this Bullet step onto that pose (identity without substeps) and
/// `normalToWorld` maps normals back; `toPrevious` maps a point riding on the
/// head at the end of the step to where it was at the step's start, which
/// gives the surface velocity for friction. Rigid head motion is exact; a
/// deforming head's non-rigid motion is taken from the end pose.
struct HeadQuery {
    const Collider* collider = nullptr;
    Eigen::Isometry3f toCollider = Eigen::Isometry3f::Identity();
    Mat3f normalToWorld = Mat3f::Identity();
    Eigen::Isometry3f toPrevious = Eigen::Isometry3f::Identity();

    /// Signed distance (negative inside) and outward world normal at `x`.
    float distance(const Vec3f& x, Vec3f* normal) const;
    /// Velocity of the head surface at `x` over a step of length h.
    Vec3f surfaceVelocity(const Vec3f& x, float h) const { return (x - toPrevious * x) / h; }
};

/// What a contact did to one vertex (for the velocity update).
struct Contact {
    bool active = false;
    Vec3f normal = Vec3f::Zero();  ///< outward head normal
    float push = 0.f;              ///< distance moved out along the normal, m
};

/// Projection out of the head's signed distance φ, keeping `radius` clear:
///   if φ(x) < r:  x ← x + (r - φ(x))·∇φ(x).
Contact projectOut(const HeadQuery& head, float radius, Vec3f& x);

/// Places a child vertex at exactly `length` from its parent and outside the
/// head: follow-the-leader, then (if inside) projection out of φ and back onto
/// the sphere of radius `length` about the parent, repeated a few times; the
/// two sets (a sphere around the parent, the outside of the head) intersect
/// whenever the parent is outside, so this converges to a point on both. If
/// it cannot (parent deep inside), the head wins over the length.
Contact placeSegment(const Vec3f& parent, Vec3f& child, float length, const HeadQuery* head, float radius);

/// Coulomb friction for a vertex the head pushed out by `push` during the
/// step (velocity level, relative to the surface velocity vs):
///   v_rel = v - vs; the push added push/h along n, which is removed (no
///   bounce); the normal part is clamped to ≥ 0 (no approach); Δv_n is what
///   the contact removed; the tangential part shrinks by at most μ·Δv_n
///   (static friction when that stops it).
Vec3f contactFriction(const Vec3f& v, const Vec3f& vs, const Contact& contact, float mu, float h);

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

/// Pushes two segments apart along `normal` (from B to A) by `depth` at the
/// parameters s (on A: a0→a1) and t (on B), weighted by inverse masses w:
///   Δa_k = +w_ak·α_k·λ·n, Δb_k = -w_bk·β_k·λ·n,  λ = depth / Σ w·(weight)²,
/// with α = (1-s, s), β = (1-t, t) (position-based edge-edge contact).
void separateSegments(Vec3f& a0, Vec3f& a1, Vec3f& b0, Vec3f& b1, float s, float t, const Vec3f& normal,
                      float depth, const float w[4]);

/// |l/l_rest - 1| of segment (a, b).
inline float stretch(const Vec3f& a, const Vec3f& b, float rest) { return std::abs((b - a).norm() / rest - 1.f); }

}  // namespace hp::strand
