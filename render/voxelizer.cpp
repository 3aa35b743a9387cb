#include "render/voxelizer.h"

#include "core/errors.h"
#include "render/cell_walk.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <unordered_map>

namespace hp {

namespace {

constexpr int kBlockVoxels = DensityGrid::kBlockVoxels;
constexpr int kMask = DensityGrid::kBlockSize - 1;
constexpr int kLog2 = DensityGrid::kBlockLog2;

/// Fixed-point unit of accumulation: 2^-40 of one unit of density. Integer
/// sums do not depend on the order of additions (the thread-count
/// independence rests on this); the largest representable voxel density is
/// 2^23 ≈ 8e6 (real hair stays ≤ 1), the smallest step ≈ 1e-12.
constexpr double kPi = 3.14159265358979323846;
constexpr double kFixed = 1099511627776.0;  // 2^40
constexpr double kMaxDeposit = 4.6e18;       // < 2^62: a single segment may not come near overflow

/// Three-point Gauss-Legendre on [-1, 1]: exact for polynomials of degree 5,
/// i.e. r(t)² (degree 2) times the trilinear weights (degree 3) along a line.
constexpr double kGaussX[3] = {-0.7745966692414834, 0.0, 0.7745966692414834};
constexpr double kGaussW[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};

/// One thread's sparse accumulation blocks. Channels per voxel: density, or
/// density and three momentum components (density × velocity).
class Accumulator {
  public:
    Accumulator(int channels, std::atomic<size_t>* bytes, size_t limit)
        : channels_(channels), bytes_(bytes), limit_(limit) {
        std::fill(std::begin(cacheKey_), std::end(cacheKey_), ~uint64_t(0));
    }

    /// The block at block coordinate `c`, created zeroed on first use.
    int64_t* block(const Vec3i& c) {
        // A direct-mapped cache on the coordinates' low bits holds a whole
        // 2×2×2 neighbourhood of blocks, so a dual cell straddling block
        // faces does not thrash it; strands are spatially coherent.
        const int slot = ((c.x() & 1) << 2) | ((c.y() & 1) << 1) | (c.z() & 1);
        const uint64_t key = blockKey(c);
        if (cacheKey_[slot] == key) return cache_[slot];
        auto [it, inserted] = blocks_.try_emplace(key, nullptr);
        if (inserted) {
            const size_t n = size_t(kBlockVoxels) * size_t(channels_);
            if (bytes_->fetch_add(n * sizeof(int64_t)) + n * sizeof(int64_t) > limit_) {
                blocks_.erase(it);
                throw Error(cat("voxelize: the density grid needs more than ", double(limit_) / double(1u << 30),
                                " GiB of accumulation memory; use a larger voxel size"));
            }
            storage_.emplace_back(new int64_t[n]());
            it->second = storage_.back().get();
        }
        cacheKey_[slot] = key;
        cache_[slot] = it->second;
        return it->second;
    }

    /// The block at `key`, or null when this thread never touched it.
    const int64_t* find(uint64_t key) const {
        const auto it = blocks_.find(key);
        return it == blocks_.end() ? nullptr : it->second;
    }

    void appendKeys(std::vector<uint64_t>* keys) const {
        for (const auto& kv : blocks_) keys->push_back(kv.first);
    }

  private:
    int channels_;
    std::atomic<size_t>* bytes_;
    size_t limit_;
    std::unordered_map<uint64_t, int64_t*> blocks_;
    std::vector<std::unique_ptr<int64_t[]>> storage_;
    uint64_t cacheKey_[8];
    int64_t* cache_[8] = {};
};

Vec3i blockOfVoxel(const Vec3i& v) { return Vec3i(v.x() >> kLog2, v.y() >> kLog2, v.z() >> kLog2); }
int offsetOfVoxel(const Vec3i& v) { return DensityGrid::voxelOffset(v.x() & kMask, v.y() & kMask, v.z() & kMask); }

/// Round to the nearest fixed-point step (half away from zero). Deposits
/// are rounded one by one, so the sum does not depend on how they are grouped.
inline int64_t fixedPoint(double x) { return int64_t(x < 0 ? x - 0.5 : x + 0.5); }

/// A segment prepared for deposit: end points in index space, radii, and the
/// factor turning r² · dt into fixed-point density (π · L / voxel volume · 2^40).
struct Segment {
    Vec3d a, b;
    double r0, r1;
    Vec3d v0, v1;
    double k;
};

/// Adds C channels of `value` at `voxel`.
template <int C>
inline void add(Accumulator& acc, const Vec3i& voxel, const double* value) {
    int64_t* block = acc.block(blockOfVoxel(voxel)) + size_t(offsetOfVoxel(voxel)) * C;
    for (int c = 0; c < C; ++c) block[c] += fixedPoint(value[c]);
}

/// Box filter: the segment's centre line cut at voxel faces; each piece's
/// exact volume goes to the voxel containing it. C = 1 (density) or 4 (+ momentum).
template <int C>
void depositBox(Accumulator& acc, const Segment& s) {
    const Vec3d half = Vec3d::Constant(0.5);
    walkCells(s.a + half, s.b + half, [&](const Vec3i& voxel, double t0, double t1) {
        const double mid = 0.5 * (t0 + t1), h = 0.5 * (t1 - t0);
        double q[C] = {};
        for (int g = 0; g < 3; ++g) {
            const double t = mid + h * kGaussX[g];
            const double r = s.r0 + (s.r1 - s.r0) * t;
            const double w = s.k * h * kGaussW[g] * r * r;
            q[0] += w;
            if constexpr (C == 4) {
                const Vec3d v = s.v0 + (s.v1 - s.v0) * t;
                for (int c = 0; c < 3; ++c) q[1 + c] += w * v[c];
            }
        }
        add<C>(acc, voxel, q);
    });
}

/// Trilinear filter: the centre line cut at the planes through voxel
/// centres (dual cells); within a dual cell each point spreads its volume over
/// the cell's 8 corner voxels with trilinear weights (which sum to 1).
template <int C>
void depositTrilinear(Accumulator& acc, const Segment& s) {
    const Vec3d d = s.b - s.a;
    walkCells(s.a, s.b, [&](const Vec3i& cell, double t0, double t1) {
        const double mid = 0.5 * (t0 + t1), h = 0.5 * (t1 - t0);
        const Vec3d base = s.a - cell.cast<double>();
        double q[8][C] = {};  // corner (x-major: ix·4 + iy·2 + iz) × channel
        for (int g = 0; g < 3; ++g) {
            const double t = mid + h * kGaussX[g];
            const double r = s.r0 + (s.r1 - s.r0) * t;
            const double w = s.k * h * kGaussW[g] * r * r;
            const Vec3d f = (base + d * t).cwiseMax(0.0).cwiseMin(1.0);
            const double wx[2] = {1 - f.x(), f.x()}, wy[2] = {1 - f.y(), f.y()}, wz[2] = {1 - f.z(), f.z()};
            Vec3d v;
            if constexpr (C == 4) v = s.v0 + (s.v1 - s.v0) * t;
            for (int i = 0; i < 8; ++i) {
                const double c = w * wx[i >> 2] * wy[(i >> 1) & 1] * wz[i & 1];
                q[i][0] += c;
                if constexpr (C == 4)
                    for (int k = 0; k < 3; ++k) q[i][1 + k] += c * v[k];
            }
        }
        if ((cell.x() & kMask) != kMask && (cell.y() & kMask) != kMask && (cell.z() & kMask) != kMask) {
            // All 8 corners in one block (7 cells in 8 along each axis).
            int64_t* block = acc.block(blockOfVoxel(cell)) + size_t(offsetOfVoxel(cell)) * C;
            for (int i = 0; i < 8; ++i) {
                int64_t* voxel = block + DensityGrid::voxelOffset(i >> 2, (i >> 1) & 1, i & 1) * C;
                for (int c = 0; c < C; ++c) voxel[c] += fixedPoint(q[i][c]);
            }
        } else {
            for (int i = 0; i < 8; ++i) add<C>(acc, cell + Vec3i(i >> 2, (i >> 1) & 1, i & 1), q[i]);
        }
    });
}

/// Interleaves the low 21 bits of x, y, z (Morton order).
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

/// Strand indices in Morton order of their middle vertex's block. Neighbouring
/// strands then fill the same blocks while they are in cache (the file order
/// of a Fibonacci lattice jumps around the head). The order does not change
/// the result: accumulation is in integers.
std::vector<uint32_t> spatialOrder(const StrandFrame& strands, const GridTransform& transform) {
    const size_t n = strands.strandCount();
    std::vector<std::pair<uint64_t, uint32_t>> keyed(n);
    for (size_t s = 0; s < n; ++s) {
        const uint32_t count = strands.vertexCount(s);
        uint64_t code = 0;
        if (count > 0) {
            const Vec3d p = transform.toIndex(strands.positions[strands.first(s) + count / 2].cast<double>());
            const auto q = [](double v) { return uint32_t(int64_t(std::floor(v / DensityGrid::kBlockSize)) + (1 << 20)); };
            code = morton(q(p.x()), q(p.y()), q(p.z()));
        }
        keyed[s] = {code, uint32_t(s)};
    }
    std::sort(keyed.begin(), keyed.end());
    std::vector<uint32_t> order(n);
    for (size_t i = 0; i < n; ++i) order[i] = keyed[i].second;
    return order;
}

void checkRange(const StrandFrame& strands, const GridTransform& transform) {
    const double limit = double(DensityGrid::kMaxIndex) - 2 * DensityGrid::kBlockSize;
    for (const Vec3f& p : strands.positions) {
        const Vec3d i = transform.toIndex(p.cast<double>());
        if (!(i.cwiseAbs().maxCoeff() <= limit))
            throw Error(cat("voxelize: a strand vertex at (", p.transpose(), ") m lies ", i.cwiseAbs().maxCoeff(),
                            " voxels from the grid origin, beyond the limit of ", limit,
                            " (is the voxel size far too small?)"));
    }
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
    checkRange(strands, transform);
    const bool velocity = settings.velocity;
    const int channels = velocity ? 4 : 1;
    const double voxelVolume = transform.voxelVolume();
    if (!(voxelVolume > 0) || !std::isfinite(voxelVolume)) throw Error("voxelize: the grid transform is degenerate");

    std::atomic<size_t> bytes{0};
    const size_t limit = size_t(std::max(0.0, settings.maxMemoryGiB) * double(size_t(1) << 30));
    tbb::enumerable_thread_specific<Accumulator> accumulators([&] { return Accumulator(channels, &bytes, limit); });
    const bool hasVelocities = !strands.velocities.empty();

    const std::vector<uint32_t> order = spatialOrder(strands, transform);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, order.size(), 64), [&](const tbb::blocked_range<size_t>& range) {
        Accumulator& acc = accumulators.local();
        for (size_t i = range.begin(); i != range.end(); ++i) {
            const size_t s = order[i];
            for (uint32_t v = strands.first(s) + 1; v < strands.offsets[s + 1]; ++v) {
                const Vec3d p0 = strands.positions[v - 1].cast<double>(), p1 = strands.positions[v].cast<double>();
                Segment seg;
                seg.a = transform.toIndex(p0);
                seg.b = transform.toIndex(p1);
                seg.r0 = strands.radii[v - 1];
                seg.r1 = strands.radii[v];
                seg.v0 = hasVelocities ? Vec3d(strands.velocities[v - 1].cast<double>()) : Vec3d::Zero();
                seg.v1 = hasVelocities ? Vec3d(strands.velocities[v].cast<double>()) : Vec3d::Zero();
                seg.k = kPi * (p1 - p0).norm() / voxelVolume * kFixed;
                const double rMax = std::max(std::abs(seg.r0), std::abs(seg.r1));
                if (seg.k * rMax * rMax == 0) continue;  // no volume to deposit
                if (!(seg.k * rMax * rMax < kMaxDeposit))
                    throw Error(cat("voxelize: strand ", strands.ids.empty() ? s : strands.ids[s], " radius ", rMax,
                                    " m is too thick for voxels of ", std::cbrt(voxelVolume),
                                    " m (density would overflow)"));
                const bool box = settings.filter == VoxelFilter::Box;
                if (velocity)
                    box ? depositBox<4>(acc, seg) : depositTrilinear<4>(acc, seg);
                else
                    box ? depositBox<1>(acc, seg) : depositTrilinear<1>(acc, seg);
            }
        }
    });

    // Merge: the union of touched blocks in sorted order, each summed over
    // the threads (integers: the order of threads does not matter).
    std::vector<const Accumulator*> parts;
    std::vector<uint64_t> keys;
    for (const Accumulator& acc : accumulators) {
        parts.push_back(&acc);
        acc.appendKeys(&keys);
    }
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());

    std::vector<DensityGrid::DensityBlock> density(keys.size());
    std::vector<DensityGrid::VelocityBlock> momentum(velocity ? keys.size() : 0);
    std::vector<char> keep(keys.size(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, keys.size(), 16), [&](const tbb::blocked_range<size_t>& range) {
        std::vector<int64_t> sum(size_t(kBlockVoxels) * size_t(channels));
        for (size_t b = range.begin(); b != range.end(); ++b) {
            std::fill(sum.begin(), sum.end(), 0);
            for (const Accumulator* part : parts)
                if (const int64_t* block = part->find(keys[b]))
                    for (size_t i = 0; i < sum.size(); ++i) sum[i] += block[i];
            for (int i = 0; i < kBlockVoxels; ++i) {
                const int64_t* voxel = &sum[size_t(i) * size_t(channels)];
                density[b][size_t(i)] = float(double(voxel[0]) / kFixed);
                if (voxel[0] > 0) keep[b] = 1;
                if (velocity) {
                    const double w = voxel[0] > 0 ? 1.0 / double(voxel[0]) : 0.0;
                    momentum[b][size_t(i)] =
                        Vec3f(float(double(voxel[1]) * w), float(double(voxel[2]) * w), float(double(voxel[3]) * w));
                }
            }
        }
    });
    accumulators.clear();

    // Drop blocks whose deposits all rounded to zero, keeping the sorted order.
    std::vector<Vec3i> origins;
    size_t n = 0;
    for (size_t b = 0; b < keys.size(); ++b) {
        if (!keep[b]) continue;
        origins.push_back(blockCoordOfKey(keys[b]) * DensityGrid::kBlockSize);
        if (n != b) {
            density[n] = density[b];
            if (velocity) momentum[n] = momentum[b];
        }
        ++n;
    }
    density.resize(n);
    if (velocity) momentum.resize(n);
    return DensityGrid(transform, std::move(origins), std::move(density), std::move(momentum));
}

}  // namespace hp
