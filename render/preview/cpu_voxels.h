// The light passes' hair voxelization on the CPU (Dehlin and Styngberg
// 2017's voxel grid, filled as shaders/voxelize.frag fills it). On a software
// renderer (llvmpipe) the GPU path pays the tessellation of every strand on
// llvmpipe's one calling thread and a fragment shader with image atomics per
// raster pixel; the strands' vertices are on the CPU already, so cutting them
// into the same pieces and walking the same raster pixels here, on every
// core, is several times cheaper (docs/benchmarks.md). A vendor GPU
// voxelizes faster by rasterizing: PreviewShadowSettings::voxelize chooses.
//
// What it reproduces, per light-pass piece (strand.tesc / strand.tese with
// MIN_SEGMENTS_PER_PIECE, voxel_lines.vert for the other lights):
// - the pieces: per patch (a strand, or a chunk of one), n = clamp(ceil(L /
//   pixels), 1, segments level) with L the polyline's length in the piece
//   light's raster, at least ceil(segments / minSegmentsPerPiece), on
//   ceil(n / 64) isolines; their ends on the Catmull-Rom or B-spline curve
//   (strand_curve.glsl), tangent and radius there;
// - the raster: GL's diamond-exit rule, one fragment per pixel along the
//   line's major axis, in the row the line crosses at that column's centre;
//   its attributes the line's at that centre, perspective-correct for a
//   point light;
// - the deposit: voxelize.frag's crossingWeight, rounded to the grid's fixed
//   point (kVoxelUnit), added to the fragment's voxel (nearest), or to the 8
//   around it with trilinear weights, or the largest kept (binary).
// Deposits are integers added with atomic adds: integer addition is exact
// and commutative, so the grid has the same bits whatever the thread count
// and order.
#pragma once

#include "render/preview/light_grid.h"
#include "render/preview/preview.h"
#include "sim/strands/strand.h"

#include <cstdint>
#include <vector>

namespace hp {

/// How the light passes cut strands into pieces (strand.tesc's rule).
struct LightPieceRule {
    int segmentsPerPatch = 29;    ///< most segments in one patch (StrandBuffers::patchSize - 3)
    int level = 8;                ///< most pieces per segment (tessellationLevel)
    float pixels = 20.f;          ///< target piece length in raster pixels of the pieces' grid; <= 0: the most
    int minSegmentsPerPiece = 0;  ///< at least a piece per this many segments; 0: no floor
    CurveType curve = CurveType::CatmullRom;
};

/// Where voxel (x, y, z) of a grid of `resolution`³ lies in the CPU's grids:
/// bricks of 8³ voxels (x fastest inside, then y, z; the bricks in the same
/// order), so that the deposits along a strand, which step through
/// neighbouring voxels in any direction, mostly stay within a brick's 2 KB
/// (a 256³ grid in rows of x is 64 MB touched a cache line per deposit).
inline size_t cpuVoxelIndex(int x, int y, int z, int resolution) {
    const size_t bricks = size_t((resolution + 7) / 8);
    const size_t brick = (size_t(z >> 3) * bricks + size_t(y >> 3)) * bricks + size_t(x >> 3);
    return brick * 512 + size_t(((z & 7) * 8 + (y & 7)) * 8 + (x & 7));
}
/// Voxels (padding included) of a CPU grid of `resolution`³.
size_t cpuVoxelCount(int resolution);

/// One light's grid to fill: r32ui units, kVoxelUnit (render/preview/preview_gpu.h) per crossing
/// (or per fragment), in cpuVoxelIndex's order; z is depth along the light.
struct CpuVoxelTarget {
    LightGrid grid;
    int resolution = 0;
    std::vector<uint32_t>* voxels = nullptr;  ///< resized to resolution³ and overwritten
};

/// Cuts `strands` into the pieces a light pass of `pieceGrid` (raster
/// `pieceResolution`²) draws and voxelizes them into every target, as
/// voxelize.frag with `shadow`'s mode, splat and weight. Parallel (TBB);
/// the result does not depend on the thread count.
void voxelizeStrandsOnCpu(const StrandFrame& strands, const LightPieceRule& rule, const LightGrid& pieceGrid,
                          int pieceResolution, const PreviewShadowSettings& shadow,
                          const std::vector<CpuVoxelTarget>& targets);

/// The preview's light grids on the CPU: every slot's `voxels[k]` filled
/// with the pieces its GPU light pass would draw (whole-strand patches of at
/// most `maxPatchVertices`, with sorted hair at least a piece per 4
/// segments, render/preview/preview.cpp), from the first slot's raster when
/// `share` (PreviewShadowSettings::shareTessellation), else each its own.
/// `strands` may be null (empty grids).
void voxelizeSlotsOnCpu(const StrandFrame* strands, const std::vector<ShadowSlot>& slots, const int* resolutions,
                        const PreviewSettings& settings, int maxPatchVertices, bool share,
                        std::vector<uint32_t>* voxels);

/// Dehlin and Styngberg's sum along the light, as shaders/prefix.comp sums
/// (the same float operations in the same order, so the same bits): C at
/// voxel z = sum over z' < z of V / kVoxelUnit (`sum`), else V / kVoxelUnit;
/// `out` in rows of x, then y, then z (the density texture's order).
void sumCpuVoxels(const std::vector<uint32_t>& voxels, int resolution, bool sum, std::vector<float>& out);
/// The grid's units in rows of x, then y, then z (the r32ui texture's order).
void linearCpuVoxels(const std::vector<uint32_t>& voxels, int resolution, std::vector<uint32_t>& out);

/// V (units / kVoxelUnit) in rows of x, then y, then z (VoxelSnapshot::raw).
std::vector<float> cpuVoxelValues(const std::vector<uint32_t>& voxels, int resolution);

/// Whether `voxelize` puts the voxelization on the CPU for a driver whose
/// GL_RENDERER is `renderer`: Auto does on a software rasterizer (llvmpipe,
/// softpipe).
bool voxelizeOnCpu(VoxelizeOn voxelize, const std::string& renderer);

}  // namespace hp
