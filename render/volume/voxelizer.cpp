#include "render/volume/voxelizer.h"

#include "core/errors.h"
#include "render/volume/voxel_tiles.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <ctime>
#include <functional>
#include <iterator>
#include <limits>
#include <memory>
#include <unordered_map>
#include <utility>

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

/// Allocates without initializing: each element is written once, in
/// parallel, by its producer (a value-initializing std::vector would first
/// zero the array on one thread, 166 MB of segments for B-vdb).
template <typename T>
struct BulkAllocator {
    using value_type = T;
    BulkAllocator() = default;
    template <typename U>
    BulkAllocator(const BulkAllocator<U>&) noexcept {}
    T* allocate(size_t n) { return std::allocator<T>().allocate(n); }
    void deallocate(T* p, size_t n) noexcept { std::allocator<T>().deallocate(p, n); }
    template <typename U>
    void construct(U* p) noexcept {
        ::new (static_cast<void*>(p)) U;  // default-initialized: no zeroing
    }
    template <typename U, typename... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
    template <typename U>
    bool operator==(const BulkAllocator<U>&) const noexcept { return true; }
    template <typename U>
    bool operator!=(const BulkAllocator<U>&) const noexcept { return false; }
};

template <typename T>
using BulkVector = std::vector<T, BulkAllocator<T>>;

/// The tiles segment g may deposit into, lo .. hi per axis; 0 if it has no
/// volume, else how many.
struct TileReach {
    double shift;  // the box filter rounds to the nearest centre
    int reach;     // the trilinear one reaches floor .. floor + 1
    size_t operator()(const Segment& g, Vec3i* lo, Vec3i* hi) const {
        *lo = tileOf(floorVec(g.a.cwiseMin(g.b) + Vec3d::Constant(shift)));
        *hi = tileOf(floorVec(g.a.cwiseMax(g.b) + Vec3d::Constant(shift)) + Vec3i::Constant(reach));
        const bool empty = g.k == 0 || (g.r0 == 0 && g.r1 == 0);
        return empty ? 0 : size_t((*hi - *lo + Vec3i::Ones()).prod());
    }
};

/// The tiles a segment reaches: lo .. lo + size − 1 per axis (size 0: none,
/// the segment has no volume). Computed where the segment is prepared, so
/// that binning reads 16 bytes a segment instead of the 72 of the segment.
struct TileSpan {
    int32_t lo[3];
    uint8_t size[3];  // ≤ 2: a part spans ≤ kMaxPartVoxels + 1 voxels < a tile
    uint8_t unused = 0;
    size_t count() const { return size_t(size[0]) * size[1] * size[2]; }
};

/// How many equal parts a segment spanning `d` (index space) is cut into.
size_t partsOf(const Vec3d& d) { return size_t(std::max(1.0, std::ceil(d.cwiseAbs().maxCoeff() / kMaxPartVoxels))); }

/// All segments with volume, prepared in index space, strands in Morton
/// order of their middle vertex: the segments one tile needs then lie close
/// together in memory (a Fibonacci lattice's strand order jumps around the
/// head, which made every tile's segment loads cache misses).
///
/// Two parallel passes over the strands, each mapping a vertex to index
/// space once: the first checks the range, takes the Morton code and counts
/// the parts; the second writes the segments. (The range check, the order,
/// the counts and the segments were four passes, the last two mapping each
/// vertex twice per segment: seven maps a vertex. The values are the same
/// expressions of the same mapped vertices, bit for bit.)
BulkVector<Segment> prepareSegments(const StrandFrame& strands, const GridTransform& transform, const TileReach& reach,
                                    std::vector<SegmentVelocity>* velocities, BulkVector<TileSpan>* spans) {
    const size_t n = strands.strandCount();
    const double limit = double(DensityGrid::kMaxIndex) - 2 * kTile;
    std::vector<std::pair<uint64_t, uint32_t>> order(n);
    std::vector<size_t> partCount(n);
    std::atomic<bool> outOfRange{false};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 64), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t s = range.begin(); s != range.end(); ++s) {
            const uint32_t begin = strands.first(s), end = strands.offsets[s + 1], middle = begin + (end - begin) / 2;
            uint64_t code = 0;
            size_t parts = 0;
            bool inRange = true;
            Vec3d previous = Vec3d::Zero();
            for (uint32_t v = begin; v < end; ++v) {
                const Vec3d p = transform.toIndex(strands.positions[v].cast<double>());
                if (!(p.cwiseAbs().maxCoeff() <= limit)) {
                    inRange = false;  // reported by checkRange below (parts would overflow)
                    break;
                }
                if (v > begin) parts += partsOf(p - previous);
                if (v == middle) {
                    auto q = [](double x) { return uint32_t(int64_t(std::floor(x)) >> kTileLog2) & 0x1FFFFF; };
                    code = morton(q(p.x()), q(p.y()), q(p.z()));
                }
                previous = p;
            }
            if (!inRange) outOfRange = true;
            order[s] = {code, uint32_t(s)};
            partCount[s] = parts;
        }
    });
    if (outOfRange) checkRange(strands, transform);  // throws, naming the first such vertex
    tbb::parallel_sort(order.begin(), order.end());  // unique pairs: a deterministic order

    // Each strand's first part.
    std::vector<size_t> first(n + 1, 0);
    for (size_t i = 0; i < n; ++i) first[i + 1] = first[i] + partCount[order[i].second];

    BulkVector<Segment> segments(first[n]);
    spans->resize(first[n]);
    if (velocities) velocities->assign(first[n], SegmentVelocity{Vec3f::Zero(), Vec3f::Zero()});
    const bool hasVelocities = velocities && !strands.velocities.empty();
    const double voxelVolume = transform.voxelVolume();
    std::atomic<bool> absurd{false};  // a radius that would overflow the deposits
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
        const size_t s = order[i].second;
        size_t out = first[i];
        const uint32_t begin = strands.first(s), end = strands.offsets[s + 1];
        if (end == begin) return;
        Vec3d a = transform.toIndex(strands.positions[begin].cast<double>());
        for (uint32_t v = begin + 1; v < end; ++v) {
            const Vec3d p0 = strands.positions[v - 1].cast<double>(), p1 = strands.positions[v].cast<double>();
            const Vec3d next = transform.toIndex(p1), d = next - a;
            const double r0 = strands.radii[v - 1], r1 = strands.radii[v];
            const size_t parts = partsOf(d);
            const double k = kPi * (p1 - p0).norm() / voxelVolume / double(parts);
            for (size_t j = 0; j < parts; ++j, ++out) {
                const double u0 = double(j) / double(parts), u1 = double(j + 1) / double(parts);
                Segment& g = segments[out];
                g.a = j == 0 ? a : Vec3d(a + d * u0);
                g.b = j + 1 == parts ? Vec3d(a + d) : Vec3d(a + d * u1);
                g.r0 = r0 + (r1 - r0) * u0;
                g.r1 = r0 + (r1 - r0) * u1;
                g.k = k;
                const double rMax = std::max(std::abs(g.r0), std::abs(g.r1));
                if (!(g.k * rMax * rMax < 1e30)) absurd = true;
                Vec3i lo, hi;
                TileSpan& span = (*spans)[out];
                const bool some = reach(g, &lo, &hi) > 0;
                for (int e = 0; e < 3; ++e) {
                    span.lo[e] = lo[e];
                    span.size[e] = some ? uint8_t(hi[e] - lo[e] + 1) : 0;
                }
                if (hasVelocities) {
                    const Vec3f& v0 = strands.velocities[v - 1];
                    const Vec3f dv = strands.velocities[v] - v0;
                    (*velocities)[out] = {v0 + dv * float(u0), v0 + dv * float(u1)};
                }
            }
            a = next;
        }
    });
    if (absurd) {  // the first such segment, for the message
        for (const Segment& g : segments) {
            const double rMax = std::max(std::abs(g.r0), std::abs(g.r1));
            if (!(g.k * rMax * rMax < 1e30))
                throw Error(cat("voxelize: a strand radius of ", rMax, " m is absurd for voxels of ",
                                std::cbrt(voxelVolume), " m"));
        }
    }
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
    BulkVector<uint32_t> segments;
};

/// Most slots of the dense tile table (8 bytes each: 32 MiB at most) before
/// binning falls back to a hash map: a head of hair fills a compact box of
/// tiles, strands spread far apart may not.
constexpr size_t kMaxDenseTiles = size_t(1) << 22;

/// Counting sort of the (tile, segment) pairs by tile, stable (segment order
/// within a tile), tiles in key order. `count`: pairs in all. Tiles are
/// counted in a dense table over the box of tiles reached when it is small
/// enough (one array index per pair), else in a hash map.
TileBins sortPairs(const BulkVector<TileSpan>& spans, size_t count) {
    // The box of tiles reached (a deterministic reduction: min and max).
    struct Box {
        Vec3i lo = Vec3i::Constant(std::numeric_limits<int>::max()), hi = Vec3i::Constant(std::numeric_limits<int>::min());
    };
    const Box box = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, spans.size(), 4096), Box(),
        [&](const tbb::blocked_range<size_t>& r, Box b) {
            for (size_t i = r.begin(); i != r.end(); ++i) {
                const TileSpan& t = spans[i];
                if (t.count() == 0) continue;
                for (int e = 0; e < 3; ++e) {
                    b.lo[e] = std::min(b.lo[e], t.lo[e]);
                    b.hi[e] = std::max(b.hi[e], t.lo[e] + t.size[e] - 1);
                }
            }
            return b;
        },
        [](Box x, const Box& y) {
            x.lo = x.lo.cwiseMin(y.lo);
            x.hi = x.hi.cwiseMax(y.hi);
            return x;
        });
    TileBins bins;
    if (count == 0) {
        bins.start.assign(1, 0);
        return bins;
    }
    const Vec3i extent = box.hi - box.lo + Vec3i::Ones();
    const double dense = double(extent.x()) * double(extent.y()) * double(extent.z());
    std::vector<uint32_t> slotOfPair;  // hash path only
    std::vector<size_t> sizes;
    std::unordered_map<uint64_t, uint32_t> slotOfKey;
    auto forEachPair = [&](auto&& visit) {  // visit(segment, slot), in pair order
        for (size_t i = 0; i < spans.size(); ++i) {
            const TileSpan& t = spans[i];
            const int dx = t.lo[0] - box.lo.x(), dy = t.lo[1] - box.lo.y(), dz = t.lo[2] - box.lo.z();
            for (int x = dx; x < dx + t.size[0]; ++x)
                for (int y = dy; y < dy + t.size[1]; ++y) {
                    const size_t row = (size_t(x) * size_t(extent.y()) + size_t(y)) * size_t(extent.z());
                    for (int z = dz; z < dz + t.size[2]; ++z) visit(i, row + size_t(z));
                }
        }
    };
    const bool useDense = dense <= double(kMaxDenseTiles);
    if (useDense) {
        sizes.assign(size_t(dense), 0);
        forEachPair([&](size_t, size_t slot) { ++sizes[slot]; });
    } else {
        // Sparse: a slot per tile met, numbered in order of first appearance.
        slotOfPair.resize(count);
        size_t p = 0, lastSlot = ~size_t(0);
        uint32_t last = 0;
        forEachPair([&](size_t, size_t slot) {
            if (slot != lastSlot) {
                lastSlot = slot;
                last = slotOfKey.emplace(slot, uint32_t(slotOfKey.size())).first->second;
            }
            slotOfPair[p++] = last;
        });
        sizes.assign(slotOfKey.size(), 0);
        for (uint32_t t : slotOfPair) ++sizes[t];
    }
    // Occupied slots in key order, then each one's first pair.
    auto coordOfSlot = [&](size_t slot) -> Vec3i {
        const size_t yz = size_t(extent.y()) * size_t(extent.z());
        return box.lo + Vec3i(int(slot / yz), int(slot / size_t(extent.z()) % size_t(extent.y())),
                              int(slot % size_t(extent.z())));
    };
    std::vector<std::pair<uint64_t, size_t>> occupied;  // (key, slot)
    if (useDense) {
        for (size_t slot = 0; slot < sizes.size(); ++slot)
            if (sizes[slot]) occupied.emplace_back(DensityGrid::blockKey(coordOfSlot(slot)), slot);
    } else {
        for (const auto& [denseSlot, slot] : slotOfKey)
            occupied.emplace_back(DensityGrid::blockKey(coordOfSlot(denseSlot)), slot);
    }
    std::sort(occupied.begin(), occupied.end());
    bins.keys.resize(occupied.size());
    bins.start.assign(occupied.size() + 1, 0);
    std::vector<size_t>& next = sizes;  // each slot's cursor, reusing the counts
    for (size_t r = 0; r < occupied.size(); ++r) {
        bins.keys[r] = occupied[r].first;
        bins.start[r + 1] = bins.start[r] + sizes[occupied[r].second];
        next[occupied[r].second] = bins.start[r];
    }
    bins.segments.resize(count);
    if (useDense) {
        forEachPair([&](size_t i, size_t slot) { bins.segments[next[slot]++] = uint32_t(i); });
    } else {
        size_t p = 0;
        forEachPair([&](size_t i, size_t) { bins.segments[next[slotOfPair[p++]]++] = uint32_t(i); });
    }
    return bins;
}

TileBins binSegments(const BulkVector<TileSpan>& spans, double maxBytes) {
    const size_t count = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, spans.size(), 4096), size_t(0),
        [&](const tbb::blocked_range<size_t>& r, size_t n) {
            for (size_t i = r.begin(); i != r.end(); ++i) n += spans[i].count();
            return n;
        },
        std::plus<size_t>());
    if (double(count) * 16.0 > maxBytes)
        throw Error(cat("voxelize: binning needs more than the memory limit (", count,
                        " segment-tile pairs); use a larger voxel size"));
    return sortPairs(spans, count);
}

template <int C>
DensityGrid voxelizeTiles(const StrandFrame& strands, const GridTransform& transform,
                          const VoxelizeSettings& settings, PhaseClock& clock) {
    std::vector<SegmentVelocity> velocities;
    const TileReach reach{settings.filter == VoxelFilter::Box ? 0.5 : 0.0, settings.filter == VoxelFilter::Box ? 0 : 1};
    BulkVector<TileSpan> spans;
    const BulkVector<Segment> segments =
        prepareSegments(strands, transform, reach, C == 4 ? &velocities : nullptr, &spans);
    if (segments.size() > size_t(UINT32_MAX)) throw Error("voxelize: too many segments; use a larger voxel size");
    clock.lap(&VoxelizePhases::prepare);
    const TileBins bins = binSegments(spans, settings.maxMemoryGiB * double(size_t(1) << 30));
    spans = BulkVector<TileSpan>();
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
    PhaseClock clock(settings.phases);  // the checks count as preparing (the range check is in prepareSegments)
    strands.validate();
    const double voxelVolume = transform.voxelVolume();
    if (!(voxelVolume > 0) || !std::isfinite(voxelVolume) || !transform.offset.allFinite())
        throw Error("voxelize: the grid transform is degenerate");
    return settings.velocity ? voxelizeTiles<4>(strands, transform, settings, clock)
                             : voxelizeTiles<1>(strands, transform, settings, clock);
}

}  // namespace hp
