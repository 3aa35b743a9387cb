// Colliders for a triangle-mesh head (sim/strands/head.h's Collider interface).
//
// - MeshCollider: exact signed distance to the mesh as it is (closest
//   triangle through an Embree BVH, ~1 µs a query). The sign comes from the
//   angle-weighted pseudonormal of the closest feature (Bærentzen & Aanæs
//   2005), which is exact for closed meshes and locally sensible for open
//   ones. Use it to measure penetration against the truly deformed mesh.
// - LevelSetCollider: the rest pose's narrow-band distance grid
//   (sim/collision/level_set.h) moved by the head's rigid transform: ~100 ns a query,
//   nothing rebuilt per frame. Exact for rigid head motion; where the mesh
//   deforms (a skinned neck) it is off by the non-rigid part of the motion,
//   so the pipeline can rebuild the grid per frame instead.
#pragma once

#include "sim/strands/head.h"
#include "sim/collision/level_set.h"
#include "sim/collision/mesh_query.h"

#include <memory>
#include <vector>

namespace hp {

/// For each vertex, the lowest index of the vertices within `tolerance` ×
/// (bounding box diagonal) of it (transitively): merges the copies a mesh
/// keeps at UV or normal seams, so adjacency (pseudonormals) sees one surface.
std::vector<uint32_t> weldVertices(const std::vector<Vec3f>& positions, float tolerance = 1e-6f);

/// @brief Exact signed distance to a triangle mesh.
class MeshCollider final : public Collider {
  public:
    /// `weld` maps vertices to their representative (weldVertices); computed
    /// from `mesh` when empty. Pass the rest pose's weld for deformed frames:
    /// seam copies may drift apart by rounding when skinned.
    explicit MeshCollider(const TriangleMesh& mesh, std::vector<uint32_t> weld = {});

    float signedDistance(const Vec3f& p, Vec3f* normal = nullptr) const override;
    /// The closest surface point and its signed distance.
    MeshPoint closest(const Vec3f& p, float* signedDistance = nullptr) const;
    const MeshQuery& query() const { return query_; }

  private:
    MeshQuery query_;
    std::vector<Vec3f> faceNormals_;                  ///< unit, per triangle
    std::vector<std::array<Vec3f, 3>> edgeNormals_;   ///< per triangle edge (ab, bc, ca): sum of adjacent face normals
    std::vector<Vec3f> vertexNormals_;                ///< per welded vertex: angle-weighted face normals
    std::vector<uint32_t> weld_;
};

/// @brief A rest-pose signed distance grid carried by a rigid transform:
/// d(p) = grid(T⁻¹ p), normal = R · ∇grid.
///
/// Beyond the grid's exterior band the result is a lower bound of the
/// distance (the band's values, or outside the band's box the distance to
/// the box plus band - voxel), with the normal pointing away from the box
/// centre, so far-away strand vertices cost no more than near ones. Deeper
/// inside than the interior band it asks `exact` (the MeshCollider of the
/// mesh the grid was built from) for the distance, when given, and keeps
/// the grid's side: inside (a fold's pocket, whose closest triangle may
/// face away from it).
class LevelSetCollider final : public Collider {
  public:
    LevelSetCollider(std::shared_ptr<const LevelSet> grid, const Eigen::Isometry3f& restToWorld,
                     std::shared_ptr<const MeshCollider> exact = nullptr);
    float signedDistance(const Vec3f& p, Vec3f* normal = nullptr) const override;

  private:
    std::shared_ptr<const LevelSet> grid_;
    std::shared_ptr<const MeshCollider> exact_;
    Eigen::Matrix3f rotation_;     ///< rest -> world
    Eigen::Isometry3f worldToRest_;
};

}  // namespace hp
