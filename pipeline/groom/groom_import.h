// The user's own groom (hair.groom.file) bound to the head: each strand's
// root on the nearest scalp triangle, its shape in that root's frame, so it
// rides the deforming mesh like a procedural root.
//
// - Placement: hair.groom.unit_scale, up_axis, translate and rotate, as the
//   head's keys, take the file into the head's rest space (metres, Y up).
// - Binding: the closest point of the scalp (MeshQuery, triangle +
//   barycentrics); a strand whose first point is further than
//   hair.groom.max_root_distance from it is reported and dropped. With
//   head.scalp.method auto, every triangle is scalp: the groom itself says
//   where hair grows. The strand is moved rigidly so its root lies on the
//   surface point.
// - Resampling: every strand to `vertices` points evenly spaced along its
//   own arc length (its length is kept, segment lengths are equal).
// - Guides: with at most hair.guides.count strands every strand is a guide
//   (the followers are placed procedurally and copy their nearest guide);
//   with more, hair.guides.count guides are chosen among them by
//   farthest-point sampling of (root, middle, tip) (deterministic: it
//   starts from the strand nearest the roots' mean), and every other strand
//   becomes a follower keeping its own groomed shape
//   (FollowerGroom::followerShapes).
#pragma once

#include "pipeline/head/head_setup.h"
#include "sim/followers/followers.h"

#include <vector>

namespace hp {

struct ImportedGroom {
    GroomRoots roots;           ///< guides: chosen strands; followers: the others (or procedural ones)
    RestShapes guideShapes;     ///< root-local rest shapes, [t, n, t × n] frames, `vertices` points each
    RestShapes followerShapes;  ///< one per follower root when the groom is dense; empty otherwise
    /// The file's strand index of each guide, then of each follower (dense grooms).
    std::vector<uint32_t> sources;
    size_t read = 0;            ///< strands in the file
    size_t dropped = 0;         ///< strands too far from the scalp
};

/// True when the scene names a groom file (hair.groom.file).
bool sceneHasGroomFile(const Scene& scene);

/// @brief Reads, places, binds and resamples hair.groom.file (throws
/// AssetError naming the file, SceneError at the key for settings).
ImportedGroom importGroom(const Scene& scene, const HeadSetup& head, int vertices);

/// The followers' root frame [t, n, t × n] of a surface frame as columns
/// (Gram-Schmidt, as sim/followers/followers.cpp, so inexact mesh frames agree).
Eigen::Matrix3f rootAxes(const SurfaceFrame& frame);

/// @brief Rest shapes for followers that copy the world-space shape of their
/// nearest guide (by root distance), moved to their own root: for grooms
/// that gravity shaped (settled or imported), where copying the guide's
/// root-local shape instead would turn hair that hangs beside a guide on
/// the side of the head into hair that sticks out from the crown.
/// `guides` holds the guides at rest (strand g at `guideRoots[g]`).
RestShapes nearestGuideShapes(const StrandFrame& guides, const std::vector<SurfaceFrame>& guideRoots,
                              const std::vector<SurfaceFrame>& followerRoots);

/// @brief World-space strands of root-local `shapes` at the root frames
/// `roots` (one per shape): x = t, y = n, z = t × n of each (Gram-Schmidt).
std::vector<std::vector<Vec3f>> strandsAt(const RestShapes& shapes, const std::vector<SurfaceFrame>& roots);

}  // namespace hp
