// The tile deposits of the voxelizer (render/volume/voxel_tiles.h): the cell
// walk and the Gauss-Legendre integrals of the box and trilinear filters.
#include "render/volume/voxel_tiles.h"

#include "render/volume/cell_walk.h"

#include <emmintrin.h>  // SSE2, the x86-64 baseline
#include <xmmintrin.h>  // _mm_prefetch

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

namespace hp::voxel_tiles {

namespace {

/// Three-point Gauss-Legendre on [-1, 1]: exact for polynomials of degree 5,
/// i.e. r(t)² (degree 2) times the trilinear weights (degree 3) along a line.
constexpr double kGaussX[3] = {-0.7745966692414834, 0.0, 0.7745966692414834};
constexpr double kGaussW[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};

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

/// The walk's state where a segment enters the dual cells that reach a tile
/// (see depositTrilinear).
struct WalkStart {
    int cell[3], step[3];
    double tMax[3], inv[3];
    double tIn, tOut;
};

/// Starts the dual-cell walk of segment s at the part whose cells reach the
/// tile at `origin`, cells [origin − 1, origin + kTile) per axis: t ∈ [tIn,
/// tOut], its ends plane crossings computed as the walk computes them.
/// False if the segment misses those cells.
bool startWalk(const Segment& s, const Vec3i& origin, WalkStart* w) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    double tIn = 0, tOut = 1;
    for (int e = 0; e < 3; ++e) {
        const double a = s.a[e], d = s.b[e] - a;
        w->inv[e] = d != 0 ? 1.0 / d : 0.0;
        w->step[e] = d > 0 ? 1 : (d < 0 ? -1 : 0);
        const int lo = origin[e] - 1, hi = origin[e] + kTile;  // the box's planes
        if (w->step[e] == 0) {
            if (!(a >= lo && a < hi)) return false;
            continue;
        }
        const double tLo = (lo - a) * w->inv[e], tHi = (hi - a) * w->inv[e];
        tIn = std::max(tIn, w->step[e] > 0 ? tLo : tHi);
        tOut = std::min(tOut, w->step[e] > 0 ? tHi : tLo);
    }
    if (!(tIn < tOut)) return false;
    // The walk's state at tIn: along each axis, every plane whose crossing
    // time is ≤ tIn has been crossed (crossing times grow with the plane
    // index, also in floating point, so this is the state the walk from
    // t = 0 reaches; the pieces from tIn on are the same, bit for bit).
    for (int e = 0; e < 3; ++e) {
        const double a = s.a[e];
        const int start = int(std::floor(a)), step = w->step[e];
        if (step == 0) {
            w->cell[e] = start;
            w->tMax[e] = kInf;
            continue;
        }
        // Plane crossed when leaving cell c forwards: c + 1 (step > 0) or c (step < 0).
        auto exitTime = [&](int c) { return (c + (step > 0 ? 1 : 0) - a) * w->inv[e]; };
        int c = tIn > 0 ? int(std::floor(a + (s.b[e] - a) * tIn)) : start;
        if (step > 0 ? c < start : c > start) c = start;
        while (exitTime(c) <= tIn) c += step;
        while (c != start && exitTime(c - step) > tIn) c -= step;
        w->cell[e] = c;
        w->tMax[e] = exitTime(c);
    }
    w->tIn = tIn;
    w->tOut = tOut;
    return true;
}

/// Calls piece(lx, ly, lz, t0, t1, cxy, cz) for each piece [t0, t1] of the
/// segment in a dual cell that reaches the tile, (lx, ly, lz) the cell's
/// corner (0,0,0) in tile coordinates (−1 .. kTile−1) and (cxy, cz) in
/// index space as doubles. The cell walk of cell_walk.h (same planes, same
/// intervals, same choice of axis at ties), written out so the deposit is
/// inlined into it.
///
/// The crossing times stay in registers: each step computes every axis's
/// next crossing (next plane − a) · inv and keeps the chosen axis's by mask,
/// so the step's dependency chain is compare → blend (the array indexed by
/// the axis, stored and reloaded, made it ~3× longer). The values are the
/// ones the plane formula gives, bit for bit.
template <typename Piece>
void walkTile(const Segment& s, const Vec3i& origin, Piece&& piece) {
    WalkStart w;
    if (!startWalk(s, origin, &w)) return;
    const int ox = origin.x(), oy = origin.y(), oz = origin.z();
    // (x, y) in one SSE2 pair, z in the low lane of another.
    const __m128d axy = _mm_set_pd(s.a.y(), s.a.x()), az = _mm_set_sd(s.a.z());
    const __m128d ixy = _mm_set_pd(w.inv[1], w.inv[0]), iz = _mm_set_sd(w.inv[2]);
    const __m128d sxy = _mm_set_pd(w.step[1], w.step[0]), sz = _mm_set_sd(w.step[2]);
    // The plane crossed when leaving the current cell: cell + 1 forwards, cell backwards.
    auto forward = [&](int e) { return w.step[e] > 0 ? 1.0 : 0.0; };
    const __m128d fxy = _mm_set_pd(forward(1), forward(0)), fz = _mm_set_sd(forward(2));
    __m128d pxy = _mm_add_pd(_mm_set_pd(w.cell[1], w.cell[0]), fxy), pz = _mm_add_sd(_mm_set_sd(w.cell[2]), fz);
    __m128d txy = _mm_set_pd(w.tMax[1], w.tMax[0]), tz = _mm_set_sd(w.tMax[2]);
    const __m128d ones = _mm_castsi128_pd(_mm_set1_epi32(-1));
    int cell[3] = {w.cell[0], w.cell[1], w.cell[2]};
    double t = w.tIn;
    for (;;) {
        // e = 1 if t_y < t_x, else 0; then 2 if t_z < t_e.
        const __m128d ty = _mm_unpackhi_pd(txy, txy);
        const __m128d yFirst = _mm_cmplt_sd(ty, txy);                      // low lane: t_y < t_x
        const __m128d te = _mm_or_pd(_mm_and_pd(yFirst, ty), _mm_andnot_pd(yFirst, txy));
        const __m128d zFirst = _mm_cmplt_sd(tz, te);                       // low lane: t_z < t_e
        const double tNext = _mm_cvtsd_f64(_mm_or_pd(_mm_and_pd(zFirst, tz), _mm_andnot_pd(zFirst, te)));
        const int e = _mm_movemask_pd(zFirst) & 1 ? 2 : (_mm_movemask_pd(yFirst) & 1);
        const double t1 = std::min(tNext, 1.0);
        // The tile owns voxels 0..kTile-1, so cells -1..kTile-1 reach it.
        const int lx = cell[0] - ox, ly = cell[1] - oy, lz = cell[2] - oz;
        if (t1 > t && unsigned(lx + 1) <= unsigned(kTile) && unsigned(ly + 1) <= unsigned(kTile) &&
            unsigned(lz + 1) <= unsigned(kTile))
            piece(lx, ly, lz, t, t1, _mm_sub_pd(pxy, fxy), _mm_cvtsd_f64(_mm_sub_sd(pz, fz)));
        if (tNext >= w.tOut) return;  // tOut ≤ 1: the segment's end or the box's
        t = std::max(t, t1);
        cell[e] += w.step[e];
        // Masks of the axis that advances: x, y in the pair, z in the low lane.
        const __m128d notZ = _mm_andnot_pd(_mm_unpacklo_pd(zFirst, zFirst), ones);
        const __m128d yLanes = _mm_unpacklo_pd(yFirst, yFirst);
        const __m128d mxy = _mm_and_pd(notZ, _mm_unpacklo_pd(_mm_andnot_pd(yLanes, ones), yLanes));
        // Recomputed from the plane rather than accumulated (as in cell_walk.h).
        const __m128d pxyNext = _mm_add_pd(pxy, sxy), pzNext = _mm_add_sd(pz, sz);
        const __m128d txyNext = _mm_mul_pd(_mm_sub_pd(pxyNext, axy), ixy);
        const __m128d tzNext = _mm_mul_sd(_mm_sub_sd(pzNext, az), iz);
        pxy = _mm_or_pd(_mm_and_pd(mxy, pxyNext), _mm_andnot_pd(mxy, pxy));
        txy = _mm_or_pd(_mm_and_pd(mxy, txyNext), _mm_andnot_pd(mxy, txy));
        pz = _mm_or_pd(_mm_and_pd(zFirst, pzNext), _mm_andnot_pd(zFirst, pz));
        tz = _mm_or_pd(_mm_and_pd(zFirst, tzNext), _mm_andnot_pd(zFirst, tz));
    }
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
/// a polynomial of degree 5 (2 from the tapering radius, 3 from the
/// weights), integrated exactly by 3-point Gauss-Legendre (2 points are
/// exact to degree 3 only: enough for an untapered segment, not for hair).
///
/// Density only (C = 1, the hot loop of the VDB export): with w_g = k·h·W_g·r(t_g)²
/// the rule accumulates the 8 moments Σ_g w_g·{1, f_x}·{1, f_y}·{1, f_z}
/// as four SSE2 pairs (24 operations a Gauss point), and the corners follow
/// by inclusion-exclusion, e.g. Σ w·(1 − f_x)·f_y·f_z = M_yz − M_xyz: the same
/// sums as the products of the weights, in another order (so values differ
/// in the last bits; the absolute rounding stays ~1e-16 of the piece's
/// volume). Each corner pair (Z_0, Z_1) is one unaligned add into the padded
/// buffer.
template <int C>
void depositTrilinear(TileBuffer<C>& tile, const Segment& s, const SegmentVelocity* sv) {
    double* const values = tile.values.data();
    const double ax = s.a.x(), ay = s.a.y(), az = s.a.z();
    const double dx = s.b.x() - ax, dy = s.b.y() - ay, dz = s.b.z() - az;
    const double r0 = s.r0, dr = s.r1 - s.r0, k = s.k;
    if constexpr (C == 1) {
        constexpr double kInf = std::numeric_limits<double>::infinity();
        const __m128d zero = _mm_setzero_pd(), one = _mm_set1_pd(1.0);
        const __m128d d1 = _mm_set_pd(dy, dx), d2 = _mm_set_pd(dr, dz);  // _mm_set_pd(high, low)
        // Clamps of (f_z, r): f_z to [0, 1] (rounding at the cell's faces), r untouched.
        const __m128d lo2 = _mm_set_pd(-kInf, 0.0), hi2 = _mm_set_pd(kInf, 1.0);
        const __m128d axy = _mm_set_pd(ay, ax);
        walkTile(s, tile.origin, [&](int lx, int ly, int lz, double t0, double t1, __m128d cxy, double cz) {
            const double mid = 0.5 * (t0 + t1), h = 0.5 * (t1 - t0), kh = k * h;
            const __m128d b1 = _mm_sub_pd(axy, cxy);  // f at t = 0
            const __m128d b2 = _mm_set_pd(r0, az - cz);
            // u: (Σ w, Σ w f_x), v: (Σ w f_y, Σ w f_x f_y); u1, v1 the same times f_z.
            __m128d u = zero, v = zero, u1 = zero, v1 = zero;
            for (int g = 0; g < 3; ++g) {
                const __m128d tg = _mm_set1_pd(mid + h * kGaussX[g]);
                const __m128d f1 = _mm_min_pd(_mm_max_pd(_mm_add_pd(b1, _mm_mul_pd(d1, tg)), zero), one);  // (fx, fy)
                const __m128d f2 = _mm_min_pd(_mm_max_pd(_mm_add_pd(b2, _mm_mul_pd(d2, tg)), lo2), hi2);   // (fz, r)
                const __m128d r = _mm_unpackhi_pd(f2, f2);
                const __m128d w = _mm_mul_pd(_mm_mul_pd(r, r), _mm_set1_pd(kh * kGaussW[g]));
                const __m128d wu = _mm_mul_pd(w, _mm_unpacklo_pd(one, f1));
                const __m128d wv = _mm_mul_pd(wu, _mm_unpackhi_pd(f1, f1));
                const __m128d fz = _mm_unpacklo_pd(f2, f2);
                u = _mm_add_pd(u, wu);
                v = _mm_add_pd(v, wv);
                u1 = _mm_add_pd(u1, _mm_mul_pd(wu, fz));
                v1 = _mm_add_pd(v1, _mm_mul_pd(wv, fz));
            }
            // (P_lo, P_hi) = (Σ w·g, Σ w·f_x·g) → (Σ w·X_0·g, Σ w·X_1·g).
            auto splitX = [&](__m128d p) { return _mm_sub_pd(p, _mm_unpackhi_pd(p, zero)); };
            const __m128d all0 = splitX(_mm_sub_pd(u, v)), all1 = splitX(v);     // Y_0, Y_1; any z
            const __m128d top0 = splitX(_mm_sub_pd(u1, v1)), top1 = splitX(v1);  // Y_0, Y_1; Z_1
            const __m128d bot0 = _mm_sub_pd(all0, top0), bot1 = _mm_sub_pd(all1, top1);  // Z_0
            // Corner pairs (Z_0, Z_1) of (i, j), at x·kPad² + y·kPad from corner (0,0,0).
            double* c = values + TileBuffer<C>::index(lx, ly, lz);
            auto add = [](double* at, __m128d q) { _mm_storeu_pd(at, _mm_add_pd(_mm_loadu_pd(at), q)); };
            add(c, _mm_unpacklo_pd(bot0, top0));
            add(c + kPad, _mm_unpacklo_pd(bot1, top1));
            add(c + kPad * kPad, _mm_unpackhi_pd(bot0, top0));
            add(c + kPad * kPad + kPad, _mm_unpackhi_pd(bot1, top1));
            tile.mark(lx, ly, lz);
        });
    } else {
        walkTile(s, tile.origin, [&](int lx, int ly, int lz, double t0, double t1, __m128d, double) {
            const double mid = 0.5 * (t0 + t1), h = 0.5 * (t1 - t0);
            const double bx = ax - (tile.origin.x() + lx), by = ay - (tile.origin.y() + ly),
                         bz = az - (tile.origin.z() + lz);
            double q[8][C] = {};  // corner (x-major: ix·4 + iy·2 + iz) × channel
            for (int g = 0; g < 3; ++g) {
                const double tg = mid + h * kGaussX[g];
                const double r = r0 + dr * tg;
                const double w = k * h * kGaussW[g] * r * r;
                const double fx = std::min(std::max(bx + dx * tg, 0.0), 1.0);
                const double fy = std::min(std::max(by + dy * tg, 0.0), 1.0);
                const double fz = std::min(std::max(bz + dz * tg, 0.0), 1.0);
                const double wx[2] = {w * (1 - fx), w * fx};
                const double y[2] = {1 - fy, fy}, z[2] = {1 - fz, fz};
                const Vec3d vel = sv->v0.cast<double>() + (sv->v1 - sv->v0).cast<double>() * tg;
                for (int i = 0; i < 8; ++i) {
                    const double cw = (wx[i >> 2] * y[(i >> 1) & 1]) * z[i & 1];
                    q[i][0] += cw;
                    for (int m = 0; m < 3; ++m) q[i][1 + m] += cw * vel[m];
                }
            }
            double* c = values + size_t(TileBuffer<C>::index(lx, ly, lz)) * C;
            for (int i = 0; i < 8; ++i) {
                double* corner = c + size_t(((i >> 2) * kPad + ((i >> 1) & 1)) * kPad + (i & 1)) * C;
                for (int m = 0; m < C; ++m) corner[m] += q[i][m];
            }
            tile.mark(lx, ly, lz);
        });
    }
}


template <int C>
void extractBlocks(TileBuffer<C>& tile, TileBlocks* out) {
    double* const values = tile.values.data();
    for (int bx = 0; bx < kBlocksPerTile; ++bx)
        for (int by = 0; by < kBlocksPerTile; ++by)
            for (int bz = 0; bz < kBlocksPerTile; ++bz) {
                // Voxel block b receives deposits from the dual cells of cell blocks b and b + 1.
                bool touched = false;
                for (int i = 0; i < 8; ++i) touched |= tile.isTouched(bx + (i >> 2), by + ((i >> 1) & 1), bz + (i & 1));
                if (!touched) continue;
                const int x0 = bx * kBlock, y0 = by * kBlock, z0 = bz * kBlock;
                bool any = false;
                for (int x = 0; x < kBlock; ++x)
                    for (int y = 0; y < kBlock; ++y) {
                        const double* row = values + size_t(TileBuffer<C>::index(x0 + x, y0 + y, z0)) * C;
                        for (int z = 0; z < kBlock; ++z) any |= row[z * C] > 0;
                    }
                if (!any) continue;  // only zero deposits (e.g. exactly on a voxel plane): nothing active
                out->origins.push_back(tile.origin + Vec3i(x0, y0, z0));
                out->density.emplace_back(new DensityGrid::DensityBlock);  // every voxel written below
                DensityGrid::DensityBlock& density = *out->density.back();
                DensityGrid::VelocityBlock* velocity = nullptr;
                if constexpr (C == 4) {
                    out->velocity.emplace_back(new DensityGrid::VelocityBlock);
                    velocity = out->velocity.back().get();
                }
                for (int x = 0; x < kBlock; ++x)
                    for (int y = 0; y < kBlock; ++y) {
                        const double* row = values + size_t(TileBuffer<C>::index(x0 + x, y0 + y, z0)) * C;
                        for (int z = 0; z < kBlock; ++z) {
                            const int i = DensityGrid::voxelOffset(x, y, z);
                            density[size_t(i)] = float(row[z * C]);
                            if constexpr (C == 4) {
                                const double* m = row + z * C;
                                const double w = m[0] > 0 ? 1.0 / m[0] : 0.0;
                                (*velocity)[size_t(i)] = Vec3f(float(m[1] * w), float(m[2] * w), float(m[3] * w));
                            }
                        }
                    }
            }
    // Clear what the deposits reached: cell block b's cells b·8 − 1 .. b·8 + 6
    // write voxels b·8 − 1 .. b·8 + 7, padded b·8 .. b·8 + 8.
    for (int b = 0; b < kCellBlocks * kCellBlocks * kCellBlocks; ++b) {
        if (!(tile.touched[b >> 6] >> (b & 63) & 1)) continue;
        const int X = b / (kCellBlocks * kCellBlocks), Y = (b / kCellBlocks) % kCellBlocks, Z = b % kCellBlocks;
        const int zLo = Z * kBlock, zHi = std::min(Z * kBlock + kBlock, kPad - 1);
        for (int x = X * kBlock; x <= std::min(X * kBlock + kBlock, kPad - 1); ++x)
            for (int y = Y * kBlock; y <= std::min(Y * kBlock + kBlock, kPad - 1); ++y) {
                // In SSE2 pairs: a call to memset per row of 9 cost more than
                // the clearing. An odd row's extra double is the next voxel of
                // the same row (zHi < kPad − 1 then), cleared or zero anyway:
                // extraction is done.
                double* row = values + (size_t(x * kPad + y) * kPad + zLo) * C;
                for (int i = 0; i < (zHi - zLo + 1) * C; i += 2) _mm_storeu_pd(row + i, _mm_setzero_pd());
            }
    }
    std::fill(std::begin(tile.touched), std::end(tile.touched), 0);
}


}  // namespace

/// How many segments ahead the tile loop prefetches.
constexpr size_t kPrefetch = 4;

template <int C>
void fillTile(TileBuffer<C>& tile, bool box, const Segment* segments, const SegmentVelocity* velocities,
              const uint32_t* ids, size_t count, TileBlocks* out) {
    for (size_t i = 0; i < count; ++i) {
        // A tile's segments are near in memory, not adjacent: fetch one a
        // few walks ahead (its load was ~10% of the loop).
        if (i + kPrefetch < count) {
            const char* ahead = reinterpret_cast<const char*>(&segments[ids[i + kPrefetch]]);
            _mm_prefetch(ahead, _MM_HINT_T0);
            _mm_prefetch(ahead + sizeof(Segment) - 1, _MM_HINT_T0);
        }
        const SegmentVelocity* v = C == 4 ? &velocities[ids[i]] : nullptr;
        if (box)
            depositBox(tile, segments[ids[i]], v);
        else
            depositTrilinear(tile, segments[ids[i]], v);
    }
    extractBlocks(tile, out);
}

template void fillTile<1>(TileBuffer<1>&, bool, const Segment*, const SegmentVelocity*, const uint32_t*, size_t,
                          TileBlocks*);
template void fillTile<4>(TileBuffer<4>&, bool, const Segment*, const SegmentVelocity*, const uint32_t*, size_t,
                          TileBlocks*);

}  // namespace hp::voxel_tiles
