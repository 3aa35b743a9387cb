// A sparse voxel grid of hair density: what the voxelizer produces
// (render/volume/voxelizer.h), what the VDB writer exports (render/volume/vdb_writer.h), and
// what the preview's voxel shadows are checked against (line integrals of
// density along light rays).
//
// Units. density = hair volume fraction: cubic metres of hair per cubic metre
// of space, averaged over a voxel (dimensionless; 0 = empty, 1 = solid hair).
// Σ density × voxel volume is therefore the hair volume in m³. A ray's optical
// depth is σ · ∫ density ds (s in metres), where σ (1/m) is the scene's
// extinction per unit volume fraction. For fibres of radius r in random
// orientation, the projected area per hair volume gives σ ≈ 1 / (2 r)
// (≈ 20000 /m for r = 25 µm); a renderer may use any artistic value.
//
// Layout. The grid has no OpenVDB types, so this header stays cheap: blocks of
// 8³ voxels (the size of an OpenVDB leaf, so export copies blocks 1:1), keyed
// by their origin, each holding 512 floats in OpenVDB's leaf order
// (offset = x·64 + y·8 + z of the voxel within the block).
#pragma once

#include "sim/strands/strand.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

namespace hp {

using Vec3d = Eigen::Vector3d;
using Vec3i = Eigen::Vector3i;

/// @brief The affine map between world space (metres) and a grid's index space.
///
/// index = linear · world + offset. Voxel (i, j, k) is centred at index
/// coordinates (i, j, k) and covers [i-½, i+½) × [j-½, j+½) × [k-½, k+½), as in
/// OpenVDB, so an OpenVDB linear transform with the same matrix addresses the
/// same voxels. (A GL 3D texture puts texel centres at i+½: shift by half a
/// voxel when comparing texel indices.)
struct GridTransform {
    Eigen::Matrix3d linear = Eigen::Matrix3d::Identity();  ///< world → index, 1/m
    Vec3d offset = Vec3d::Zero();                           ///< index of the world origin

    /// World-aligned cubic voxels of `voxelSize` metres, voxel centres at
    /// integer multiples of voxelSize (the VDB export's grid).
    static GridTransform uniform(double voxelSize);
    /// An arbitrary affine (e.g. light-space) grid: voxel (0,0,0) is centred at
    /// `origin`; stepping one voxel along index axis a moves by column a of
    /// `axes` (metres). E.g. axes = [right·h, up·h, lightDirection·h] makes
    /// index z run along a directional light. Throws hp::Error if singular.
    static GridTransform fromAxes(const Eigen::Matrix3d& axes, const Vec3d& origin);
    /// From an affine world → index matrix (last row 0 0 0 1), e.g. a light's
    /// view-projection mapped to texels: for a GL 3D texture of N texels per
    /// axis addressed by texture coordinates u ∈ [0, 1], index = u·N − ½.
    /// Throws hp::Error if the matrix is not affine or is singular.
    static GridTransform fromMatrix(const Eigen::Matrix4d& worldToIndex);

    Vec3d toIndex(const Vec3d& world) const { return linear * world + offset; }
    Vec3d toWorld(const Vec3d& index) const;
    /// Columns: world displacement of one voxel step along each index axis.
    Eigen::Matrix3d indexToWorld() const;
    /// World volume of one voxel, m³.
    double voxelVolume() const;
    /// Edge length in metres when the grid is world-aligned with cubic voxels, else 0.
    double uniformVoxelSize() const;
};

/// How a continuous density is reconstructed from voxel values.
enum class Reconstruction {
    Nearest,    ///< piecewise constant over each voxel's cube
    Trilinear,  ///< trilinear between voxel centres (like GL_LINEAR 3D textures)
};

/// @brief Sparse density (and optional density-weighted velocity) per voxel.
///
/// Absent voxels are 0. Blocks are kept in the order they were added (the
/// voxelizer's order is deterministic: by 32³ tile, then x, y, z within it).
class DensityGrid {
  public:
    static constexpr int kBlockLog2 = 3;
    static constexpr int kBlockSize = 1 << kBlockLog2;  ///< voxels per block edge
    static constexpr int kBlockVoxels = kBlockSize * kBlockSize * kBlockSize;
    /// Voxel coordinates must stay within ±kMaxIndex (blocks are keyed by 21-bit coordinates).
    static constexpr int kMaxIndex = (1 << 23) - 16;

    using DensityBlock = std::array<float, kBlockVoxels>;
    using VelocityBlock = std::array<Vec3f, kBlockVoxels>;
    /// Blocks are allocated one by one, so building a grid from pieces made
    /// in parallel moves pointers instead of copying voxels.
    using DensityBlockPtr = std::unique_ptr<DensityBlock>;
    using VelocityBlockPtr = std::unique_ptr<VelocityBlock>;

    DensityGrid() = default;
    explicit DensityGrid(const GridTransform& transform) : transform_(transform) {}
    /// Takes whole blocks at once (the voxelizer's fast path); `velocity` is
    /// empty or one block per origin. Same checks as addBlock.
    DensityGrid(const GridTransform& transform, std::vector<Vec3i> origins, std::vector<DensityBlockPtr> density,
                std::vector<VelocityBlockPtr> velocity);

    const GridTransform& transform() const { return transform_; }

    /// Adds a block whose first voxel is `origin` (each component a multiple
    /// of kBlockSize); `velocity` may be null. Velocity must be given for all
    /// blocks or none. Throws hp::Error on a duplicate or misaligned origin.
    void addBlock(const Vec3i& origin, const float* density, const Vec3f* velocity = nullptr);

    /// Frees block b's values (blockDensity(b) becomes null): for writers
    /// that consume the grid block by block. Safe in parallel for distinct b.
    void releaseBlock(size_t b);
    /// Removes every block, keeping the transform.
    void clear();

    size_t blockCount() const { return origins_.size(); }
    const Vec3i& blockOrigin(size_t b) const { return origins_[b]; }
    const float* blockDensity(size_t b) const { return density_[b]->data(); }
    /// Null when the grid carries no velocity.
    const Vec3f* blockVelocity(size_t b) const { return velocity_.empty() ? nullptr : velocity_[b]->data(); }
    bool hasVelocity() const { return !velocity_.empty(); }
    /// Offset of voxel `local` (each component in [0, 8)) inside a block.
    static int voxelOffset(int x, int y, int z) { return (x << 6) | (y << 3) | z; }
    /// Packs a block coordinate (voxel >> 3, each within ±2^20) into a key;
    /// sorting keys sorts by x, then y, then z.
    static uint64_t blockKey(const Vec3i& blockCoord);
    /// The block coordinate of a key.
    static Vec3i blockCoordOfKey(uint64_t key);

    /// Density of one voxel (0 outside the stored blocks).
    float density(const Vec3i& voxel) const;
    /// Density-weighted mean velocity of the hair in one voxel (m/s); zero
    /// where there is no hair or no velocity channel.
    Vec3f velocity(const Vec3i& voxel) const;

    /// Density at a world position, reconstructed trilinearly (the GL_LINEAR
    /// / openvdb BoxSampler convention) or as the containing voxel's value.
    float sample(const Vec3f& world, Reconstruction mode = Reconstruction::Trilinear) const;
    /// ∫ density ds along the straight segment from → to (s in metres), exact
    /// for the chosen reconstruction (voxel walk, Gauss quadrature per cell).
    double integrate(const Vec3f& from, const Vec3f& to, Reconstruction mode = Reconstruction::Nearest) const;
    /// exp(-sigma · integrate(from, to)): the light transmitted between two
    /// points through hair of extinction `sigma` (1/m per unit volume fraction).
    double transmittance(const Vec3f& from, const Vec3f& to, double sigma,
                         Reconstruction mode = Reconstruction::Nearest) const;

    /// Σ density × voxel volume: the hair volume in m³.
    double totalVolume() const;
    /// Voxels with density > 0.
    size_t activeVoxelCount() const;
    /// Index bounds (inclusive) of the voxels with density > 0; false if none.
    bool activeBounds(Vec3i* min, Vec3i* max) const;
    /// Largest voxel density (0 if empty).
    float maxDensity() const;

  private:
    /// Index of the block holding `voxel` (and the voxel's offset in it), or -1.
    long findBlock(const Vec3i& voxel, int* offset) const;

    GridTransform transform_;
    std::vector<Vec3i> origins_;
    std::vector<DensityBlockPtr> density_;
    std::vector<VelocityBlockPtr> velocity_;
    std::unordered_map<uint64_t, uint32_t> lookup_;  // packed block coordinate → block
};


}  // namespace hp
