#include "render/volume/voxelizer.h"

#include "core/errors.h"
#include "render/volume/cell_walk.h"

#include <emmintrin.h>  // SSE2, the x86-64 baseline
#include <xmmintrin.h>  // _mm_prefetch
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
/// that stays in cache (34³ doubles with its border, 314 KiB), in a fixed segment order. So
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

/// A tile's non-empty blocks, converted to floats.
struct TileBlocks {
    std::vector<Vec3i> origins;
    std::vector<DensityGrid::DensityBlockPtr> density;
    std::vector<DensityGrid::VelocityBlockPtr> velocity;
};

/// Moves the tile's non-empty blocks into `out` as floats and clears the
/// buffer (the border voxels too), leaving it zeroed for the next tile.
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
                double* row = values + (size_t(x * kPad + y) * kPad + zLo) * C;
                std::fill(row, row + size_t(zHi - zLo + 1) * C, 0.0);
            }
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

/// How many segments ahead the tile loop prefetches.
constexpr size_t kPrefetch = 4;

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
            const size_t end = bins.start[t + 1];
            for (size_t i = bins.start[t]; i < end; ++i) {
                const uint32_t g = bins.segments[i];
                // A tile's segments are near in memory, not adjacent: fetch
                // one a few walks ahead (its load was ~10% of the loop).
                if (i + kPrefetch < end) {
                    const char* ahead = reinterpret_cast<const char*>(&segments[bins.segments[i + kPrefetch]]);
                    _mm_prefetch(ahead, _MM_HINT_T0);
                    _mm_prefetch(ahead + sizeof(Segment) - 1, _MM_HINT_T0);
                }
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
