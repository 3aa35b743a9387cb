// @brief The voxelizer's dual-cell walk inside one tile, and the Gauss-Legendre
// rule of its deposits: shared by the SSE2 reference kernel
// (render/volume/voxel_tiles.cpp) and the AVX2 one (voxel_tiles_avx2.cpp),
// so both cut a segment at the same planes, bit for bit. Internal to
// render/volume/; SSE2 only (the x86-64 baseline), so it inlines into either.
#pragma once

#include "render/volume/voxel_tiles.h"

#include <emmintrin.h>  // SSE2, the x86-64 baseline

#include <algorithm>
#include <cmath>
#include <limits>

namespace hp::voxel_tiles {

/// How many segments ahead the tile loops prefetch.
constexpr size_t kPrefetch = 4;

/// Three-point Gauss-Legendre on [-1, 1]: exact for polynomials of degree 5,
/// i.e. r(t)² (degree 2) times the trilinear weights (degree 3) along a line.
inline constexpr double kGaussX[3] = {-0.7745966692414834, 0.0, 0.7745966692414834};
inline constexpr double kGaussW[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};

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
inline bool startWalk(const Segment& s, const Vec3i& origin, WalkStart* w) {
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
    // The cell in three registers, each advanced by its step and a mask
    // (cell[e] += step[e] with e computed went through memory: a store and
    // three reloads a piece).
    int cx = w.cell[0], cy = w.cell[1], cz = w.cell[2];
    const int stepX = w.step[0], stepY = w.step[1], stepZ = w.step[2];
    double t = w.tIn;
    for (;;) {
        // e = 1 if t_y < t_x, else 0; then 2 if t_z < t_e.
        const __m128d ty = _mm_unpackhi_pd(txy, txy);
        const __m128d yFirst = _mm_cmplt_sd(ty, txy);                      // low lane: t_y < t_x
        const __m128d te = _mm_or_pd(_mm_and_pd(yFirst, ty), _mm_andnot_pd(yFirst, txy));
        const __m128d zFirst = _mm_cmplt_sd(tz, te);                       // low lane: t_z < t_e
        const double tNext = _mm_cvtsd_f64(_mm_or_pd(_mm_and_pd(zFirst, tz), _mm_andnot_pd(zFirst, te)));
        const int zBit = _mm_movemask_pd(zFirst) & 1, yBit = _mm_movemask_pd(yFirst) & 1;  // e = z, y or x
        const double t1 = std::min(tNext, 1.0);
        // The tile owns voxels 0..kTile-1, so cells -1..kTile-1 reach it.
        const int lx = cx - ox, ly = cy - oy, lz = cz - oz;
        if (t1 > t && unsigned(lx + 1) <= unsigned(kTile) && unsigned(ly + 1) <= unsigned(kTile) &&
            unsigned(lz + 1) <= unsigned(kTile))
            piece(lx, ly, lz, t, t1, _mm_sub_pd(pxy, fxy), _mm_cvtsd_f64(_mm_sub_sd(pz, fz)));
        if (tNext >= w.tOut) return;  // tOut ≤ 1: the segment's end or the box's
        t = std::max(t, t1);
        cx += stepX & -((zBit | yBit) ^ 1);
        cy += stepY & -(yBit & (zBit ^ 1));
        cz += stepZ & -zBit;
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


}  // namespace hp::voxel_tiles
