// Kernels of the curly strand model (Kim 2023, after Iben et al. 2013,
// "Artistic simulation of curly hair"): pure functions on plain vectors, each
// with its governing equation, testable without a physics world (after
// PositionBasedDynamics). sim/curly/curly_dynamics.h assembles them into one
// linearly implicit step per strand; sim/curly/curly_wet.cpp runs that step inside
// Bullet worlds.
//
// Notation: p_i particle positions (p_0 the root), e_i = p_{i+1} - p_i the
// edges, v_i velocities, Δv_i = v_{i+1} - v_i, a bar (ē) the rest value, a
// hat (ê) a unit vector, h the step.
#pragma once

#include "sim/strands/head.h"
#include "sim/solver/head_contact.h"

#include <Eigen/Geometry>

#include <cstddef>

namespace hp::curly {

using Mat3f = Eigen::Matrix3f;
using Quatf = Eigen::Quaternionf;

// ---- Smoothing (Iben et al. §4; Kim 2023 eq. 2-3) -------------------------------

/// The filter coefficient β = min(1, 1 - exp(-l/α)) for edges of length l and
/// smoothing length α (m). α ≤ 0 means no smoothing (β = 1).
float smoothingBeta(float edgeLength, float alpha);

/// The IIR smoothing filter of Kim 2023's eq. (2), one output per edge:
///   d_i = 2(1-β) d_{i-1} - (1-β)² d_{i-2} + β² (λ_{i+1} - λ_i),
/// started with d_{-1} = d_{-2} = λ_1 - λ_0 (so d_0 = λ_1 - λ_0). A critically
/// damped second-order low-pass whose gain at zero frequency is 1: β = 1
/// returns the edges unchanged, smaller β smooths over ~1/β edges.
/// `lambda` has n ≥ 2 entries (positions or velocities), `d` receives n - 1.
/// `start`, when given, replaces λ_1 - λ_0 as d_{-1} = d_{-2}: the bending
/// frames start the filter along the root's hair direction (see
/// bendingCurveStart).
void smoothEdges(const Vec3f* lambda, size_t n, float beta, Vec3f* d, const Vec3f* start = nullptr);

/// Where the bending frames' smoothed curve starts: the root's hair
/// direction R·ŷ (the follicle normal, the axis a curl is grown along) times
/// the first edge's length, instead of Kim 2023's first edge λ_1 - λ_0. The
/// first edge of a curl runs around the coil (58° off its axis at the
/// default curl), and the frames are transported from it to every edge, so
/// when a load tilted that edge every bending target turned with it: a
/// hanging curl with the material's springs (curly::materialSprings)
/// extended 2.3-2.6× less than the coil spring it stands for (pitch +10%
/// against +24%); started along the hair direction it extends by +19% (80%
/// of the linear coil, as with frames frozen at rest: +20%).
Vec3f bendingCurveStart(const Vec3f* x, const Mat3f& root);

/// The smoothed curve of eq. (3): p'_0 = λ_0, p'_i = p'_{i-1} + d_{i-1}.
/// `out` receives n points.
void smoothedCurve(const Vec3f* lambda, size_t n, float beta, Vec3f* out);

/// Frames along the smoothed curve, one per edge: the root frame R is carried
/// by parallel transport (the rotation-minimising rotation between
/// consecutive unit tangents),
///   F_0 = rot(R·ŷ → d̂_0)·R,   F_i = rot(d̂_{i-1} → d̂_i)·F_{i-1},
/// where R·ŷ is the root's hair direction (rootFrame's second column, the
/// surface normal). Because the smoothed curve does not follow the curls,
/// these frames turn with the strand as a whole but not with each curl, so a
/// rest edge expressed in them (t̄_i = F̄_iᵀ ē_i) is the curl's shape relative
/// to the strand: Iben et al.'s bending targets t_i = F_i t̄_i.
void transportFrames(const Vec3f* d, size_t edges, const Mat3f& rootFrame, Mat3f* frames);

// ---- Springs (Kim 2023 eq. 1, 4, 5) ---------------------------------------------

/// A spring between particles a = i and b = i + 1. `force` acts on a; b gets
/// -force. `K` = ∂force/∂e and `C` = ∂force/∂Δv (symmetric, positive
/// semi-definite) are what the linearly implicit step needs.
struct PairForce {
    Vec3f force = Vec3f::Zero();
    Mat3f K = Mat3f::Zero();
    Mat3f C = Mat3f::Zero();
};

/// Stretch spring, eq. (1): f = ks(|e| - |ē|)ê + cs(Δv·ê)ê.
/// K = ks[êêᵀ + max(0, 1 - |ē|/|e|)(I - êêᵀ)] (the transverse part is
/// dropped under compression, where it would be indefinite), C = cs êêᵀ.
PairForce stretchSpring(const Vec3f& e, const Vec3f& dv, float restLength, float ks, float cs);

/// Bending spring toward the target vector t, eq. (4):
///   f = kb(e - t) + cb(Δv - (Δv·ê)ê),
/// K = kb I (the target is held fixed over the step), C = cb(I - êêᵀ).
PairForce bendingSpring(const Vec3f& e, const Vec3f& dv, const Vec3f& target, float kb, float cb);

/// Core spring on the smoothed curve, eq. (5): f = kc(|b| - |b̄|)b̂ + cc(ν·b̂)b̂
/// with b the smoothed edge (smoothEdges of the positions with α_c), b̄ its rest
/// value and ν the smoothed velocity difference (smoothEdges of the
/// velocities). Applied to the edge's two particles like a stretch spring: it
/// resists the lengthening of the smoothed curve that happens when a curl is
/// pulled straight. ∂b_i/∂e_i = β_c² (the filter's direct tap), so
/// K = kc β_c² b̂b̂ᵀ and C = cc β_c² b̂b̂ᵀ (`tap` = β_c²).
PairForce coreSpring(const Vec3f& b, float restLength, const Vec3f& nu, float kc, float cc, float tap);

// ---- The implicit step -------------------------------------------------------

/// Solves A x = r for a symmetric positive definite block-tridiagonal A with
/// 3×3 blocks: diagonal blocks D_0..D_{n-1}, off-diagonal U_i = A(i, i+1)
/// (A(i+1, i) = U_iᵀ), by block Gaussian elimination without pivoting (the
/// Thomas algorithm; stable for SPD matrices). O(n). `diag` and `rhs` are
/// overwritten; the solution is left in `rhs`.
void solveBlockTridiagonal(Mat3f* diag, const Mat3f* upper, Vec3f* rhs, size_t n);

// ---- Limits (Selle et al. 2008, as Kim 2023's §1.1; strain: see placeParticle) --

/// Velocity limiting, root to tip: where |v_{i+1} - v_i| > vmax the child's
/// velocity is pulled back to v_i + vmax·Δv̂. Returns how many were limited.
size_t limitRelativeVelocity(Vec3f* v, size_t n, float maxRelative);

/// A per-step factor f given at the reference step h_ref, applied over a step
/// h: f^(h/h_ref). Applying it n times with h/n gives the same decay, so
/// Kim 2023's per-step constants (ξ, ζ) do not depend on the step size.
float perStepFactor(float factor, float h, float hRef);

// ---- The obstacle (head) -----------------------------------------------------

/// The head during one Bullet step and what a contact did to one particle:
/// the same query, contact and projection out of the signed distance
/// (Bridson et al.'s collision handling, which Kim 2023 uses) as the rope
/// guides' (sim/solver/head_contact.h).
using ObstacleQuery = strand::HeadQuery;
using strand::Contact;
using strand::projectOut;

/// The strain limit on one length: clamp(l, (1-s)|ē|, (1+s)|ē|).
float strainLimited(float length, float restLength, float maxStrain);

/// Places a child particle at distance `length` from its (already placed)
/// parent, along their current direction, and outside the head:
/// strand::placeOutside with the radial rule (projectOut, then back along
/// the parent-child direction). Used root to tip with the strain-limited
/// lengths Bullet's link solve left, so moving a parent out of the head
/// carries its child instead of stretching the edge between them.
inline Contact placeParticle(const Vec3f& parent, Vec3f& child, float length, const ObstacleQuery& head,
                             float radius) {
    return strand::placeOutside(parent, child, length, &head, radius, strand::Reattach::Radial);
}

/// Friction after a contact: the same Coulomb update as the rope guides'
/// (strand::contactFriction).
using strand::contactFriction;

// ---- Helices (Kim 2023 eq. 6) and measuring them ----------------------------------

/// Points of the helix (r cos t, r sin t, c t), c = pitch / 2π, sampled at equal
/// arc lengths `segment` from t = 0 and shifted so the first point is the
/// origin: n points along +Z. `pitch` is the advance per turn (m).
void helixPoints(float radius, float pitch, float segment, size_t n, Vec3f* out);

/// Radius and pitch of a curl, estimated from the strand's own shape.
struct HelixFit {
    float radius = 0.f;  ///< m
    float pitch = 0.f;   ///< m per turn
    size_t samples = 0;  ///< edge triples that gave an estimate
};

/// Fits a helix locally: consecutive edges of a uniformly sampled helix are
/// related by one screw motion, a rotation by θ about the axis â with an
/// advance along it. For each triple (e_{i-1}, e_i, e_{i+1}):
///   â ∥ (e_i - e_{i-1}) × (e_{i+1} - e_i),   θ = angle between the parts of
///   e_{i-1} and e_i perpendicular to â,
///   pitch = 2π (â·e_i)/θ,   radius = |e_i - (â·e_i)â| / (2 sin(θ/2)).
/// Exact for a sampled helix; returns the medians over the triples starting at
/// edge `skip` (to leave out the root), so a slowly bending axis barely
/// matters. Zero samples when the strand is straight.
HelixFit fitHelix(const Vec3f* p, size_t n, size_t skip = 0);

}  // namespace hp::curly
