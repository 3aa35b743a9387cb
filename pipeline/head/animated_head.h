// The imported head as the simulation sees it: a HeadMotion that poses the
// rig at any shot time and hands out the deformed mesh, the head's rigid
// motion and a collider.
#pragma once

#include "pipeline/head/head_rig.h"
#include "sim/collision/collision_world.h"
#include "sim/collision/level_set.h"
#include "sim/collision/mesh_collider.h"
#include "sim/collision/mesh_parts.h"

#include <functional>
#include <memory>
#include <mutex>

namespace hp {

/// How HeadPose::collider is made per frame.
enum class ColliderMethod {
    Rigid,     ///< the rest pose's distance grid moved by the rigid transform (built once, ~100 ns a query); with
               ///< several parts, each part's by its own fit, rebuilt per pose where that fit misses by > voxel/2
    PerFrame,  ///< a distance grid of each frame's deformed mesh (exact for skinned necks, costs a build per frame)
    Exact,     ///< closest-triangle queries on the deformed mesh (~1 µs a query, a BVH built per frame)
    None,      ///< no collider
};

class AnimatedHead;

/// One collider beside the head (scene key head.colliders[]): a Bullet
/// shape placed at each time by `place` (local -> world, or local -> the
/// head's rest frame when it follows the head's rigid motion).
struct ExtraCollider {
    ColliderShape shape;
    bool followsHead = false;
    bool visible = true;  ///< a mesh collider drawn beside the head (HeadPose::scenery)
    std::function<Eigen::Isometry3f(double)> place;
    /// Skinned mesh: its own file's animation, sampled at the shot time
    /// for the vertices of each pose (shape.kind SkinnedMesh).
    std::shared_ptr<const AnimatedHead> skin;
};

struct HeadAnimationSettings {
    int clip = -1;            ///< index in HeadRig::clips; -1: the rest pose (a static head)
    double clipOffset = 0.0;  ///< clip time = shot time · clipSpeed + clipOffset
    double clipSpeed = 1.0;
    bool loop = false;        ///< wrap the clip time into [0, duration) instead of holding the last pose
    double restTime = 0.0;    ///< shot time of the pose the hair is grown on
    /// Extra rigid motion at a shot time (the scene's head.animate keys),
    /// applied after the rig; empty: none.
    std::function<Eigen::Isometry3f(double)> motion;
    ColliderMethod collider = ColliderMethod::Rigid;
    LevelSetSettings levelSet;
    /// Colliders beside the head; the pose's collider joins them to the
    /// head's (CompositeCollider). Empty: the head's collider alone.
    std::vector<ExtraCollider> colliders;
    /// How far the colliders beside the head measure exactly (beyond: a
    /// lower bound), m (head.collider.colliders_band).
    float collidersBand = 0.01f;
};

/// @brief A posed, animated head. sample() is thread-safe and deterministic.
class AnimatedHead final : public HeadMotion {
  public:
    AnimatedHead(std::shared_ptr<const HeadRig> rig, HeadAnimationSettings settings);

    /// The head at shot time `time` (seconds): deformed world mesh (rest
    /// topology), rigid transform rest -> now (least-squares fit of the fit
    /// vertices, exact for rigid and node animation), collider.
    HeadPose sample(double time) const override;

    /// The rest pose (roots are placed on it; its topology is every pose's).
    const TriangleMesh& rest() const { return rest_; }
    const HeadRig& rig() const { return *rig_; }
    const HeadAnimationSettings& settings() const { return settings_; }
    /// Clip time (seconds) at a shot time.
    double clipTime(double time) const;

    /// Fits the rigid transform to the vertices of these triangles (the
    /// scalp) only; default: all vertices. Call before sampling.
    void setFitTriangles(const std::vector<uint8_t>& mask);

    /// The rest pose's distance grid and exact collider (built on first use).
    std::shared_ptr<const LevelSet> restLevelSet() const;
    std::shared_ptr<const MeshCollider> restCollider() const;

    /// The mesh's connected parts (sim/collision/mesh_parts.h). With more
    /// than one (a head that folds into itself) every pose's collider is a
    /// PartsCollider of one collider of the chosen method per part, so a
    /// strand can ignore the parts its root lies inside.
    const MeshPartition& partition() const { return parts_; }

    /// Part k's own rigid motion rest -> `mesh` (a pose of this head): the
    /// least-squares rigid fit of its fit vertices (those of the fit
    /// triangles in it, or all of its vertices when fewer than 3 are). The
    /// `rigid` collider carries each part's rest grid by it, so a neck that
    /// stays while the head bone tips keeps its grid where it is; a part
    /// this fit misses by more than half a voxel at some vertex (a neck
    /// bent over its blend) gets a grid of its posed mesh instead.
    Eigen::Isometry3f partTransform(const TriangleMesh& mesh, size_t k) const;

  private:
    TriangleMesh posed(double time) const;

    std::shared_ptr<const HeadRig> rig_;
    HeadAnimationSettings settings_;
    TriangleMesh rest_;
    std::vector<uint32_t> weld_;       ///< rest-pose vertex weld, shared by per-frame colliders
    std::vector<uint32_t> fitVertices_;
    std::vector<std::vector<uint32_t>> partFit_;  ///< per part (parts_.count() > 1): the vertices its rigid fit uses
    void setPartFit(const std::vector<uint8_t>& fitVertex);
    mutable std::once_flag gridOnce_;
    mutable std::shared_ptr<const LevelSet> grid_;
    mutable std::shared_ptr<const MeshCollider> restExact_;
    MeshPartition parts_;
    mutable std::vector<std::shared_ptr<const LevelSet>> partGrids_;       ///< per part: rest grid (parts_.count() > 1)
    mutable std::vector<std::shared_ptr<const MeshCollider>> partExact_;  ///< per part: rest exact collider
    /// The head's collider at `pose` (mesh and transform set) by the chosen method.
    std::shared_ptr<const Collider> headCollider(const HeadPose& pose) const;
    std::shared_ptr<const CollisionWorld> world_;  ///< settings_.colliders in Bullet; null when none
};

/// @brief What a renderer draws of a pose: the head's mesh followed by its
/// scenery (the visible mesh colliders), as one mesh.
/// @param storage  filled with that mesh when the pose has scenery; without
///                 scenery the result is pose.mesh itself (no copy).
/// @return pose.mesh or `storage`; valid while both are.
const TriangleMesh& drawnMesh(const HeadPose& pose, TriangleMesh& storage);

/// @brief Least-squares rigid transform (Kabsch / Umeyama without scale)
/// taking `from[i]` to `to[i]` for the listed indices (all when empty).
Eigen::Isometry3f fitRigidTransform(const std::vector<Vec3f>& from, const std::vector<Vec3f>& to,
                                    const std::vector<uint32_t>& indices = {});

}  // namespace hp
