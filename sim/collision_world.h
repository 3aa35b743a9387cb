// Colliders beside the head: the body, shoulders, a hat, a hand, props.
//
// Each is a Bullet collision object in one btCollisionWorld (the Bullet side
// stays in sim/collision_world.cpp): Bullet's primitives for analytic shapes
// (btSphereShape, btCapsuleShape, btBoxShape) and a btConvexHullShape for a
// rigid mesh prop. A hair vertex asks the world for its signed distance:
// the broadphase (btDbvtBroadphase::aabbTest) finds the objects near it and
// Bullet's GJK/EPA (btGjkEpaSolver2::SignedDistance) gives the distance,
// negative inside, with the normal to push along. The result is a Collider
// (sim/head.h), and CompositeCollider joins it to the head's own collider
// (the distance-grid fast path), so every solver (rope, rigid, rod,
// followers) collides with all of them unchanged; a head without extra
// colliders keeps its plain collider and pays nothing.
#pragma once

#include "sim/head.h"

#include <Eigen/Geometry>

#include <memory>
#include <vector>

namespace hp {

/// @brief One collider's shape, in its own local frame.
struct ColliderShape {
    enum class Kind { Sphere, Capsule, Box, ConvexMesh };
    Kind kind = Kind::Sphere;
    float radius = 0.05f;                  ///< sphere, capsule: m
    float length = 0.1f;                   ///< capsule: distance between the cap centres, along local Y, m
    Vec3f halfExtents = Vec3f::Constant(0.05f);  ///< box: m
    std::vector<Vec3f> points;             ///< convex mesh: the mesh's vertices (their convex hull collides)
};

/// @brief The colliders of a shot: shapes built once, posed per time.
/// Immutable after construction; posed() is thread-safe.
class CollisionWorld {
  public:
    /// @param shapes the colliders; each keeps its index in posed()'s poses.
    explicit CollisionWorld(const std::vector<ColliderShape>& shapes);
    ~CollisionWorld();
    CollisionWorld(const CollisionWorld&) = delete;
    CollisionWorld& operator=(const CollisionWorld&) = delete;

    /// @brief A Bullet world with every collider at its pose (local -> world),
    /// as a Collider: the smallest signed distance to any of them. Points
    /// farther than `range` from every collider get `range` (a lower bound
    /// of the true distance, enough to tell a hair vertex it is clear).
    std::shared_ptr<const Collider> posed(const std::vector<Eigen::Isometry3f>& poses, float range = 0.05f) const;
    size_t size() const;

    struct Impl;

  private:
    std::shared_ptr<Impl> impl_;  // shared with the posed worlds, which use its shapes
};

/// @brief The smaller signed distance of two colliders (a union of solids),
/// with the normal of the nearer one. Either may be null.
class CompositeCollider final : public Collider {
  public:
    CompositeCollider(std::shared_ptr<const Collider> head, std::shared_ptr<const Collider> others)
        : head_(std::move(head)), others_(std::move(others)) {}
    float signedDistance(const Vec3f& p, Vec3f* normal = nullptr) const override;

  private:
    std::shared_ptr<const Collider> head_, others_;
};

}  // namespace hp
