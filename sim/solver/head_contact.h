// Head-contact kernels every strand model shares: the head as one Bullet
// step (or substep) sees it, projection out of its signed distance
// (Bridson et al. 2002's collision handling; Kim 2023 handles the head so too), placing a
// vertex at its length outside the head, and Coulomb friction on the
// velocity a contact left. Pure functions on plain vectors.
//
// Notation: φ the head's signed distance (negative inside), ∇φ its outward
// normal, r the clearance kept from the surface, h the step, μ the friction
// coefficient.
#pragma once

#include "sim/strands/head.h"

#include <Eigen/Geometry>

namespace hp::strand {

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
    Eigen::Matrix3f normalToWorld = Eigen::Matrix3f::Identity();
    Eigen::Isometry3f toPrevious = Eigen::Isometry3f::Identity();
    /// The head's parts this strand ignores (bit k: part k): those its root
    /// lies inside (sim/collision/mesh_parts.h). 0: none.
    uint32_t ignoreParts = 0;

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

/// How placeOutside puts a child projected out of the head back at its
/// length from the parent.
enum class Reattach {
    /// Slides it along the contact plane onto the sphere about the parent in
    /// one move (the guides; up to 4 rounds).
    Slide,
    /// Pulls it back along the parent-child direction, x ← p + l·(x - p)/|x - p|
    /// (the curly guides, as Kim 2023 does; up to 16 rounds, since alternating
    /// projections creep toward the corner where plane and sphere meet).
    Radial,
};

/// Places a child vertex at exactly `length` from its parent and outside the
/// head: onto the sphere of radius `length` about the parent, then, while it
/// is inside, projection out of φ (projectOut) and back onto that sphere
/// (`how`); the two sets (the sphere, the outside of the head) intersect
/// whenever the parent is outside, so this converges to a point on both. A
/// last projection guarantees the clearance: if the parent sits deep inside,
/// the head wins over the length. The returned push is the total outward
/// motion along the last contact normal. `head` may be null (no head).
Contact placeOutside(const Vec3f& parent, Vec3f& child, float length, const HeadQuery* head, float radius,
                     Reattach how);

/// placeOutside with the guides' rule (Reattach::Slide).
inline Contact placeSegment(const Vec3f& parent, Vec3f& child, float length, const HeadQuery* head, float radius) {
    return placeOutside(parent, child, length, head, radius, Reattach::Slide);
}

/// Coulomb friction for a vertex the head pushed out by `push` during the
/// step (velocity level, relative to the surface velocity vs):
///   v_rel = v - vs; the push added push/h along n, which is removed (no
///   bounce); the normal part is clamped to ≥ 0 (no approach); Δv_n is what
///   the contact removed; the tangential part shrinks by at most μ·Δv_n
///   (static friction when that stops it).
Vec3f contactFriction(const Vec3f& v, const Vec3f& vs, const Contact& contact, float mu, float h);

/// The velocity of a vertex that moved from `before` to `after` over a step
/// h (position-based dynamics), with Coulomb friction against the head where
/// the step ended in a contact:
///   v = (after - before)/h,  then contactFriction(v, v_surface(after), contact, μ, h) if the contact is active.
inline Vec3f stepVelocity(const Vec3f& before, const Vec3f& after, float h, const Contact& contact,
                          const HeadQuery& head, float mu) {
    const Vec3f v = (after - before) / h;
    return contact.active ? contactFriction(v, head.surfaceVelocity(after, h), contact, mu, h) : v;
}

}  // namespace hp::strand
