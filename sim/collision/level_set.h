// A narrow-band signed distance grid of a closed triangle mesh (OpenVDB's
// meshToSignedDistanceField), sampled trilinearly with an analytic gradient.
//
// Why a grid: the guide solver asks for the head's distance at every strand
// vertex every 0.02 s step (20k+ queries per step at 845 guides), so a query
// must cost well under ~200 ns; an exact BVH query (sim/collision/mesh_query.h) costs
// ~1 µs. OpenVDB builds the narrow band robustly (its sign flood fill gives
// the inside of a closed mesh); the band's box is then copied into a dense
// array when it fits (≤ 128 MB), so a query is eight loads and a trilinear
// interpolation with its analytic gradient. The grid is built once, in the
// rest pose, and moved rigidly with the head (sim/collision/mesh_collider.h).
// Measured (tools/bench/bench_head, default head, 2 mm voxels): ~70-85 ns a
// query in strand order, ~350 ns for random points (memory-bound), ~110 ns
// from the sparse tree alone; building takes ~1 s on 2 busy cores.
#pragma once

#include "sim/strands/head.h"

#include <memory>

namespace hp {

/// Defaults match the scene's head.collider keys: 2 mm voxels keep the
/// trilinear error near a smooth scalp far below 1 mm (≲ a voxel only at
/// sharp creases) at an eighth of the build time and memory of 1 mm.
struct LevelSetSettings {
    float voxelSize = 0.002f;     ///< metres
    float exteriorBand = 0.006f;  ///< metres of exact distance kept outside the surface
    float interiorBand = 0.006f;  ///< and inside
};

/// @brief Signed distance grid of a mesh (negative inside). Immutable after
/// construction; sample() is thread-safe.
class LevelSet {
  public:
    /// Builds the grid; the mesh should be closed (a hole wider than a voxel
    /// lets the inside/outside flood fill leak). Throws Error on an empty mesh.
    LevelSet(const TriangleMesh& mesh, const LevelSetSettings& settings);
    ~LevelSet();
    LevelSet(const LevelSet&) = delete;
    LevelSet& operator=(const LevelSet&) = delete;

    /// Trilinear signed distance at `p`. `gradient` (optional) gets the
    /// interpolant's gradient (not normalised). Returns false when a corner of
    /// the cell lies outside the narrow band: then the value is only a bound
    /// (±band) and the gradient is meaningless.
    bool sample(const Vec3f& p, float& distance, Vec3f* gradient = nullptr) const;

    const LevelSetSettings& settings() const { return settings_; }
    /// World-space box of the active (narrow-band) voxels.
    const Eigen::AlignedBox3f& bounds() const { return bounds_; }
    size_t activeVoxelCount() const;
    size_t memoryBytes() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    LevelSetSettings settings_;
    Eigen::AlignedBox3f bounds_;
};

}  // namespace hp
