// The tile deposits of the voxelizer (render/volume/voxel_tiles.h): the cell
// walk and the Gauss-Legendre integrals of the box and trilinear filters.
#include "render/volume/voxel_tiles.h"

#include "render/volume/cell_walk.h"
#include "render/volume/tile_walk.h"

#include <emmintrin.h>  // SSE2, the x86-64 baseline
#include <xmmintrin.h>  // _mm_prefetch

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

namespace hp::voxel_tiles {

namespace {

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
    DensityGrid::DensityBlockPtr spare;
    for (int bx = 0; bx < kBlocksPerTile; ++bx)
        for (int by = 0; by < kBlocksPerTile; ++by)
            for (int bz = 0; bz < kBlocksPerTile; ++bz) {
                // Voxel block b receives deposits from the dual cells of cell blocks b and b + 1.
                bool touched = false;
                for (int i = 0; i < 8; ++i) touched |= tile.isTouched(bx + (i >> 2), by + ((i >> 1) & 1), bz + (i & 1));
                if (!touched) continue;
                const int x0 = bx * kBlock, y0 = by * kBlock, z0 = bz * kBlock;
                // Converted in one pass; dropped after if it holds no hair
                // (only zero deposits, e.g. exactly on a voxel plane).
                if (!spare) spare.reset(new DensityGrid::DensityBlock);  // every voxel written below
                DensityGrid::DensityBlock& density = *spare;
                bool any = false;
                if constexpr (C == 1) {
                    // A row of 8 voxels in SSE2: four pairs rounded to floats
                    // (cvtpd2ps rounds as float(double) does) and compared
                    // with 0 (GCC compiled the scalar loop to a compare, a
                    // set and an or per voxel).
                    const __m128d zero = _mm_setzero_pd();
                    __m128d positive = zero;
                    for (int x = 0; x < kBlock; ++x)
                        for (int y = 0; y < kBlock; ++y) {
                            const double* row = values + TileBuffer<C>::index(x0 + x, y0 + y, z0);
                            float* to = density.data() + DensityGrid::voxelOffset(x, y, 0);
                            const __m128d v0 = _mm_loadu_pd(row), v1 = _mm_loadu_pd(row + 2),
                                          v2 = _mm_loadu_pd(row + 4), v3 = _mm_loadu_pd(row + 6);
                            positive = _mm_or_pd(positive, _mm_or_pd(_mm_or_pd(_mm_cmpgt_pd(v0, zero), _mm_cmpgt_pd(v1, zero)),
                                                                     _mm_or_pd(_mm_cmpgt_pd(v2, zero), _mm_cmpgt_pd(v3, zero))));
                            _mm_storeu_ps(to, _mm_movelh_ps(_mm_cvtpd_ps(v0), _mm_cvtpd_ps(v1)));
                            _mm_storeu_ps(to + 4, _mm_movelh_ps(_mm_cvtpd_ps(v2), _mm_cvtpd_ps(v3)));
                        }
                    any = _mm_movemask_pd(positive) != 0;
                } else {
                    for (int x = 0; x < kBlock; ++x)
                        for (int y = 0; y < kBlock; ++y) {
                            const double* row = values + size_t(TileBuffer<C>::index(x0 + x, y0 + y, z0)) * C;
                            for (int z = 0; z < kBlock; ++z) {
                                any |= row[z * C] > 0;
                                density[size_t(DensityGrid::voxelOffset(x, y, z))] = float(row[z * C]);
                            }
                        }
                }
                if (!any) continue;
                out->origins.push_back(tile.origin + Vec3i(x0, y0, z0));
                out->density.push_back(std::move(spare));
                if constexpr (C == 4) {
                    out->velocity.emplace_back(new DensityGrid::VelocityBlock);
                    DensityGrid::VelocityBlock* velocity = out->velocity.back().get();
                    for (int x = 0; x < kBlock; ++x)
                        for (int y = 0; y < kBlock; ++y) {
                            const double* row = values + size_t(TileBuffer<C>::index(x0 + x, y0 + y, z0)) * C;
                            for (int z = 0; z < kBlock; ++z) {
                                const int i = DensityGrid::voxelOffset(x, y, z);
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
                // A row of 9 (all but the last cell block) as five explicit
                // pair stores: GCC turned the loop into a `rep stos` per row,
                // whose start-up was 40% of extracting.
                double* row = values + (size_t(x * kPad + y) * kPad + zLo) * C;
                const int count = (zHi - zLo + 1) * C;
                if (count == 9) {
                    const __m128d zero = _mm_setzero_pd();
                    _mm_storeu_pd(row, zero);
                    _mm_storeu_pd(row + 2, zero);
                    _mm_storeu_pd(row + 4, zero);
                    _mm_storeu_pd(row + 6, zero);
                    _mm_storeu_pd(row + 8, zero);
                } else {
                    for (int i = 0; i < count; i += 2) _mm_storeu_pd(row + i, _mm_setzero_pd());
                }
            }
    }
    std::fill(std::begin(tile.touched), std::end(tile.touched), 0);
}


}  // namespace

template <int C>
void fillTile(TileBuffer<C>& tile, bool box, bool avx2, const Segment* segments, const SegmentVelocity* velocities,
              const uint32_t* ids, size_t count, TileBlocks* out) {
    if constexpr (C == 1) {
        if (avx2 && !box) {
            depositTrilinearAvx2(tile, segments, ids, count);
            extractBlocks(tile, out);
            return;
        }
    }
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

void depositTrilinearReference(TileBuffer<1>& tile, const Segment& s) { depositTrilinear(tile, s, nullptr); }

template void fillTile<1>(TileBuffer<1>&, bool, bool, const Segment*, const SegmentVelocity*, const uint32_t*, size_t,
                          TileBlocks*);
template void fillTile<4>(TileBuffer<4>&, bool, bool, const Segment*, const SegmentVelocity*, const uint32_t*, size_t,
                          TileBlocks*);

}  // namespace hp::voxel_tiles
