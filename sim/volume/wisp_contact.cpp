// Wisps against wisps (equations and determinism: sim/volume/wisp_contact.h).
#include "sim/volume/wisp_contact.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>

namespace hp::volume {
namespace {

/// Jacobi relaxation ω: a vertex between two neighbours gets both pairs'
/// full moves in one sweep, so a sweep takes half of each (ω = 1
/// overshoots a vertex squeezed from two sides, ω = 1/2 cannot).
constexpr float kOmega = 0.5f;

/// Vertices below which the sweeps run on the calling thread.
constexpr size_t kParallelVertices = 8192;

/// Neighbours a vertex keeps from the first scan (more: scanned again).
constexpr uint32_t kInline = 16;

/// Neighbour lists reach this fraction of d further, so that the sweeps
/// can move vertices that far before the lists are found again.
constexpr float kMargin = 0.1f;

/// Hash of a cell (Teschner, Heidelberger, Müller, Pomeranets and Gross,
/// "Optimized Spatial Hashing for Collision Detection of Deformable
/// Objects", 2003): three large primes, xor, masked to the table size.
inline uint32_t cellKey(const Eigen::Vector3i& c, uint32_t mask) {
    return (uint32_t(c.x()) * 73856093u ^ uint32_t(c.y()) * 19349663u ^ uint32_t(c.z()) * 83492791u) & mask;
}

/// The move of vertex i (inverse mass wi) against vertex j of another wisp,
/// added to dx: apart along the pair's normal to the bound min(d, start
/// distance), the side being where the pair started if it crossed since,
/// and its slide taken back by friction. False when the pair is not closer
/// than its bound (no move).
bool pairMove(const ContactInput& in, size_t i, size_t j, float d, float wi, Eigen::Vector3f& dx) {
    const Eigen::Vector3f cur = in.x[i] - in.x[j];
    const float dist2 = cur.squaredNorm();
    if (dist2 >= d * d) return false;
    const Eigen::Vector3f start = in.x0[i] - in.x0[j];
    const float d0 = start.norm();
    // Crossed since the start: back to the side it came from.
    Eigen::Vector3f nrm;
    float dist;
    if (cur.dot(start) < 0.f && d0 > 0.f) {
        nrm = start / d0;
        dist = cur.dot(nrm);
    } else if (dist2 > 0.f) {
        dist = std::sqrt(dist2);
        nrm = cur / dist;
    } else {
        return false;  // coincident now and at the start: no direction
    }
    const float bound = std::min(d, d0);
    if (dist >= bound) return false;
    const float wj = in.mass[j] > 0.f ? 1.f / in.mass[j] : 0.f;
    const float depth = bound - dist;
    // Friction at position level (Macklin, Müller, Chentanez and Kim,
    // "Unified Particle Physics for Real-Time Applications", 2014): the
    // pair's relative slide over the substep, taken back whole below μ·depth
    // (static), by μ·depth above it (kinetic; slideLen > grip ≥ 0 there).
    Eigen::Vector3f slide = (in.x[i] - in.x0[i]) - (in.x[j] - in.x0[j]);
    slide -= slide.dot(nrm) * nrm;
    const float slideLen = slide.norm(), grip = in.friction * depth;
    const Eigen::Vector3f back = slideLen <= grip ? slide : Eigen::Vector3f((grip / slideLen) * slide);
    dx += (kOmega * wi / (wi + wj)) * (depth * nrm - back);
    return true;
}

}  // namespace

float wispRadius(float hairsPerGuide, float targetDensityPerCm2) {
    return std::sqrt(hairsPerGuide / (float(M_PI) * targetDensityPerCm2 * 1e4f));
}

size_t WispContact::apply(const ContactInput& in, const ParallelFor& parallel) {
    const size_t n = in.count;
    const float d = in.distance;
    if (n == 0 || !(d > 0.f)) return 0;
    const bool serial = n < kParallelVertices;
    auto run = [&](size_t count, const std::function<void(size_t, size_t)>& f) {
        if (serial) f(0, count);
        else parallel(count, f);
    };

    const float radius = d * (1.f + kMargin);
    uint32_t table = 1;
    while (table < 2 * n) table <<= 1;
    const uint32_t mask = table - 1;
    const size_t perGuide = std::max<size_t>(1, in.verticesPerGuide);
    auto findNeighbours = [&] {
        // Neighbour lists of radius R = d·(1 + kMargin) on the current
        // positions, in cells of side R: every pair closer than R lies in
        // neighbouring cells. Found once a substep (as Macklin and Müller 2013
        // do once a step), and again only when the sweeps have moved two
        // vertices together by more than the margin, so no pair closer than d
        // is missed.
        cell_.resize(n);
        key_.resize(n);
        const float invD = 1.f / radius;
        run(n, [&](size_t b, size_t e) {
            for (size_t i = b; i < e; ++i) {
                const Eigen::Vector3f f = (in.x[i] * invD).array().floor();
                // Non-finite or absurdly far vertices get no neighbours (key past the table).
                const bool ok = f.allFinite() && f.cwiseAbs().maxCoeff() < 1e8f;
                cell_[i] = ok ? Eigen::Vector3i(f.cast<int>()) : Eigen::Vector3i::Zero();
                key_[i] = ok ? cellKey(cell_[i], mask) : table;
            }
        });
        // Stable counting sort of the vertices by key (vertex order within a bucket).
        bucketStart_.assign(size_t(table) + 2, 0u);
        for (size_t i = 0; i < n; ++i) ++bucketStart_[size_t(key_[i]) + 1];
        for (size_t k = 0; k <= table; ++k) bucketStart_[k + 1] += bucketStart_[k];
        order_.resize(n);
        fill_.assign(bucketStart_.begin(), bucketStart_.end() - 1);
        for (size_t i = 0; i < n; ++i) order_[fill_[key_[i]]++] = uint32_t(i);

        // The vertices' positions and guides in bucket order, so that a
        // bucket's scan reads contiguous memory (the scan was three quarters of
        // the contact's time with random reads through order_).
        sorted_.resize(n);
        run(n, [&](size_t b, size_t e) {
            for (size_t o = b; o < e; ++o) {
                const uint32_t i = order_[o];
                sorted_[o] = {in.x[i], uint32_t(i / perGuide)};
            }
        });
        // Neighbour lists, found once a substep (Macklin and Müller 2013 find
        // them once a step too): the vertices of other guides closer
        // than R, in the fixed scan order of the 27 cells around.
        // A vertex within d lies in one of them, so the distance test alone
        // also rejects a hash collision's vertices; a key two cells share is
        // scanned once. Two passes (count, then fill) so the lists are one array.
        auto scan = [&](size_t i, auto&& visit) {
            const uint32_t gi = uint32_t(i / perGuide);
            const Eigen::Vector3f xi = in.x[i];
            const float d2 = radius * radius;
            uint32_t keys[27];
            int nk = 0;
            for (int oz = -1; oz <= 1; ++oz)
                for (int oy = -1; oy <= 1; ++oy)
                    for (int ox = -1; ox <= 1; ++ox) {
                        const uint32_t k = cellKey(cell_[i] + Eigen::Vector3i(ox, oy, oz), mask);
                        if (std::find(keys, keys + nk, k) != keys + nk) continue;
                        keys[nk++] = k;
                        for (uint32_t o = bucketStart_[k]; o < bucketStart_[k + 1]; ++o)
                            if (sorted_[o].guide != gi && (sorted_[o].x - xi).squaredNorm() < d2) visit(order_[o]);
                    }
        };
        auto active = [&](size_t i) { return in.mass[i] > 0.f && key_[i] != table; };
        // One scan: up to kInline neighbours a vertex kept in place, the rare
        // vertex with more scanned again when the lists are packed.
        nbrStart_.assign(n + 1, 0u);
        inline_.resize(n * kInline);
        run(n, [&](size_t b, size_t e) {
            for (size_t o = b; o < e; ++o) {
                const size_t i = order_[o];
                uint32_t count = 0;
                uint32_t* slot = &inline_[i * kInline];
                if (active(i))
                    scan(i, [&](uint32_t j) {
                        if (count < kInline) slot[count] = j;
                        ++count;
                    });
                nbrStart_[i + 1] = count;
            }
        });
        for (size_t i = 0; i < n; ++i) nbrStart_[i + 1] += nbrStart_[i];
        nbr_.resize(nbrStart_[n]);
        run(n, [&](size_t b, size_t e) {
            for (size_t i = b; i < e; ++i) {
                const uint32_t count = nbrStart_[i + 1] - nbrStart_[i];
                if (count <= kInline) {
                    std::copy_n(&inline_[i * kInline], count, &nbr_[nbrStart_[i]]);
                } else {
                    uint32_t at = nbrStart_[i];
                    scan(i, [&](uint32_t j) { nbr_[at++] = j; });
                }
            }
        });
    };
    findNeighbours();
    if (nbr_.empty()) return 0;

    move_.resize(n);
    size_t firstSweep = 0;
    float drift = 0.f;  // how far two vertices may have come together since the lists were found
    for (int sweep = 0; sweep < std::max(1, in.iterations); ++sweep) {
        if (drift > d * kMargin) {
            findNeighbours();
            drift = 0.f;
        }
        std::atomic<size_t> touching{0};
        run(n, [&](size_t b, size_t e) {
            size_t count = 0;
            for (size_t i = b; i < e; ++i) {
                Eigen::Vector3f dx = Eigen::Vector3f::Zero();
                if (nbrStart_[i] != nbrStart_[i + 1]) {
                    const float wi = 1.f / in.mass[i];
                    for (uint32_t o = nbrStart_[i]; o < nbrStart_[i + 1]; ++o)
                        if (pairMove(in, i, nbr_[o], d, wi, dx)) ++count;
                }
                move_[i] = dx;
            }
            touching += count;
        });
        if (sweep == 0) firstSweep = touching.load();
        if (touching.load() == 0) break;  // nothing closer than its bound: the next sweeps would not move either
        std::atomic<uint32_t> longest{0};  // the sweep's longest move, as float bits (non-negative: ordered as integers)
        run(n, [&](size_t b, size_t e) {
            float most = 0.f;
            for (size_t i = b; i < e; ++i) {
                in.x[i] += move_[i];
                most = std::max(most, move_[i].squaredNorm());
            }
            uint32_t bits, seen = longest.load();
            std::memcpy(&bits, &most, sizeof bits);
            while (bits > seen && !longest.compare_exchange_weak(seen, bits)) {}
        });
        float most;
        const uint32_t bits = longest.load();
        std::memcpy(&most, &bits, sizeof most);
        drift += 2.f * std::sqrt(most);
    }
    return firstSweep;
}

}  // namespace hp::volume
