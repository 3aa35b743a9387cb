#include "sim/strands/roots.h"

#include "core/errors.h"
#include "core/hash.h"
#include "sim/strands/fibonacci.h"
#include "sim/collision/mesh_query.h"

#include <tbb/parallel_for.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace hp {

namespace {

double triangleArea(const TriangleMesh& m, const Tri& t) {
    return 0.5 * double((m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]).norm());
}

bool selected(const std::vector<uint8_t>& mask, size_t t) { return mask.empty() || mask[t] != 0; }

Vec3f pointOf(const TriangleMesh& m, const SurfacePoint& s) {
    const Tri& t = m.triangles[s.triangle];
    return (1.f - s.b1 - s.b2) * m.positions[t[0]] + s.b1 * m.positions[t[1]] + s.b2 * m.positions[t[2]];
}

/// splitmix64 (its golden-ratio increment, then its finaliser in core/hash.h):
/// a counter-based generator, so candidate i's numbers do not depend on which
/// thread draws them.
uint64_t mix(uint64_t x) { return hash::splitMix64(x + 0x9e3779b97f4a7c15ull); }

double uniform(uint64_t seed, uint64_t index, uint64_t stream) {
    return double(mix(mix(seed ^ (stream * 0xd1b54a32d192ed03ull)) + index) >> 11) * 0x1.0p-53;
}

/// The scalp's centre for the Fibonacci lattice: a sphere fit, or, for a
/// nearly flat scalp, a point behind it along its mean normal.
Vec3f latticeCenter(const TriangleMesh& mesh, const std::vector<uint8_t>& scalp) {
    std::vector<Vec3f> centroids;
    Vec3f meanNormal = Vec3f::Zero();
    Eigen::AlignedBox3f box;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        if (!selected(scalp, t)) continue;
        const Tri& tri = mesh.triangles[t];
        const Vec3f& a = mesh.positions[tri[0]];
        const Vec3f& b = mesh.positions[tri[1]];
        const Vec3f& c = mesh.positions[tri[2]];
        centroids.push_back((a + b + c) / 3.f);
        meanNormal += (b - a).cross(c - a);
        box.extend(a).extend(b).extend(c);
    }
    const float size = box.diagonal().norm();
    Vec3f center;
    float radius = 0.f;
    if (fitSphere(centroids, center, radius) && radius < 2.f * size) return center;
    const Vec3f n = meanNormal.norm() > 0.f ? Vec3f(meanNormal.normalized()) : Vec3f::UnitY();
    return box.center() - n * size;
}

std::vector<SurfacePoint> fibonacciRoots(const TriangleMesh& mesh, const std::vector<uint8_t>& scalp,
                                         const RootSettings& settings) {
    const Vec3f c = settings.center ? *settings.center : latticeCenter(mesh, scalp);
    float reach = 0.f;
    for (const Vec3f& p : mesh.positions) reach = std::max(reach, (p - c).norm());
    // The cone of directions (from c) that holds the scalp: the lattice is
    // only generated there, so no ray is wasted on the face or the neck.
    std::vector<Vec3f> dirs;
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
        if (selected(scalp, t))
            for (uint32_t v : mesh.triangles[t]) {
                const Vec3f d = mesh.positions[v] - c;
                if (d.norm() > 0.f) dirs.push_back(d.normalized());
            }
    Vec3f axis = Vec3f::Zero();
    for (const Vec3f& d : dirs) axis += d;
    if (settings.axis && settings.axis->norm() > 0.f) axis = settings.axis->normalized();
    else if (axis.norm() > 1e-3f * float(dirs.size())) axis.normalize();
    else axis = Vec3f::UnitY();  // the scalp surrounds the centre: use the whole sphere
    float minCos = 1.f;
    for (const Vec3f& d : dirs) minCos = std::min(minCos, d.dot(axis));
    minCos = std::max(-1.f, minCos - 0.02f);  // margin: triangle interiors bulge past their corners
    const Eigen::Quaternionf toAxis = Eigen::Quaternionf::FromTwoVectors(Vec3f::UnitY(), axis);

    const MeshQuery all(mesh);
    const float start = 1.01f * reach + 1e-3f;
    std::vector<Vec3f> lattice;
    std::vector<RayHit> hits;
    // Casts the cap of an n-point sphere lattice; returns how many
    // directions' outermost surface point lies on the scalp.
    auto cast = [&](size_t n) {
        lattice.clear();
        // Heights decrease with the index: the cap is a prefix of the lattice.
        for (size_t i = 0; i < n; ++i) {
            const Vec3f p = fibonacciPoint(i, n);
            if (p.y() < minCos) break;
            lattice.push_back(toAxis * p);
        }
        hits.assign(lattice.size(), RayHit{});
        tbb::parallel_for(tbb::blocked_range<size_t>(0, lattice.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i != r.end(); ++i) {
                const RayHit h = all.intersect(c + start * lattice[i], -lattice[i]);
                if (h.hit() && selected(scalp, h.point.triangle)) hits[i] = h;
            }
        });
        return size_t(std::count_if(hits.begin(), hits.end(), [](const RayHit& h) { return h.hit(); }));
    };

    // The smallest lattice that puts `want` roots on the scalp (Gomes 2024's
    // lattice itself when the scalp is its cap). Hits grow nearly in
    // proportion to the lattice size, so proportional guesses, kept inside
    // the bracket [lo, hi] found so far, converge in a few casts. Large
    // counts stop within 0.1 % of the target and drop the extra roots evenly.
    const size_t want = settings.count;
    const size_t slack = want > 10000 ? want / 1000 : 0;
    size_t n = size_t(std::ceil(double(want) * 2.0 / (1.0 - double(minCos)))), lo = 0, hi = 0, foundHi = 0;
    size_t found = cast(n);
    for (int i = 0;; ++i) {
        if (found >= want && (hi == 0 || n < hi)) hi = n, foundHi = found;
        if (found < want) lo = std::max(lo, n);
        if (hi && (foundHi - want <= slack || hi - lo <= 1)) break;
        if (found == 0 || i > 40)
            throw Error(cat("root placement: the Fibonacci lattice reaches only ", found, " of ", want,
                            " roots on the scalp (is the scalp hidden under other geometry?)"));
        size_t next = size_t(std::llround(double(n) * double(want) / double(found)));
        if (found < want) next = std::max(next, n + 1 + n / 2000);
        if (hi) next = std::min(next, hi - 1);
        if (next <= lo) next = hi ? lo + (hi - lo) / 2 : lo + 1;
        n = next;
        found = cast(n);
    }
    if (n != hi) cast(hi);
    std::vector<size_t> onScalpHits;
    for (size_t i = 0; i < hits.size(); ++i)
        if (hits[i].hit()) onScalpHits.push_back(i);
    const MeshQuery onScalp(mesh, scalp);
    std::vector<SurfacePoint> roots(onScalpHits.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, roots.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t k = r.begin(); k != r.end(); ++k) {
            // Re-derive the point by a closest-point query: its index
            // tie-break makes a hit on a shared edge pick the same triangle
            // whatever the BVH's traversal order.
            roots[k] = onScalp.closest(pointOf(mesh, hits[onScalpHits[k]].point)).point;
        }
    });
    // Drop the few extra roots evenly spread over the lattice order.
    const size_t extra = roots.size() - want;
    if (extra > 0) {
        std::vector<SurfacePoint> kept;
        kept.reserve(want);
        for (size_t i = 0, dropped = 0; i < roots.size(); ++i) {
            const size_t due = (i + 1) * extra / roots.size();
            if (due > dropped) ++dropped;
            else kept.push_back(roots[i]);
        }
        roots.swap(kept);
    }
    return roots;
}

/// A cell coordinate packed into 63 bits (21 per axis, two's complement).
uint64_t cellKey(const Eigen::Vector3i& c) {
    return (uint64_t(uint32_t(c.x()) & 0x1FFFFF) << 42) | (uint64_t(uint32_t(c.y()) & 0x1FFFFF) << 21) |
           uint64_t(uint32_t(c.z()) & 0x1FFFFF);
}

/// Cell key -> [begin, end) range of a key-sorted array: open addressing
/// with linear probing (a node-based map's pointer chasing was the cost).
class CellTable {
  public:
    explicit CellTable(const std::vector<std::pair<uint64_t, uint32_t>>& sorted) {
        size_t cells = 0;
        for (size_t i = 0; i < sorted.size(); ++i) cells += i == 0 || sorted[i].first != sorted[i - 1].first;
        size_t capacity = 16;
        while (capacity < 2 * cells) capacity *= 2;
        mask_ = capacity - 1;
        slots_.assign(capacity, Slot{kEmpty, 0, 0});
        for (uint32_t i = 0; i < sorted.size();) {
            uint32_t j = i;
            while (j < sorted.size() && sorted[j].first == sorted[i].first) ++j;
            size_t h = hash(sorted[i].first);
            while (slots_[h].key != kEmpty) h = (h + 1) & mask_;
            slots_[h] = {sorted[i].first, i, j};
            i = j;
        }
    }
    static constexpr uint32_t kNone = ~0u;
    /// The cell's range, or {kNone, kNone} when no candidate lies in it.
    std::pair<uint32_t, uint32_t> find(uint64_t key) const {
        for (size_t h = hash(key);; h = (h + 1) & mask_) {
            if (slots_[h].key == key) return {slots_[h].begin, slots_[h].end};
            if (slots_[h].key == kEmpty) return {kNone, kNone};
        }
    }

  private:
    static constexpr uint64_t kEmpty = ~0ull;  // keys use 63 bits
    struct Slot {
        uint64_t key;
        uint32_t begin, end;
    };
    size_t hash(uint64_t key) const { return size_t(mix(key)) & mask_; }
    std::vector<Slot> slots_;
    size_t mask_ = 0;
};

/// A max-heap of candidate weights that supports lowering a weight (sample
/// elimination removes the heaviest and lightens its neighbours). Ties go to
/// the higher index, so the order is fully determined.
class WeightHeap {
  public:
    explicit WeightHeap(const std::vector<double>& w) : w_(w), heap_(w.size()), pos_(w.size()) {
        for (uint32_t i = 0; i < heap_.size(); ++i) heap_[i] = pos_[i] = i;
        for (size_t i = heap_.size() / 2; i-- > 0;) down(i);
    }
    uint32_t pop() {
        const uint32_t top = heap_[0];
        swapAt(0, heap_.size() - 1);
        heap_.pop_back();
        pos_[top] = kGone;
        if (!heap_.empty()) down(0);
        return top;
    }
    bool contains(uint32_t i) const { return pos_[i] != kGone; }
    void lower(uint32_t i, double w) {
        w_[i] = w;
        down(pos_[i]);
    }
    size_t size() const { return heap_.size(); }

  private:
    static constexpr uint32_t kGone = 0xFFFFFFFFu;
    bool above(uint32_t a, uint32_t b) const { return w_[a] > w_[b] || (w_[a] == w_[b] && a > b); }
    void swapAt(size_t a, size_t b) {
        std::swap(heap_[a], heap_[b]);
        pos_[heap_[a]] = uint32_t(a);
        pos_[heap_[b]] = uint32_t(b);
    }
    void down(size_t i) {
        for (;;) {
            size_t best = i;
            for (size_t c = 2 * i + 1; c <= 2 * i + 2 && c < heap_.size(); ++c)
                if (above(heap_[c], heap_[best])) best = c;
            if (best == i) return;
            swapAt(i, best);
            i = best;
        }
    }
    std::vector<double> w_;
    std::vector<uint32_t> heap_, pos_;
};

std::vector<SurfacePoint> blueNoiseRoots(const TriangleMesh& mesh, const std::vector<uint8_t>& scalp,
                                         const RootSettings& settings) {
    const size_t want = settings.count;
    std::vector<uint32_t> tris;
    std::vector<double> cdf;
    double total = 0.0;
    for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
        if (!selected(scalp, t)) continue;
        const double a = triangleArea(mesh, mesh.triangles[t]);
        if (a <= 0.0) continue;
        total += a;
        tris.push_back(t);
        cdf.push_back(total);
    }
    if (tris.empty()) throw Error("root placement: the scalp has no area");

    // Area-uniform candidates: a triangle by area, then a uniform point in it.
    const size_t m = std::max(want, size_t(std::ceil(double(want) * std::max(1.f, settings.candidateRatio))));
    std::vector<SurfacePoint> cand(m);
    std::vector<Vec3f> pos(m);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, m, 1024), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const double u0 = uniform(settings.seed, i, 0) * total;
            const size_t k = std::min(size_t(std::upper_bound(cdf.begin(), cdf.end(), u0) - cdf.begin()), tris.size() - 1);
            const double s = std::sqrt(uniform(settings.seed, i, 1)), u2 = uniform(settings.seed, i, 2);
            cand[i] = {tris[k], float(s * (1.0 - u2)), float(s * u2)};
            pos[i] = pointOf(mesh, cand[i]);
        }
    });
    if (m == want) return cand;

    // Yuksel's parameters for 2-D sampling domains: r_max is the disk radius
    // of the densest (hexagonal) packing, so neighbours within 2 r_max
    // interact; distances below r_min weigh alike (weight limiting, β = 0.65,
    // γ = 1.5); exponent α = 8.
    const double rMax = std::sqrt(total / (2.0 * std::sqrt(3.0) * double(want)));
    const double reach = 2.0 * rMax;
    const double rMin = reach * 0.65 * (1.0 - std::pow(double(want) / double(m), 1.5));
    auto weight = [&](double d) {
        const double t = 1.0 - std::max(d, rMin) / reach, t2 = t * t, t4 = t2 * t2;
        return t4 * t4;  // (1 - d̂ / 2r_max)^8
    };

    // A hash grid of cell size 2 r_max: neighbours lie in the 27 cells
    // around. Candidates are renumbered in cell order so that a cell's
    // points are contiguous in memory (the scans are memory-bound).
    auto cellOf = [&](const Vec3f& p) {
        return Eigen::Vector3i(int(std::floor(p.x() / reach)), int(std::floor(p.y() / reach)),
                               int(std::floor(p.z() / reach)));
    };
    std::vector<std::pair<uint64_t, uint32_t>> order(m);
    for (uint32_t i = 0; i < m; ++i) order[i] = {cellKey(cellOf(pos[i])), i};
    std::sort(order.begin(), order.end());
    std::vector<Vec3f> spos(m);
    for (uint32_t s = 0; s < m; ++s) spos[s] = pos[order[s].second];
    // Cells in key order: cellStart[c] is the first candidate of cell c.
    std::vector<uint32_t> cellStart, cellOfCandidate(m);
    for (uint32_t t = 0; t < m; ++t) {
        if (t == 0 || order[t].first != order[t - 1].first) cellStart.push_back(t);
        cellOfCandidate[t] = uint32_t(cellStart.size() - 1);
    }
    const size_t cellCount = cellStart.size();
    cellStart.push_back(uint32_t(m));
    // Each cell's non-empty neighbour cells (itself included), found once per
    // cell rather than once per candidate.
    std::vector<uint32_t> neighbourStart(cellCount + 1, 0), neighbours;
    {
        const CellTable table(order);
        std::vector<std::vector<uint32_t>> lists(cellCount);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, cellCount, 256), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t c = r.begin(); c != r.end(); ++c) {
                const Eigen::Vector3i cc = cellOf(spos[cellStart[c]]);
                for (int dx = -1; dx <= 1; ++dx)
                    for (int dy = -1; dy <= 1; ++dy)
                        for (int dz = -1; dz <= 1; ++dz) {
                            const uint32_t begin = table.find(cellKey(cc + Eigen::Vector3i(dx, dy, dz))).first;
                            if (begin != CellTable::kNone) lists[c].push_back(cellOfCandidate[begin]);
                        }
            }
        });
        for (size_t c = 0; c < cellCount; ++c) {
            neighbours.insert(neighbours.end(), lists[c].begin(), lists[c].end());
            neighbourStart[c + 1] = uint32_t(neighbours.size());
        }
    }
    auto forNeighbours = [&](uint32_t s, auto&& visit) {
        const uint32_t c = cellOfCandidate[s];
        for (uint32_t k = neighbourStart[c]; k < neighbourStart[c + 1]; ++k) {
            const uint32_t nc = neighbours[k];
            for (uint32_t t = cellStart[nc]; t < cellStart[nc + 1]; ++t) {
                if (t == s) continue;
                const double d = double((spos[s] - spos[t]).norm());
                if (d < reach) visit(t, d);
            }
        }
    };

    std::vector<double> w(m, 0.0);
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, uint32_t(m), 1024), [&](const tbb::blocked_range<uint32_t>& r) {
        for (uint32_t s = r.begin(); s != r.end(); ++s) forNeighbours(s, [&](uint32_t, double d) { w[s] += weight(d); });
    });
    // Remove the most crowded candidate until `want` remain, taking its
    // contribution off its neighbours' weights.
    WeightHeap heap(w);
    while (heap.size() > want) {
        const uint32_t s = heap.pop();
        forNeighbours(s, [&](uint32_t t, double d) {
            if (heap.contains(t)) {
                w[t] -= weight(d);
                heap.lower(t, w[t]);
            }
        });
    }
    std::vector<uint32_t> kept;
    kept.reserve(want);
    for (uint32_t s = 0; s < m; ++s)
        if (heap.contains(s)) kept.push_back(order[s].second);
    std::sort(kept.begin(), kept.end());
    std::vector<SurfacePoint> roots;
    roots.reserve(want);
    for (uint32_t i : kept) roots.push_back(cand[i]);
    return roots;
}

}  // namespace

double surfaceArea(const TriangleMesh& mesh, const std::vector<uint8_t>& mask) {
    double a = 0.0;
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
        if (selected(mask, t)) a += triangleArea(mesh, mesh.triangles[t]);
    return a;
}

bool fitSphere(const std::vector<Vec3f>& points, Vec3f& center, float& radius) {
    if (points.size() < 4) return false;
    // Centre the data first: the normal equations stay well conditioned.
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Vec3f& p : points) mean += p.cast<double>();
    mean /= double(points.size());
    Eigen::Matrix4d ata = Eigen::Matrix4d::Zero();
    Eigen::Vector4d atb = Eigen::Vector4d::Zero();
    for (const Vec3f& pf : points) {
        const Eigen::Vector3d p = pf.cast<double>() - mean;
        const Eigen::Vector4d row(2 * p.x(), 2 * p.y(), 2 * p.z(), 1.0);
        ata += row * row.transpose();
        atb += row * p.squaredNorm();
    }
    const Eigen::LDLT<Eigen::Matrix4d> ldlt(ata);
    if (ldlt.info() != Eigen::Success || ldlt.rcond() < 1e-12) return false;
    const Eigen::Vector4d x = ldlt.solve(atb);
    const double r2 = x[3] + x.head<3>().squaredNorm();
    if (!(r2 > 0.0) || !std::isfinite(r2)) return false;
    center = (x.head<3>() + mean).cast<float>();
    radius = float(std::sqrt(r2));
    return true;
}

std::vector<SurfacePoint> placeRoots(const TriangleMesh& mesh, const std::vector<uint8_t>& scalp,
                                     const RootSettings& settings) {
    if (!scalp.empty() && scalp.size() != mesh.triangles.size())
        throw Error(cat("root placement: scalp mask has ", scalp.size(), " entries for ", mesh.triangles.size(),
                        " triangles"));
    if (settings.count == 0) return {};
    if (!scalp.empty() && std::none_of(scalp.begin(), scalp.end(), [](uint8_t s) { return s != 0; }))
        throw Error("root placement: the scalp mask selects no triangle");
    return settings.method == RootMethod::Fibonacci ? fibonacciRoots(mesh, scalp, settings)
                                                    : blueNoiseRoots(mesh, scalp, settings);
}

}  // namespace hp
