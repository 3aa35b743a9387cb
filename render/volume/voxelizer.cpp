#include "render/volume/voxelizer.h"

#include "core/errors.h"
#include "render/volume/voxel_tiles.h"

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

#include <chrono>
#include <ctime>

namespace hp {

namespace {

using namespace voxel_tiles;

constexpr double kPi = 3.14159265358979323846;

/// Segments longer than this (in voxels) are split into equal parts, so a
/// part's bounding box spans at most 2 tiles per axis: small voxels do not
/// make a diagonal segment claim (and re-walk) a whole cube of tiles. The
/// split conserves volume exactly (the radius is linear along the segment).
constexpr double kMaxPartVoxels = kTile / 2;

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

/// Fills VoxelizeSettings::phases, if asked: wall and process CPU seconds
/// since the last lap.
class PhaseClock {
public:
    explicit PhaseClock(VoxelizePhases* phases) : phases_(phases) {
        if (phases_) *phases_ = VoxelizePhases();
        wall_ = std::chrono::steady_clock::now();
        cpu_ = cpuSeconds();
    }
    void lap(VoxelizePhases::Phase VoxelizePhases::*phase) {
        if (!phases_) return;
        const auto wall = std::chrono::steady_clock::now();
        const double cpu = cpuSeconds();
        phases_->*phase = {std::chrono::duration<double>(wall - wall_).count(), cpu - cpu_};
        wall_ = wall;
        cpu_ = cpu;
    }

private:
    static double cpuSeconds() {
        timespec ts{};
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
        return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
    }
    VoxelizePhases* phases_;
    std::chrono::steady_clock::time_point wall_;
    double cpu_ = 0;
};

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
                          const VoxelizeSettings& settings, PhaseClock& clock) {
    std::vector<SegmentVelocity> velocities;
    const std::vector<Segment> segments = prepareSegments(strands, transform, C == 4 ? &velocities : nullptr);
    if (segments.size() > size_t(UINT32_MAX)) throw Error("voxelize: too many segments; use a larger voxel size");
    for (const Segment& g : segments) {
        const double rMax = std::max(std::abs(g.r0), std::abs(g.r1));
        if (!(g.k * rMax * rMax < 1e30))
            throw Error(cat("voxelize: a strand radius of ", rMax, " m is absurd for voxels of ",
                            std::cbrt(transform.voxelVolume()), " m"));
    }
    clock.lap(&VoxelizePhases::prepare);
    const TileBins bins = binSegments(segments, settings.filter, settings.maxMemoryGiB * double(size_t(1) << 30));
    const size_t tiles = bins.keys.size();
    clock.lap(&VoxelizePhases::bin);

    const size_t limit = size_t(std::max(0.0, settings.maxMemoryGiB) * double(size_t(1) << 30));
    const size_t blockBytes = sizeof(DensityGrid::DensityBlock) + (C == 4 ? sizeof(DensityGrid::VelocityBlock) : 0);
    std::atomic<size_t> bytes{bins.segments.size() * sizeof(uint32_t) + segments.size() * sizeof(Segment) +
                              velocities.size() * sizeof(SegmentVelocity)};
    const bool avx2 = settings.kernel == VoxelKernel::Auto && hasAvx2();
    std::vector<TileBlocks> results(tiles);
    tbb::enumerable_thread_specific<TileBuffer<C>> buffers;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles, 1), [&](const tbb::blocked_range<size_t>& range) {
        TileBuffer<C>& tile = buffers.local();
        for (size_t t = range.begin(); t != range.end(); ++t) {
            tile.origin = DensityGrid::blockCoordOfKey(bins.keys[t]) * kTile;
            fillTile(tile, settings.filter == VoxelFilter::Box, avx2, segments.data(), C == 4 ? velocities.data() : nullptr,
                     &bins.segments[bins.start[t]], bins.start[t + 1] - bins.start[t], &results[t]);
            if (bytes.fetch_add(results[t].origins.size() * blockBytes) > limit)
                throw Error(cat("voxelize: the density grid needs more than ", settings.maxMemoryGiB,
                                " GiB; use a larger voxel size"));
        }
    });

    clock.lap(&VoxelizePhases::tiles);
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
    DensityGrid grid(transform, std::move(origins), std::move(density), std::move(velocity));
    clock.lap(&VoxelizePhases::gather);
    return grid;
}

}  // namespace

bool avx2KernelAvailable() { return hasAvx2(); }

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
    PhaseClock clock(settings.phases);  // the checks count as preparing
    strands.validate();
    const double voxelVolume = transform.voxelVolume();
    if (!(voxelVolume > 0) || !std::isfinite(voxelVolume) || !transform.offset.allFinite())
        throw Error("voxelize: the grid transform is degenerate");
    checkRange(strands, transform);
    return settings.velocity ? voxelizeTiles<4>(strands, transform, settings, clock)
                             : voxelizeTiles<1>(strands, transform, settings, clock);
}

}  // namespace hp
