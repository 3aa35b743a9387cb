// @brief Voxelizes strands into a hair density field that conserves hair volume.
//
// Each strand segment is a truncated cone: radius tapering linearly from its
// first to its second vertex, volume π·L·(r0² + r0·r1 + r1²)/3. The segment's
// centre line is cut at voxel (or dual-cell) boundaries and every piece
// deposits exactly its share of that volume, so
//     Σ density × voxel volume = hair volume
// up to float rounding, for any grid (world-aligned or an affine light-space
// grid). Strands are treated as lines: the radius sets how much they deposit,
// not where (hair is far thinner than a voxel).
//
// Parallel over space (TBB): segments are binned into tiles of 32³ voxels;
// one task owns a tile and adds every segment touching it, in segment order,
// into a dense buffer, walking only the part of the segment whose cells
// reach the tile (the walk's state where it enters is the one the walk from
// the segment's start reaches there, so the pieces are the same). Each voxel's sum is therefore formed in the same order
// whatever the thread count: the result is bit-identical for 1 or N threads,
// and no per-thread copies of the grid are merged.
#pragma once

#include "render/volume/density_grid.h"
#include "sim/strands/strand.h"

namespace hp {

/// How a segment's volume is spread over voxels.
enum class VoxelFilter {
    /// Into the voxel whose cube contains each piece of the centre line (the
    /// exact line integral of a box kernel): sharp, one voxel wide.
    Box,
    /// Over the 8 voxels around each point with trilinear (tent) weights,
    /// integrated exactly along the line (Gauss-Legendre per dual cell): the
    /// inverse of trilinear sampling, smooth and free of voxel-crossing
    /// flicker in animation; two voxels wide.
    Trilinear,
};

/// The instruction set of the trilinear density deposit, the voxelizer's hot
/// loop. Both give the same grid, bit for bit.
enum class VoxelKernel {
    /// AVX2 where the CPU has it (four pieces of a segment at a time), else SSE2.
    Auto,
    /// The SSE2 reference (the x86-64 baseline): one piece at a time.
    Sse2,
};

/// Where a voxelize() call's time went (for benchmarks): wall and process CPU
/// seconds of its phases, in order.
struct VoxelizePhases {
    struct Phase {
        double wall = 0, cpu = 0;
    };
    Phase prepare;  ///< segments in index space, strands in Morton order, long ones split
    Phase bin;      ///< (tile, segment) pairs sorted by tile
    Phase tiles;    ///< the walks and deposits, one task per tile, and the blocks extracted
    Phase gather;   ///< the tiles' blocks concatenated into the grid
};

struct VoxelizeSettings {
    VoxelFilter filter = VoxelFilter::Trilinear;
    /// Also accumulate vertex velocities (linear along each segment) weighted
    /// by the deposited volume, giving each voxel its hair's mean velocity.
    bool velocity = false;
    /// Memory (segments, binning, the grid's blocks) above which voxelize()
    /// stops with hp::Error rather than exhausting the machine: a voxel size
    /// far too small. (Writing with the consuming writeDensityVdb adds little.)
    double maxMemoryGiB = 8.0;
    VoxelKernel kernel = VoxelKernel::Auto;
    /// If set, filled with the time of each phase.
    VoxelizePhases* phases = nullptr;
};

/// @brief The density field of `strands` on the grid `transform`.
/// @param strands   one frame of strands (validated; velocities may be empty = at rest)
/// @param transform world → index map of the grid (GridTransform::uniform(h) for VDB export)
/// @param settings  filter, velocity channel, memory limit
/// @return a DensityGrid whose blocks hold every voxel with density > 0 (hair volume
///         fraction, see render/volume/density_grid.h), with a velocity channel if asked.
/// @throws hp::Error on invalid strands, strands beyond the grid's index range,
///         or a grid that would exceed the memory limit.
DensityGrid voxelize(const StrandFrame& strands, const GridTransform& transform, const VoxelizeSettings& settings = {});

/// Whether VoxelKernel::Auto runs the AVX2 kernel on this CPU.
bool avx2KernelAvailable();

/// The hair volume of `strands` in m³: Σ over segments of the truncated cone
/// π·L·(r0² + r0·r1 + r1²)/3. voxelize() conserves exactly this quantity.
double hairVolume(const StrandFrame& strands);

}  // namespace hp
