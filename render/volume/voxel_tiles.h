// @brief The voxelizer's unit of parallel work: a tile of 32³ voxels with its
// dense accumulator, the deposits of one segment into it (box and trilinear
// filters) and the extraction of its non-empty 8³ blocks. Internal to
// render/volume/voxelizer.cpp, which prepares the segments, bins them by
// tile and runs one task per tile (render/volume/voxelizer.h).
#pragma once

#include "render/volume/density_grid.h"

#include <cstdint>
#include <vector>

namespace hp::voxel_tiles {

constexpr int kBlock = DensityGrid::kBlockSize;
constexpr int kBlockVoxels = DensityGrid::kBlockVoxels;

/// Tiles of 32³ voxels (4³ blocks) are the unit of parallel work: one task
/// owns a tile, accumulates every segment touching it into a dense buffer
/// that stays in cache (34³ doubles with its border, 314 KiB), in a fixed segment order. So
/// each voxel's sum is formed in the same order whatever the thread count,
/// and no per-thread copies of the grid need merging.
constexpr int kTileLog2 = 5;
constexpr int kTile = 1 << kTileLog2;
constexpr int kBlocksPerTile = kTile / kBlock;

/// A segment prepared for deposit: end points in index space, radii, and
/// k = π · L / voxel volume, which turns ∫ r² dt into density.
struct Segment {
    Vec3d a, b;
    double k;
    double r0, r1;
};

/// End-point velocities of a segment (only when the velocity channel is on).
struct SegmentVelocity {
    Vec3f v0, v1;
};

/// Voxels per axis of a tile's accumulator: the tile's own kTile voxels and
/// one on each side, so a dual cell's 8 corners (cells −1 .. kTile−1 reach
/// the tile) are always inside it and a deposit needs no bounds checks. The
/// border voxels belong to neighbouring tiles (which compute the same pieces
/// and keep them); they are discarded.
constexpr int kPad = kTile + 2;
/// Cell blocks: dual cells c grouped by (c + 1) >> 3 per axis (0 .. kBlocksPerTile),
/// the unit in which the accumulator records where deposits went.
constexpr int kCellBlocks = kBlocksPerTile + 1;

/// A tile's dense accumulator: C channels per voxel (density, or density and
/// momentum = density × velocity), x-major over the padded kPad³ voxels
/// (tile-local −1 .. kTile), in double precision so that each voxel's sum
/// keeps the mass error at the float grid's rounding.
template <int C>
struct TileBuffer {
    Vec3i origin;  // first voxel of the tile
    std::vector<double> values = std::vector<double>(size_t(kPad) * kPad * kPad * C, 0.0);
    /// Bit per cell block that received deposits (sparse hair touches few).
    uint64_t touched[(kCellBlocks * kCellBlocks * kCellBlocks + 63) / 64] = {};

    /// Position of tile-local voxel (x, y, z), each in −1 .. kTile, in `values`, in voxels.
    static int index(int x, int y, int z) { return ((x + 1) * kPad + (y + 1)) * kPad + (z + 1); }
    static int cellBlock(int x, int y, int z) {
        return (((x + 1) >> 3) * kCellBlocks + ((y + 1) >> 3)) * kCellBlocks + ((z + 1) >> 3);
    }
    /// Records a deposit from the dual cell (x, y, z) (or, for the box
    /// filter, into voxel (x, y, z), whose cell block is one of the voxel's).
    void mark(int x, int y, int z) {
        const int b = cellBlock(x, y, z);
        touched[b >> 6] |= uint64_t(1) << (b & 63);
    }
    bool isTouched(int bx, int by, int bz) const {
        const int b = (bx * kCellBlocks + by) * kCellBlocks + bz;
        return touched[b >> 6] >> (b & 63) & 1;
    }
    bool inside(const Vec3i& local) const {
        return unsigned(local.x()) < unsigned(kTile) && unsigned(local.y()) < unsigned(kTile) &&
               unsigned(local.z()) < unsigned(kTile);
    }
    /// Adds q to voxel `local` (in the tile: 0 .. kTile−1).
    void add(const Vec3i& local, const double* q) {
        mark(local.x(), local.y(), local.z());
        double* v = &values[size_t(index(local.x(), local.y(), local.z())) * C];
        for (int c = 0; c < C; ++c) v[c] += q[c];
    }
};


/// A tile's non-empty blocks, converted to floats.
struct TileBlocks {
    std::vector<Vec3i> origins;
    std::vector<DensityGrid::DensityBlockPtr> density;
    std::vector<DensityGrid::VelocityBlockPtr> velocity;
};


/// Deposits the `count` segments segments[ids[0 .. count)] into the tile
/// (the part of each whose voxels the tile owns), in that order, with the
/// box or the trilinear filter (`velocities`: their end-point velocities
/// when C = 4, else null), then moves the tile's non-empty blocks into `out`
/// as floats and clears the buffer (the border voxels too) for the next
/// tile. Defined for C = 1 and C = 4.
/// `avx2`: the trilinear density deposit (C = 1) runs the AVX2 kernel
/// (same values, bit for bit; only where hasAvx2()).
template <int C>
void fillTile(TileBuffer<C>& tile, bool box, bool avx2, const Segment* segments, const SegmentVelocity* velocities,
              const uint32_t* ids, size_t count, TileBlocks* out);

/// Whether this CPU runs the AVX2 kernel.
bool hasAvx2();

/// The trilinear density deposits of segments[ids[0 .. count)] into the
/// tile, in that order, four pieces at a time in AVX2 lanes
/// (render/volume/voxel_tiles_avx2.cpp; call only where hasAvx2()).
void depositTrilinearAvx2(TileBuffer<1>& tile, const Segment* segments, const uint32_t* ids, size_t count);

/// The SSE2 reference of the same deposit, for one segment.
void depositTrilinearReference(TileBuffer<1>& tile, const Segment& s);

}  // namespace hp::voxel_tiles
