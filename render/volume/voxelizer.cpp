#include "render/volume/voxelizer.h"

#include "core/errors.h"
#include "render/volume/cell_walk.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <iterator>
#include <limits>
#include <memory>
#include <unordered_map>

namespace hp {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kBlock = DensityGrid::kBlockSize;
constexpr int kBlockVoxels = DensityGrid::kBlockVoxels;

/// Tiles of 32³ voxels (4³ blocks) are the unit of parallel work: one task
/// owns a tile, accumulates every segment touching it into a dense buffer
/// that stays in cache (256 KiB of doubles), in a fixed segment order. So
/// each voxel's sum is formed in the same order whatever the thread count,
/// and no per-thread copies of the grid need merging.
constexpr int kTileLog2 = 5;
constexpr int kTile = 1 << kTileLog2;
constexpr int kTileVoxels = kTile * kTile * kTile;
constexpr int kBlocksPerTile = kTile / kBlock;

/// Three-point Gauss-Legendre on [-1, 1]: exact for polynomials of degree 5,
/// i.e. r(t)² (degree 2) times the trilinear weights (degree 3) along a line.
constexpr double kGaussX[3] = {-0.7745966692414834, 0.0, 0.7745966692414834};
constexpr double kGaussW[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};

/// A segment prepared for deposit: end points in index space, radii, and
/// k = π · L / voxel volume, which turns ∫ r² dt into density.
struct Segment {
    Vec3d a, b;
    double k;
    double r0, r1;
};

/// Segments longer than this (in voxels) are split into equal parts, so a
/// part's bounding box spans at most 2 tiles per axis: small voxels do not
/// make a diagonal segment claim (and re-walk) a whole cube of tiles. The
/// split conserves volume exactly (the radius is linear along the segment).
constexpr double kMaxPartVoxels = kTile / 2;

/// End-point velocities of a segment (only when the velocity channel is on).
struct SegmentVelocity {
    Vec3f v0, v1;
};

/// A tile's dense accumulator: C channels per voxel (density, or density and
/// momentum = density × velocity). Stored block by block in OpenVDB's leaf
/// order, so a block is extracted and cleared as one contiguous run.
template <int C>
struct TileBuffer {
    Vec3i origin;  // first voxel of the tile
    std::vector<double> values = std::vector<double>(size_t(kTileVoxels) * C, 0.0);
    static constexpr int kBlocks = kBlocksPerTile * kBlocksPerTile * kBlocksPerTile;
    uint64_t touched[(kBlocks + 63) / 64] = {};  // bit b: block b received deposits (sparse hair touches few)

    static int block(int x, int y, int z) { return ((x >> 3) * kBlocksPerTile + (y >> 3)) * kBlocksPerTile + (z >> 3); }
    /// Position of tile-local voxel (x, y, z) in `values`, in voxels.
    static int index(int x, int y, int z) {
        return block(x, y, z) * kBlockVoxels + DensityGrid::voxelOffset(x & 7, y & 7, z & 7);
    }
    static int index(const Vec3i& v) { return index(v.x(), v.y(), v.z()); }
    /// Voxel `local`'s C channels, marking its block touched.
    double* at(const Vec3i& local) {
        const int b = block(local.x(), local.y(), local.z());
        touched[b >> 6] |= uint64_t(1) << (b & 63);
        return &values[size_t(index(local)) * C];
    }
    bool inside(const Vec3i& local) const {
        return unsigned(local.x()) < unsigned(kTile) && unsigned(local.y()) < unsigned(kTile) &&
               unsigned(local.z()) < unsigned(kTile);
    }
    void add(const Vec3i& local, const double* q) {
        double* v = at(local);
        for (int c = 0; c < C; ++c) v[c] += q[c];
    }
};

/// Box filter: the segment's centre line cut at voxel faces; each piece's
/// exact volume goes to the voxel containing it (if that voxel is in the tile).
template <int C>
void depositBox(TileBuffer<C>& tile, const Segment& s, const SegmentVelocity* sv) {
    const Vec3d half = Vec3d::Constant(0.5);
    walkCells(s.a + half, s.b + half, [&](const Vec3i& voxel, double t0, double t1) {
        const Vec3i local = voxel - tile.origin;
        if (!tile.inside(local)) return;
        const double mid = 0.5 * (t0 + t1), h = 0.5 * (t1 - t0);
        double q[C] = {};
        for (int g = 0; g < 3; ++g) {
            const double t = mid + h * kGaussX[g];
            const double r = s.r0 + (s.r1 - s.r0) * t;
            const double w = s.k * h * kGaussW[g] * r * r;
            q[0] += w;
            if constexpr (C == 4) {
                const Vec3d v = sv->v0.cast<double>() + (sv->v1 - sv->v0).cast<double>() * t;
                for (int c = 0; c < 3; ++c) q[1 + c] += w * v[c];
            }
        }
        tile.add(local, q);
    });
}

/// Trilinear filter: the centre line cut at the planes through voxel centres
/// (dual cells); within a dual cell every point spreads its volume over the
/// cell's 8 corner voxels with trilinear weights, which sum to 1. The tile
/// keeps the corners it owns; the tiles owning the other corners compute the
/// same pieces (same walk over the whole segment) and keep theirs.
///
/// For a piece t ∈ [t0, t1] of dual cell c, corner (i, j, l) receives
///     k · ∫ r(t)² · X_i(t) · Y_j(t) · Z_l(t) dt,
/// X_1 = f_x(t) = a_x + d_x t − c_x, X_0 = 1 − X_1 (likewise Y, Z), r linear:
/// a degree-5 polynomial, integrated exactly by 3-point Gauss-Legendre.
///
/// This is the hot loop of the VDB export: the cell walk of cell_walk.h
/// (same planes, same intervals) is written out here so the deposit is
/// inlined into it, cells outside the tile cost one compare, and the 8
/// weights are formed as (w · X_i) · (Y_j · Z_l): 2 + 4 + 8 products per
/// Gauss point instead of 24.
template <int C>
void depositTrilinear(TileBuffer<C>& tile, const Segment& s, const SegmentVelocity* sv) {
    // Locals, not loads through `s`: the tile's stores are doubles too, so the
    // compiler could not otherwise keep these in registers.
    const double ax = s.a.x(), ay = s.a.y(), az = s.a.z();
    const double dx = s.b.x() - ax, dy = s.b.y() - ay, dz = s.b.z() - az;
    const double r0 = s.r0, dr = s.r1 - s.r0, k = s.k;
    int cell[3], step[3];
    double tMax[3], inv[3];
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const int origin[3] = {tile.origin.x(), tile.origin.y(), tile.origin.z()};
    // The part of the segment inside the dual cells that reach the tile,
    // [origin − 1, origin + kTile) per axis: t ∈ [tIn, tOut], its ends plane
    // crossings computed as the walk computes them.
    double tIn = 0, tOut = 1;
    for (int e = 0; e < 3; ++e) {
        const double a = s.a[e], d = s.b[e] - a;
        inv[e] = d != 0 ? 1.0 / d : 0.0;
        step[e] = d > 0 ? 1 : (d < 0 ? -1 : 0);
        const int lo = origin[e] - 1, hi = origin[e] + kTile;  // the box's planes
        if (step[e] == 0) {
            if (!(a >= lo && a < hi)) return;
            continue;
        }
        const double tLo = (lo - a) * inv[e], tHi = (hi - a) * inv[e];
        tIn = std::max(tIn, step[e] > 0 ? tLo : tHi);
        tOut = std::min(tOut, step[e] > 0 ? tHi : tLo);
    }
    if (!(tIn < tOut)) return;
    // The walk's state at tIn: along each axis, every plane whose crossing
    // time is ≤ tIn has been crossed (crossing times grow with the plane
    // index, also in floating point, so this is the state the walk from
    // t = 0 reaches; the pieces from tIn on are the same, bit for bit).
    for (int e = 0; e < 3; ++e) {
        const double a = s.a[e];
        const int start = int(std::floor(a));
        if (step[e] == 0) {
            cell[e] = start;
            tMax[e] = kInf;
            continue;
        }
        // Plane crossed when leaving cell c forwards: c + 1 (step > 0) or c (step < 0).
        auto exitTime = [&](int c) { return (c + (step[e] > 0 ? 1 : 0) - a) * inv[e]; };
        int c = tIn > 0 ? int(std::floor(a + (s.b[e] - a) * tIn)) : start;
        if (step[e] > 0 ? c < start : c > start) c = start;
        while (exitTime(c) <= tIn) c += step[e];
        while (c != start && exitTime(c - step[e]) > tIn) c -= step[e];
        cell[e] = c;
        tMax[e] = exitTime(c);
    }
    const int ox = origin[0], oy = origin[1], oz = origin[2];
    double* const values = tile.values.data();
    double t = tIn;
    for (;;) {
        int e = tMax[1] < tMax[0] ? 1 : 0;
        e = tMax[2] < tMax[e] ? 2 : e;
        const double t1 = std::min(tMax[e], 1.0);
        // Corner (0,0,0) of the dual cell in tile coordinates; the tile owns
        // voxels 0..kTile-1, so cells -1..kTile-1 reach it.
        const int lx = cell[0] - ox, ly = cell[1] - oy, lz = cell[2] - oz;
        if (t1 > t && unsigned(lx + 1) <= unsigned(kTile) && unsigned(ly + 1) <= unsigned(kTile) &&
            unsigned(lz + 1) <= unsigned(kTile)) {
            const double mid = 0.5 * (t + t1), h = 0.5 * (t1 - t);
            const double bx = ax - cell[0], by = ay - cell[1], bz = az - cell[2];
            double q[8][C] = {};  // corner (x-major: ix·4 + iy·2 + iz) × channel
            // Gauss point g of the piece: its parameter, weight k·h·w_g·r²
            // and fractional position in the dual cell.
            struct GaussPoint {
                double t, w, fx, fy, fz;
            };
            auto at = [&](int g) {
                const double tg = mid + h * kGaussX[g];
                const double r = r0 + dr * tg;
                return GaussPoint{tg, k * h * kGaussW[g] * r * r, std::min(std::max(bx + dx * tg, 0.0), 1.0),
                                  std::min(std::max(by + dy * tg, 0.0), 1.0),
                                  std::min(std::max(bz + dz * tg, 0.0), 1.0)};
            };
            if constexpr (C == 1) {
                // Density only: the z pair of each (x, y) corner as one SSE2
                // packet, (w · X_i · Y_j) · (Z_0, Z_1).
                Eigen::Array2d pair[4] = {Eigen::Array2d::Zero(), Eigen::Array2d::Zero(), Eigen::Array2d::Zero(),
                                          Eigen::Array2d::Zero()};
                for (int g = 0; g < 3; ++g) {
                    const GaussPoint p = at(g);
                    const double w = p.w, fx = p.fx, fy = p.fy, fz = p.fz;
                    const double wx0 = w * (1 - fx), wx1 = w * fx;
                    const Eigen::Array2d z(1 - fz, fz);
                    pair[0] += (wx0 * (1 - fy)) * z;
                    pair[1] += (wx0 * fy) * z;
                    pair[2] += (wx1 * (1 - fy)) * z;
                    pair[3] += (wx1 * fy) * z;
                }
                for (int i = 0; i < 4; ++i) {
                    q[2 * i][0] = pair[i][0];
                    q[2 * i + 1][0] = pair[i][1];
                }
            } else {
                for (int g = 0; g < 3; ++g) {
                    const GaussPoint p = at(g);
                    const double tg = p.t, w = p.w, fx = p.fx, fy = p.fy, fz = p.fz;
                    const double wx[2] = {w * (1 - fx), w * fx};
                    const double y[2] = {1 - fy, fy}, z[2] = {1 - fz, fz};
                    const Vec3d v = sv->v0.cast<double>() + (sv->v1 - sv->v0).cast<double>() * tg;
                    for (int i = 0; i < 8; ++i) {
                        const double c = (wx[i >> 2] * y[(i >> 1) & 1]) * z[i & 1];
                        q[i][0] += c;
                        for (int m = 0; m < 3; ++m) q[i][1 + m] += c * v[m];
                    }
                }
            }
            if (lx >= 0 && ly >= 0 && lz >= 0 && (lx & 7) != 7 && (ly & 7) != 7 && (lz & 7) != 7) {
                // All 8 corners in one block (7 cells in 8 along each axis;
                // lx < kTile - 1 follows from lx & 7 != 7).
                const int b = TileBuffer<C>::block(lx, ly, lz);
                tile.touched[b >> 6] |= uint64_t(1) << (b & 63);
                double* v = values + size_t(TileBuffer<C>::index(lx, ly, lz)) * C;
                for (int i = 0; i < 8; ++i) {
                    double* corner = v + DensityGrid::voxelOffset(i >> 2, (i >> 1) & 1, i & 1) * C;
                    for (int c = 0; c < C; ++c) corner[c] += q[i][c];
                }
            } else {
                const Vec3i local(lx, ly, lz);
                for (int i = 0; i < 8; ++i) {
                    const Vec3i corner = local + Vec3i(i >> 2, (i >> 1) & 1, i & 1);
                    if (tile.inside(corner)) tile.add(corner, q[i]);
                }
            }
        }
        if (tMax[e] >= tOut) return;  // tOut ≤ 1: the segment's end or the box's
        t = std::max(t, t1);
        // Recomputed from the plane rather than accumulated (as in cell_walk.h).
        cell[e] += step[e];
        tMax[e] = (cell[e] + (step[e] > 0 ? 1 : 0) - s.a[e]) * inv[e];
    }
}

/// A tile's non-empty blocks, converted to floats.
struct TileBlocks {
    std::vector<Vec3i> origins;
    std::vector<DensityGrid::DensityBlockPtr> density;
    std::vector<DensityGrid::VelocityBlockPtr> velocity;
};

/// Moves the tile's non-empty blocks into `out` as floats and clears them,
/// leaving the buffer zeroed for the next tile.
template <int C>
void extractBlocks(TileBuffer<C>& tile, TileBlocks* out) {
    for (int b = 0; b < kBlocksPerTile * kBlocksPerTile * kBlocksPerTile; ++b) {
        if (!(tile.touched[b >> 6] >> (b & 63) & 1)) continue;
        double* v = &tile.values[size_t(b) * kBlockVoxels * C];
        bool any = false;
        for (int i = 0; i < kBlockVoxels; ++i) any |= v[i * C] > 0;
        if (!any) {  // only zero deposits (e.g. exactly on a voxel plane): nothing active
            std::fill(v, v + size_t(kBlockVoxels) * C, 0.0);
            continue;
        }
        const Vec3i local(b / (kBlocksPerTile * kBlocksPerTile), (b / kBlocksPerTile) % kBlocksPerTile,
                          b % kBlocksPerTile);
        out->origins.push_back(tile.origin + local * kBlock);
        out->density.emplace_back(new DensityGrid::DensityBlock);  // every voxel written below
        DensityGrid::DensityBlock& density = *out->density.back();
        for (int i = 0; i < kBlockVoxels; ++i) density[size_t(i)] = float(v[i * C]);
        if constexpr (C == 4) {
            out->velocity.emplace_back(new DensityGrid::VelocityBlock);
            DensityGrid::VelocityBlock& velocity = *out->velocity.back();
            for (int i = 0; i < kBlockVoxels; ++i) {
                const double* m = v + i * C;
                const double w = m[0] > 0 ? 1.0 / m[0] : 0.0;
                velocity[size_t(i)] = Vec3f(float(m[1] * w), float(m[2] * w), float(m[3] * w));
            }
        }
        std::fill(v, v + size_t(kBlockVoxels) * C, 0.0);
    }
    std::fill(std::begin(tile.touched), std::end(tile.touched), 0);
}

void checkRange(const StrandFrame& strands, const GridTransform& transform) {
    const double limit = double(DensityGrid::kMaxIndex) - 2 * kTile;
    for (const Vec3f& p : strands.positions) {
        const Vec3d i = transform.toIndex(p.cast<double>());
        if (!(i.cwiseAbs().maxCoeff() <= limit))
            throw Error(cat("voxelize: a strand vertex at (", p.transpose(), ") m lies ", i.cwiseAbs().maxCoeff(),
                            " voxels from the grid origin, beyond the limit of ", limit,
                            " (is the voxel size far too small?)"));
    }
}

Vec3i floorVec(const Vec3d& p) { return Vec3i(int(std::floor(p.x())), int(std::floor(p.y())), int(std::floor(p.z()))); }

Vec3i tileOf(const Vec3i& voxel) { return Vec3i(voxel.x() >> kTileLog2, voxel.y() >> kTileLog2, voxel.z() >> kTileLog2); }

/// Interleaves the low 21 bits of x, y and z (Morton order).
uint64_t morton(uint32_t x, uint32_t y, uint32_t z) {
    auto spread = [](uint64_t v) {
        v &= 0x1FFFFF;
        v = (v | v << 32) & 0x1F00000000FFFFull;
        v = (v | v << 16) & 0x1F0000FF0000FFull;
        v = (v | v << 8) & 0x100F00F00F00F00Full;
        v = (v | v << 4) & 0x10C30C30C30C30C3ull;
        v = (v | v << 2) & 0x1249249249249249ull;
        return v;
    };
    return spread(x) << 2 | spread(y) << 1 | spread(z);
}

/// All segments with volume, prepared in index space, strands in Morton
/// order of their middle vertex: the segments one tile needs then lie close
/// together in memory (a Fibonacci lattice's strand order jumps around the
/// head, which made every tile's segment loads cache misses).
std::vector<Segment> prepareSegments(const StrandFrame& strands, const GridTransform& transform,
                                     std::vector<SegmentVelocity>* velocities) {
    const size_t n = strands.strandCount();
    std::vector<std::pair<uint64_t, uint32_t>> order(n);
    tbb::parallel_for(size_t(0), n, [&](size_t s) {
        const uint32_t count = strands.vertexCount(s);
        uint64_t code = 0;
        if (count > 0) {
            const Vec3d p = transform.toIndex(strands.positions[strands.first(s) + count / 2].cast<double>());
            auto q = [](double v) { return uint32_t(int64_t(std::floor(v)) >> kTileLog2) & 0x1FFFFF; };
            code = morton(q(p.x()), q(p.y()), q(p.z()));
        }
        order[s] = {code, uint32_t(s)};
    });
    tbb::parallel_sort(order.begin(), order.end());  // unique pairs: a deterministic order

    // Parts per segment (long segments split), then each strand's first part.
    auto partsOf = [&](uint32_t v) {
        const double length = (transform.toIndex(strands.positions[v].cast<double>()) -
                               transform.toIndex(strands.positions[v - 1].cast<double>()))
                                  .cwiseAbs()
                                  .maxCoeff();
        return size_t(std::max(1.0, std::ceil(length / kMaxPartVoxels)));
    };
    std::vector<size_t> first(n + 1, 0);
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
        const size_t s = order[i].second;
        size_t parts = 0;
        for (uint32_t v = strands.first(s) + 1; v < strands.offsets[s + 1]; ++v) parts += partsOf(v);
        first[i + 1] = parts;
    });
    for (size_t i = 0; i < n; ++i) first[i + 1] += first[i];

    std::vector<Segment> segments(first[n]);
    if (velocities) velocities->assign(first[n], SegmentVelocity{Vec3f::Zero(), Vec3f::Zero()});
    const bool hasVelocities = velocities && !strands.velocities.empty();
    const double voxelVolume = transform.voxelVolume();
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
        const size_t s = order[i].second;
        size_t out = first[i];
        for (uint32_t v = strands.first(s) + 1; v < strands.offsets[s + 1]; ++v) {
            const Vec3d p0 = strands.positions[v - 1].cast<double>(), p1 = strands.positions[v].cast<double>();
            const Vec3d a = transform.toIndex(p0), d = transform.toIndex(p1) - a;
            const double r0 = strands.radii[v - 1], r1 = strands.radii[v];
            const size_t parts = partsOf(v);
            const double k = kPi * (p1 - p0).norm() / voxelVolume / double(parts);
            for (size_t j = 0; j < parts; ++j, ++out) {
                const double u0 = double(j) / double(parts), u1 = double(j + 1) / double(parts);
                Segment& g = segments[out];
                g.a = j == 0 ? a : Vec3d(a + d * u0);
                g.b = j + 1 == parts ? Vec3d(a + d) : Vec3d(a + d * u1);
                g.r0 = r0 + (r1 - r0) * u0;
                g.r1 = r0 + (r1 - r0) * u1;
                g.k = k;
                if (hasVelocities) {
                    const Vec3f& v0 = strands.velocities[v - 1];
                    const Vec3f dv = strands.velocities[v] - v0;
                    (*velocities)[out] = {v0 + dv * float(u0), v0 + dv * float(u1)};
                }
            }
        }
    });
    return segments;
}

/// Segments grouped by the tiles they may deposit into: tile t (key
/// keys[t], sorted) owns segments[start[t] .. start[t+1]), in segment order.
struct TileBins {
    std::vector<uint64_t> keys;
    std::vector<size_t> start;
    std::vector<uint32_t> segments;
};

TileBins binSegments(const std::vector<Segment>& segments, VoxelFilter filter, double maxBytes) {
    // Voxels reached: the box filter rounds to the nearest centre, the
    // trilinear one reaches floor .. floor + 1.
    const double shift = filter == VoxelFilter::Box ? 0.5 : 0.0;
    const int reach = filter == VoxelFilter::Box ? 0 : 1;
    auto tiles = [&](const Segment& g, Vec3i* lo, Vec3i* hi) {
        *lo = tileOf(floorVec(g.a.cwiseMin(g.b) + Vec3d::Constant(shift)));
        *hi = tileOf(floorVec(g.a.cwiseMax(g.b) + Vec3d::Constant(shift)) + Vec3i::Constant(reach));
        const bool empty = g.k == 0 || (g.r0 == 0 && g.r1 == 0);
        return empty ? 0 : size_t((*hi - *lo + Vec3i::Ones()).prod());
    };
    // (tile, segment) pairs in segment order: count, scan, fill.
    std::vector<size_t> first(segments.size() + 1, 0);
    tbb::parallel_for(size_t(0), segments.size(), [&](size_t i) {
        Vec3i lo, hi;
        first[i + 1] = tiles(segments[i], &lo, &hi);
    });
    for (size_t i = 0; i < segments.size(); ++i) first[i + 1] += first[i];
    const size_t count = first.back();
    if (double(count) * 16.0 > maxBytes)
        throw Error(cat("voxelize: binning needs more than the memory limit (", count,
                        " segment-tile pairs); use a larger voxel size"));
    std::vector<uint64_t> pairKeys(count);
    tbb::parallel_for(size_t(0), segments.size(), [&](size_t i) {
        Vec3i lo, hi;
        if (tiles(segments[i], &lo, &hi) == 0) return;
        uint64_t* out = &pairKeys[first[i]];
        for (int x = lo.x(); x <= hi.x(); ++x)
            for (int y = lo.y(); y <= hi.y(); ++y)
                for (int z = lo.z(); z <= hi.z(); ++z) *out++ = DensityGrid::blockKey(Vec3i(x, y, z));
    });
    // Counting sort by tile (stable: segment order is kept within a tile).
    // Segments come in spatial order, so consecutive pairs mostly share a
    // tile and the hash lookups hit the one-entry cache.
    std::unordered_map<uint64_t, uint32_t> tileOfKey;
    std::vector<uint32_t> pairTile(count);
    uint64_t lastKey = ~uint64_t(0);
    uint32_t lastTile = 0;
    for (size_t p = 0; p < count; ++p) {
        if (pairKeys[p] != lastKey) {
            lastKey = pairKeys[p];
            lastTile = tileOfKey.emplace(lastKey, uint32_t(tileOfKey.size())).first->second;
        }
        pairTile[p] = lastTile;
    }
    TileBins bins;
    std::vector<std::pair<uint64_t, uint32_t>> sorted;  // (key, tile id), sorted by key
    for (const auto& kv : tileOfKey) sorted.emplace_back(kv.first, kv.second);
    std::sort(sorted.begin(), sorted.end());
    std::vector<size_t> rank(sorted.size()), sizes(sorted.size(), 0);
    for (size_t r = 0; r < sorted.size(); ++r) rank[sorted[r].second] = r;
    for (size_t p = 0; p < count; ++p) ++sizes[rank[pairTile[p]]];
    bins.keys.resize(sorted.size());
    bins.start.assign(sorted.size() + 1, 0);
    for (size_t r = 0; r < sorted.size(); ++r) {
        bins.keys[r] = sorted[r].first;
        bins.start[r + 1] = bins.start[r] + sizes[r];
    }
    std::vector<size_t> next(bins.start.begin(), bins.start.end() - 1);
    bins.segments.resize(count);
    for (size_t i = 0; i < segments.size(); ++i)
        for (size_t p = first[i]; p < first[i + 1]; ++p) bins.segments[next[rank[pairTile[p]]]++] = uint32_t(i);
    return bins;
}

template <int C>
DensityGrid voxelizeTiles(const StrandFrame& strands, const GridTransform& transform,
                          const VoxelizeSettings& settings) {
    std::vector<SegmentVelocity> velocities;
    const std::vector<Segment> segments = prepareSegments(strands, transform, C == 4 ? &velocities : nullptr);
    if (segments.size() > size_t(UINT32_MAX)) throw Error("voxelize: too many segments; use a larger voxel size");
    for (const Segment& g : segments) {
        const double rMax = std::max(std::abs(g.r0), std::abs(g.r1));
        if (!(g.k * rMax * rMax < 1e30))
            throw Error(cat("voxelize: a strand radius of ", rMax, " m is absurd for voxels of ",
                            std::cbrt(transform.voxelVolume()), " m"));
    }
    const TileBins bins = binSegments(segments, settings.filter, settings.maxMemoryGiB * double(size_t(1) << 30));
    const size_t tiles = bins.keys.size();

    const size_t limit = size_t(std::max(0.0, settings.maxMemoryGiB) * double(size_t(1) << 30));
    const size_t blockBytes = sizeof(DensityGrid::DensityBlock) + (C == 4 ? sizeof(DensityGrid::VelocityBlock) : 0);
    std::atomic<size_t> bytes{bins.segments.size() * sizeof(uint32_t) + segments.size() * sizeof(Segment) +
                              velocities.size() * sizeof(SegmentVelocity)};
    std::vector<TileBlocks> results(tiles);
    tbb::enumerable_thread_specific<TileBuffer<C>> buffers;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles, 1), [&](const tbb::blocked_range<size_t>& range) {
        TileBuffer<C>& tile = buffers.local();
        for (size_t t = range.begin(); t != range.end(); ++t) {
            tile.origin = DensityGrid::blockCoordOfKey(bins.keys[t]) * kTile;
            for (size_t i = bins.start[t]; i < bins.start[t + 1]; ++i) {
                const uint32_t g = bins.segments[i];
                const SegmentVelocity* v = C == 4 ? &velocities[g] : nullptr;
                if (settings.filter == VoxelFilter::Box)
                    depositBox(tile, segments[g], v);
                else
                    depositTrilinear(tile, segments[g], v);
            }
            extractBlocks(tile, &results[t]);
            if (bytes.fetch_add(results[t].origins.size() * blockBytes) > limit)
                throw Error(cat("voxelize: the density grid needs more than ", settings.maxMemoryGiB,
                                " GiB; use a larger voxel size"));
        }
    });

    // Concatenate in tile order (sorted keys), independent of scheduling.
    size_t total = 0;
    for (const TileBlocks& r : results) total += r.origins.size();
    std::vector<Vec3i> origins;
    std::vector<DensityGrid::DensityBlockPtr> density;
    std::vector<DensityGrid::VelocityBlockPtr> velocity;
    origins.reserve(total);
    density.reserve(total);
    if (C == 4) velocity.reserve(total);
    for (TileBlocks& r : results) {
        origins.insert(origins.end(), r.origins.begin(), r.origins.end());
        std::move(r.density.begin(), r.density.end(), std::back_inserter(density));
        std::move(r.velocity.begin(), r.velocity.end(), std::back_inserter(velocity));
        r = TileBlocks();
    }
    return DensityGrid(transform, std::move(origins), std::move(density), std::move(velocity));
}

}  // namespace

double hairVolume(const StrandFrame& strands) {
    double sum = 0;
    for (size_t s = 0; s < strands.strandCount(); ++s)
        for (uint32_t v = strands.first(s) + 1; v < strands.offsets[s + 1]; ++v) {
            const double L = (strands.positions[v].cast<double>() - strands.positions[v - 1].cast<double>()).norm();
            const double r0 = strands.radii[v - 1], r1 = strands.radii[v];
            sum += kPi * L * (r0 * r0 + r0 * r1 + r1 * r1) / 3.0;
        }
    return sum;
}

DensityGrid voxelize(const StrandFrame& strands, const GridTransform& transform, const VoxelizeSettings& settings) {
    strands.validate();
    const double voxelVolume = transform.voxelVolume();
    if (!(voxelVolume > 0) || !std::isfinite(voxelVolume) || !transform.offset.allFinite())
        throw Error("voxelize: the grid transform is degenerate");
    checkRange(strands, transform);
    return settings.velocity ? voxelizeTiles<4>(strands, transform, settings)
                             : voxelizeTiles<1>(strands, transform, settings);
}

}  // namespace hp
