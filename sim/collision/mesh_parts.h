// Heads that fold into themselves: a mesh made of closed shells that
// overlap (a neck cylinder pushed into a head sphere, an ear or a jaw
// modelled apart and sunk into the skull) instead of one closed surface.
//
// Definitions (docs/colliders.md, "Heads that fold into themselves"):
// - A part is a connected shell of the mesh: triangles joined through
//   shared (welded) vertices.
// - The head's solid is the union of its parts' solids, with signed distance
//   φ(p) = min_k φ_k(p): exact outside the union; inside, the depth into the
//   part that holds p deepest (a lower bound of the depth into the union).
// - A strand whose root lies inside another part at a pose (φ_k(root) < 0
//   for a part k other than the root's own) ignores that part there: its
//   vertices collide with φ_s(p) = min over the parts it does not ignore.
//   Hair grown under another part's surface, or whose root a fold carries
//   under it, is neither pushed through that surface nor counted as inside
//   it. A strand's depth, as the statistics and tests report it, is -φ_s at
//   its free vertices.
#pragma once

#include "sim/strands/head.h"

#include <memory>
#include <vector>

namespace hp {

class MeshQuery;

/// Up to this many parts can be ignored by a strand (bit k of a mask: part
/// k); parts beyond are never ignored.
constexpr uint32_t kMaxIgnoredParts = 32;

/// @brief A mesh split into its connected shells.
struct MeshPartition {
    std::vector<uint32_t> triangleParts;  ///< per triangle of the mesh: its part
    /// Per part: the mesh's vertices it uses (ascending) and its triangles
    /// over them (local indices), in mesh order.
    std::vector<std::vector<uint32_t>> vertices;
    std::vector<std::vector<Tri>> triangles;
    /// Per part: its vertices' weld (weldVertices' map, local indices).
    std::vector<std::vector<uint32_t>> welds;

    size_t count() const { return vertices.size(); }
    /// The part `k` of `mesh` (same topology as the partitioned mesh, any pose):
    /// positions and normals of its vertices, its triangles.
    TriangleMesh part(const TriangleMesh& mesh, size_t k) const;
};

/// @brief Splits `mesh` into connected parts through `weld` (weldVertices'
/// map of its vertices). Parts are numbered by their first triangle.
MeshPartition partitionMesh(const TriangleMesh& mesh, const std::vector<uint32_t>& weld);

/// @brief The union of the parts' colliders (φ = min_k φ_k), and the same
/// without the parts a strand ignores (signedDistanceIgnoring).
class PartsCollider final : public Collider {
  public:
    explicit PartsCollider(std::vector<std::shared_ptr<const Collider>> parts);
    float signedDistance(const Vec3f& p, Vec3f* normal = nullptr) const override;
    float signedDistanceIgnoring(const Vec3f& p, Vec3f* normal, uint32_t ignoreParts) const override;
    const Collider& part(size_t k) const { return *parts_[k]; }
    size_t count() const { return parts_.size(); }

  private:
    std::vector<std::shared_ptr<const Collider>> parts_;
};

/// @brief A collider seen by one strand: `collider` without the parts the
/// strand ignores (`ignoreParts`, the mask partsAroundRoots gives its root).
/// A view (borrows the collider); with a mask of 0 it is the collider itself.
/// For code written against a plain Collider (projection, bending, pinning
/// of follower vertices) to collide by the rule above.
class IgnoringParts final : public Collider {
  public:
    IgnoringParts(const Collider& collider, uint32_t ignoreParts) : collider_(collider), ignore_(ignoreParts) {}
    float signedDistance(const Vec3f& p, Vec3f* normal = nullptr) const override {
        return ignore_ ? collider_.signedDistanceIgnoring(p, normal, ignore_) : collider_.signedDistance(p, normal);
    }
    float signedDistanceIgnoring(const Vec3f& p, Vec3f* normal, uint32_t ignoreParts) const override {
        return collider_.signedDistanceIgnoring(p, normal, ignore_ | ignoreParts);
    }

  private:
    const Collider& collider_;
    uint32_t ignore_;
};

/// How far outside its own triangle (along the posed face normal) a root's
/// own part is asked whether it wraps the root, m: above rounding, far
/// below a segment.
constexpr float kBuriedRootOffset = 1e-4f;

/// @brief Whether a root lies under its own part's fold: the generalized
/// winding number of its own part (`part`, posed; `query` a BVH of it) at
/// the point kBuriedRootOffset outside its triangle of `mesh` (the posed
/// whole mesh) is above ½. On a surface that does not cross itself that
/// point is outside (w = 0); where the part folds through itself and laps
/// over the root, another layer wraps it (w = 1 or more).
bool buriedByOwnPart(const TriangleMesh& part, const MeshQuery& query, const TriangleMesh& mesh,
                     const SurfacePoint& root);

/// @brief Per root, the parts it lies inside: bit k set when φ_k(root) <
/// -tolerance for a part k other than the part of the root's triangle,
/// measured exactly (MeshCollider of each part) on `mesh`, the pose it is
/// asked for; and the bit of its own part when its own part's fold buries
/// it (buriedByOwnPart). All zero for a mesh of one part.
std::vector<uint32_t> partsAroundRoots(const MeshPartition& partition, const TriangleMesh& mesh,
                                       const std::vector<SurfacePoint>& roots, float tolerance = 1e-5f);

}  // namespace hp
