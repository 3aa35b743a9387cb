// The scene's head.* and hair.* root keys mapped onto the head import,
// animation, scalp and root placement: what the groom and the simulation
// stages start from.
#pragma once

#include "pipeline/head/animated_head.h"
#include "pipeline/head/head_import.h"
#include "pipeline/head/scalp.h"
#include "pipeline/scene/scene.h"
#include "sim/strands/roots.h"

#include <memory>

namespace hp {

/// True when the scene names a head file (head.file).
bool sceneHasHead(const Scene& scene);

/// `<prefix>.up_axis` (head, hair.groom).
UpAxis sceneUpAxis(const Scene& scene, const std::string& prefix);
/// `<prefix>.translate` after `<prefix>.rotate` (X, then Y, then Z), metres.
Affine3f scenePlacement(const Scene& scene, const std::string& prefix);

/// head.file, head.meshes, head.unit_scale, head.up_axis, head.translate, head.rotate.
HeadImportSettings headImportSettings(const Scene& scene);
/// head.clip*, head.loop, head.rest_time, head.animate.*, head.collider.* (`rig` resolves the clip name).
HeadAnimationSettings headAnimationSettings(const Scene& scene, const HeadRig& rig);
/// head.colliders[]: the colliders beside the head (a mesh collider's file is
/// imported here; a skinned one plays its clip on `head`'s timing).
std::vector<ExtraCollider> extraColliders(const Scene& scene, const HeadAnimationSettings& head);
ScalpSettings scalpSettings(const Scene& scene);

/// Everything about the head a shot needs, loaded once.
struct HeadSetup {
    std::shared_ptr<const HeadRig> rig;
    /// The HeadMotion of the shot: sample(time) gives the deformed mesh,
    /// rigid transform and collider at any time.
    std::shared_ptr<const AnimatedHead> motion;
    TriangleMesh rest;           ///< rest pose (motion->rest()); every pose has its topology
    std::vector<uint8_t> scalp;  ///< per triangle of `rest`: 1 = grows hair
    ScalpSettings scalpUsed;     ///< the selection that made `scalp` (head.scalp.method auto resolved)
    bool scalpGiven = false;     ///< the scene chose the scalp (head.scalp.method other than auto)
};

/// @brief Imports and sets up the scene's head (throws SceneError at the
/// offending key for a bad mesh/clip/scalp selection, AssetError for a bad
/// file). Requires sceneHasHead(scene).
HeadSetup loadHead(const Scene& scene);

/// Root placement settings of hair.roots.method for `count` roots; the
/// Fibonacci lattice is centred on the scalp region when the scalp is one.
RootSettings rootSettings(const Scene& scene, const HeadSetup& head, size_t count, uint64_t seed);

struct GroomRoots {
    std::vector<SurfacePoint> guides;     ///< hair.guides.count roots
    std::vector<SurfacePoint> followers;  ///< hair.followers.count roots, placed independently
};

/// @brief The guide and follower roots on the head's scalp, as surface
/// points of `head.rest` (evaluate(pose.mesh, root) at any frame).
/// Deterministic for the scene's seed.
GroomRoots placeGroomRoots(const Scene& scene, const HeadSetup& head);

}  // namespace hp
