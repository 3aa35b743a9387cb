// The rod's pre-load: the inverse static problem at the first frame. Given
// the groom x (the rest shape the user made), choose the rest curvatures c_j
// so that x is a static equilibrium of the rod step under gravity and the
// head's contact: the head carries what lies on it, rest curvature only what
// hangs free (Derouet-Jourdan, Bertails-Descoubes, Daviet and Thollot,
// "Inverse dynamic hair modeling with frictional contact", 2013; Twigg and
// Kačić-Alesić, "Optimization for sag-free simulations", 2011). Pure
// functions on plain arrays; the notation is sim/guides/rod_kernels.h's.
#pragma once

#include "sim/guides/rod_kernels.h"

#include <Eigen/Core>

namespace hp::rod {

/// Where the pre-load may lean on the head: normal[i] is the head's outward
/// unit normal at x_i where the free vertex x_i (i ≥ 1) lies closer to the
/// head's surface than `reach` (signed distance φ(x_i) < reach), zero
/// elsewhere and at the root. Returns how many vertices may lean.
int headContacts(const Vec3f* x, int n, const strand::HeadQuery& head, float reach, Vec3f* normal);

/// λ ≥ 0 minimising |A·λ - b|² (Lawson and Hanson, "Solving Least Squares
/// Problems", 1974, ch. 23, algorithm NNLS: an active set grown by the most
/// violated optimality condition w = Aᵀ(b - Aλ) > 0, each least-squares
/// subproblem solved by Householder QR, a step back to the feasible set when
/// it leaves λ ≥ 0). Deterministic; at most 3·cols + 1 outer rounds.
Eigen::VectorXd nonNegativeLeastSquares(const Eigen::MatrixXd& A, const Eigen::VectorXd& b);

/// Adds to c the pre-load that balances per-vertex forces f at x (the
/// equilibrium of the constraint forces, rod_kernels.h equilibriumMatrix):
///   Jᵀ Λ = -(f + Σ_k λ_k n_k)      (3(n-1) equations, as many multipliers)
///   c_j += (l̄_j/EI_j)·Λ_bend,j    (a bend row's multiplier is Λ = (c - κ)/α)
/// where the head may push vertex k along its outward normal n_k
/// (contactNormal[k] non-zero; null: no vertex) with a force λ_k ≥ 0 (it
/// pushes, never pulls). Λ(λ) = Λ_0 - B·λ is linear in λ, and the forces
/// chosen are those that minimise the pre-load's elastic energy
///   E(λ) = Σ_j EI_j/(2 l̄_j)·|Δc_j|² = Σ_j α_j/2·|Λ_bend,j(λ)|²,  α_j = l̄_j/EI_j,
/// a non-negative least-squares problem in λ (nonNegativeLeastSquares): the
/// rest curvature changes only as much as the head cannot carry. The
/// tangential (friction) part of a contact force is left zero: the rod's
/// Coulomb friction acts on velocities (strand::contactFriction), so a
/// vertex under a tangential load creeps by h²·a_t per step and friction
/// could not hold a tangential pre-load. Returns Σ λ_k, the normal force
/// the head carries, N.
double preloadOffset(const RodStrand& s, const Vec3f* x, const Mat3f& R, const Vec3f* force,
                     const Vec3f* contactNormal, Vec2f* c);

/// Where and how the pre-load leans on the head (GuideSettings
/// preloadContact, collisionRadius, preloadReach).
struct PreloadContact {
    const strand::HeadQuery* head = nullptr;  ///< the head at the first frame; null: the pre-load ignores it
    float radius = 0.f;                       ///< the strand's clearance from the head (the step keeps φ ≥ radius), m
    float reach = 0.f;                        ///< a vertex with φ < radius + reach may lean on the head, m
};

/// Bounds what the pre-load adds to the rest curvature, joint by joint
/// (c0: the curvatures before the pre-load, the groom's own shape):
///   ℓ_b,j = (EI_j/(μ·|g|))^(1/3)          the bending length; μ the strand's
///                                          mean mass per length
///   |c_j - c0_j| ≤ limit · l̄_j / ℓ_b,j   (c is a turn per joint: a
///                                          curvature times l̄_j)
/// Why: a pre-load is the curvature that holds the groom's weight up, and
/// one that curls a joint more than 1/ℓ_b lifts about a bending length of
/// hair on its own. A strand combed up and over the crown and held in place
/// wholly by rest curvature (a cantilever) has a second, standing
/// equilibrium beside the groom, and a nod or a shake throws it there
/// (docs/physics.md, "Pre-load"). The exact sag-free rest state (Twigg and
/// Kačić-Alesić, "Optimization for sag-free simulations", 2011) is given up
/// where the bound binds: there the groom sags, onto the head, which then
/// carries it (as Derouet-Jourdan et al. 2013 let the head carry what lies
/// on it).
/// limit ≤ 0: no bound. Returns how many joints the bound clipped.
int limitPreload(const RodStrand& s, const Vec2f* c0, float gravity, float limit, Vec2f* c);

/// Pre-loads c (holding the rest curvatures) so that x is a static
/// equilibrium of rodStep with step h under gravity and the head's contact:
/// preloadOffset for the weights, leaning on the head where x lies within
/// reach of it (headContacts), then `probes` probe steps from rest, each
/// cancelling the drift left (GuideSettings::preloadProbes); where the
/// strand leans on the head the probes step with the head (as the
/// simulation will), and may lean on it again. Without contact (or
/// contact.head null) the weights go wholly into rest curvature. Last, the
/// change is bounded by limitPreload(limit) (≤ 0: unbounded, an exact
/// equilibrium). Returns how many joints the bound clipped.
int preload(const RodStrand& s, const Vec3f* x, const Mat3f& R, const Vec3f& gravity, float h, int probes,
            const PreloadContact& contact, float limit, Vec2f* c, RodScratch& scratch);

}  // namespace hp::rod
