// Colliders beside the head: the body, shoulders, a hat, a hand, props.
//
// Each is a Bullet collision object in one btCollisionWorld (the Bullet side
// stays in sim/collision/collision_world.cpp): Bullet's primitives for analytic shapes
// (btSphereShape, btCapsuleShape, btBoxShape); a btGImpactMeshShape for a
// rigid mesh prop, whose hollows (a hat's inside, a cup's) stay open, or a
// btConvexHullShape when the prop is asked for as a hull; and a
// btBvhTriangleMeshShape for a skinned mesh (a body), whose tree is built
// once and refitted (refitTree) on each pose's deformed vertices. A hair
// vertex asks the world for
// its signed distance: the broadphase (btDbvtBroadphase::aabbTest) finds the
// objects near it; Bullet's GJK/EPA (btGjkEpaSolver2::SignedDistance) gives
// the distance to a convex shape, negative inside, with the normal to push
// along; for a triangle mesh the mesh's BVH (the GImpact box set, or the
// skin's refitted quantized BVH) lists the triangles near the
// vertex and Bullet's Voronoi-region closest point
// (btVoronoiSimplexSolver::closestPtPointTriangle) picks the nearest, whose face (by its winding) says
// inside or outside. A vertex farther than the query range from every
// triangle is clear (the range is returned, a lower bound) unless a ray
// from it crosses the mesh an odd number of times: then it lies deep inside,
// and the search goes on to its exact depth. The result is a Collider
// (sim/strands/head.h), and CompositeCollider joins it to the head's own collider
// (the distance-grid fast path), so every solver (rope, rigid, rod,
// followers) collides with all of them unchanged; a head without extra
// colliders keeps its plain collider and pays nothing.
#pragma once

#include "sim/strands/head.h"

#include <Eigen/Geometry>

#include <memory>
#include <vector>

namespace hp {

/// @brief One collider's shape, in its own local frame.
struct ColliderShape {
    enum class Kind {
        Sphere,
        Capsule,
        Box,
        ConvexMesh,   ///< the convex hull of `points` (fills every hollow)
        Mesh,         ///< a rigid triangle mesh (`points`, `triangles`), hollows kept (btGImpactMeshShape)
        SkinnedMesh,  ///< a triangle mesh over each pose's vertices (btBvhTriangleMeshShape, refitted)
    };
    Kind kind = Kind::Sphere;
    float radius = 0.05f;                  ///< sphere, capsule: m
    float length = 0.1f;                   ///< capsule: distance between the cap centres, along local Y, m
    Vec3f halfExtents = Vec3f::Constant(0.05f);  ///< box: m
    std::vector<Vec3f> points;             ///< convex mesh, mesh: the mesh's vertices; skinned mesh: its rest pose
    std::vector<Tri> triangles;            ///< mesh, skinned mesh: the triangles (outward by winding)
};

/// @brief The colliders of a shot: shapes built once, posed per time.
/// posed() is thread-safe. A skinned mesh keeps a few trees built on its
/// rest pose (`points`); each posed world borrows one, refits it to its
/// pose's vertices and hands it back when it is destroyed, so poses alive
/// at once (a step's and a frame's) never share a tree.
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
    /// `skins[i]` holds the deformed vertices of skinned collider i (local
    /// coordinates, as many as its rest `points`); other entries empty.
    std::shared_ptr<const Collider> posed(const std::vector<Eigen::Isometry3f>& poses, float range = 0.05f,
                                          std::vector<std::vector<Vec3f>> skins = {}) const;
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
    /// The parts a strand ignores are the head's (sim/collision/mesh_parts.h).
    float signedDistanceIgnoring(const Vec3f& p, Vec3f* normal, uint32_t ignoreParts) const override;

  private:
    std::shared_ptr<const Collider> head_, others_;
};

}  // namespace hp
