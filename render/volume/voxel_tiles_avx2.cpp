// The AVX2 kernel of the voxelizer's trilinear density deposit
// (render/volume/voxel_tiles.h): the same pieces, the same Gauss-Legendre
// rule and the same operations as the SSE2 reference in voxel_tiles.cpp, four
// pieces at a time, one in each lane of a 4-double vector. Chosen at run time
// (hasAvx2) where the CPU has AVX2; compiled for it by the target pragma
// below, so the rest of the program keeps the x86-64 baseline.
//
// Same values, bit for bit: every lane performs the reference's scalar
// operations in the reference's order (no FMA: a fused a·b + c rounds once
// where the reference rounds twice), and the corners go into the tile in
// piece order, so each voxel's sum is formed in the same order.
#include "render/volume/tile_walk.h"
#include "render/volume/voxel_tiles.h"

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace hp::voxel_tiles {

namespace {

/// Room for the pieces of one segment in one tile: a segment spanning at
/// most kMaxSpan voxels per axis crosses at most 17 planes per axis, so it
/// has at most 3 · 17 + 1 = 52 pieces. The voxelizer's parts span at most 16
/// (kMaxPartVoxels in render/volume/voxelizer.cpp); a longer segment goes to
/// the reference kernel (same values).
constexpr int kMaxPieces = 64;
constexpr double kMaxSpan = 16.5;

/// The pieces of one segment's walk through a tile, collected so the deposit
/// can work on four at once. Defined before the target pragma: walkTile
/// (tile_walk.h, baseline code) inlines it into the AVX2 caller.
struct PieceBatch {
    alignas(32) double t0[kMaxPieces + 3];
    alignas(32) double t1[kMaxPieces + 3];
    int32_t cell[3][kMaxPieces + 3];  // tile-local cell (lx, ly, lz); rows 1 and 2 need not be
                                      // 16-byte aligned (kMaxPieces + 3 ints a row): read unaligned
    int count = 0;
};

struct Collect {
    PieceBatch* batch;
    void operator()(int lx, int ly, int lz, double t0, double t1, __m128d, double) const {
        PieceBatch& b = *batch;
        b.t0[b.count] = t0;
        b.t1[b.count] = t1;
        b.cell[0][b.count] = lx;
        b.cell[1][b.count] = ly;
        b.cell[2][b.count] = lz;
        ++b.count;
    }
};

}  // namespace

}  // namespace hp::voxel_tiles

#pragma GCC push_options
#pragma GCC target("avx2")

namespace hp::voxel_tiles {

namespace {

/// Deposits pieces [0, batch.count) of segment s (see depositTrilinear in
/// voxel_tiles.cpp for the rule and its equations). Lanes past the count
/// compute on t0 = t1 = 0 (weight 0) and store nothing.
void depositBatch(TileBuffer<1>& tile, const Segment& s, PieceBatch& batch) {
    double* const values = tile.values.data();
    const int n = batch.count;
    for (int i = n; i < ((n + 3) & ~3); ++i) {
        batch.t0[i] = batch.t1[i] = 0.0;
        batch.cell[0][i] = batch.cell[1][i] = batch.cell[2][i] = 0;
    }
    const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0), half = _mm256_set1_pd(0.5);
    const __m256d ax = _mm256_set1_pd(s.a.x()), ay = _mm256_set1_pd(s.a.y()), az = _mm256_set1_pd(s.a.z());
    const __m256d dx = _mm256_set1_pd(s.b.x() - s.a.x()), dy = _mm256_set1_pd(s.b.y() - s.a.y()),
                  dz = _mm256_set1_pd(s.b.z() - s.a.z());
    const __m256d r0 = _mm256_set1_pd(s.r0), dr = _mm256_set1_pd(s.r1 - s.r0), k = _mm256_set1_pd(s.k);
    const __m128i ox = _mm_set1_epi32(tile.origin.x()), oy = _mm_set1_epi32(tile.origin.y()),
                  oz = _mm_set1_epi32(tile.origin.z());
    for (int p = 0; p < n; p += 4) {
        const __m256d t0 = _mm256_load_pd(batch.t0 + p), t1 = _mm256_load_pd(batch.t1 + p);
        const __m256d mid = _mm256_mul_pd(half, _mm256_add_pd(t0, t1)), h = _mm256_mul_pd(half, _mm256_sub_pd(t1, t0));
        const __m256d kh = _mm256_mul_pd(k, h);
        const __m128i lx = _mm_loadu_si128(reinterpret_cast<const __m128i*>(batch.cell[0] + p));
        const __m128i ly = _mm_loadu_si128(reinterpret_cast<const __m128i*>(batch.cell[1] + p));
        const __m128i lz = _mm_loadu_si128(reinterpret_cast<const __m128i*>(batch.cell[2] + p));
        // f at t = 0: a − c, c the cell's corner (0,0,0) in index space (exact integers).
        const __m256d bx = _mm256_sub_pd(ax, _mm256_cvtepi32_pd(_mm_add_epi32(lx, ox)));
        const __m256d by = _mm256_sub_pd(ay, _mm256_cvtepi32_pd(_mm_add_epi32(ly, oy)));
        const __m256d bz = _mm256_sub_pd(az, _mm256_cvtepi32_pd(_mm_add_epi32(lz, oz)));
        // The 8 moments Σ_g w·{1, f_x}·{1, f_y}·{1, f_z}, products formed as in the reference.
        __m256d m1 = zero, mx = zero, my = zero, mxy = zero, mz = zero, mxz = zero, myz = zero, mxyz = zero;
        for (int g = 0; g < 3; ++g) {
            const __m256d tg = _mm256_add_pd(mid, _mm256_mul_pd(h, _mm256_set1_pd(kGaussX[g])));
            auto clamp01 = [&](__m256d f) { return _mm256_min_pd(_mm256_max_pd(f, zero), one); };
            const __m256d fx = clamp01(_mm256_add_pd(bx, _mm256_mul_pd(dx, tg)));
            const __m256d fy = clamp01(_mm256_add_pd(by, _mm256_mul_pd(dy, tg)));
            const __m256d fz = clamp01(_mm256_add_pd(bz, _mm256_mul_pd(dz, tg)));
            const __m256d r = _mm256_add_pd(r0, _mm256_mul_pd(dr, tg));
            const __m256d w = _mm256_mul_pd(_mm256_mul_pd(r, r), _mm256_mul_pd(kh, _mm256_set1_pd(kGaussW[g])));
            const __m256d wx = _mm256_mul_pd(w, fx), wy = _mm256_mul_pd(w, fy), wxy = _mm256_mul_pd(wx, fy);
            m1 = _mm256_add_pd(m1, w);
            mx = _mm256_add_pd(mx, wx);
            my = _mm256_add_pd(my, wy);
            mxy = _mm256_add_pd(mxy, wxy);
            mz = _mm256_add_pd(mz, _mm256_mul_pd(w, fz));
            mxz = _mm256_add_pd(mxz, _mm256_mul_pd(wx, fz));
            myz = _mm256_add_pd(myz, _mm256_mul_pd(wy, fz));
            mxyz = _mm256_add_pd(mxyz, _mm256_mul_pd(wxy, fz));
        }
        // Inclusion-exclusion, as the reference: per (X, Y) the all-z sum,
        // the Z_1 part (top) and Z_0 = all − top (bottom).
        const __m256d a0 = _mm256_sub_pd(m1, my), a1 = _mm256_sub_pd(mx, mxy);
        const __m256d b0 = _mm256_sub_pd(mz, myz), b1 = _mm256_sub_pd(mxz, mxyz);
        const __m256d top00 = _mm256_sub_pd(b0, b1), top10 = b1;                     // (X, Y) = (0,0), (1,0)
        const __m256d top01 = _mm256_sub_pd(myz, mxyz), top11 = mxyz;               // (0,1), (1,1)
        const __m256d bot00 = _mm256_sub_pd(_mm256_sub_pd(a0, a1), top00), bot10 = _mm256_sub_pd(a1, top10);
        const __m256d bot01 = _mm256_sub_pd(_mm256_sub_pd(my, mxy), top01), bot11 = _mm256_sub_pd(mxy, top11);
        // Corner pairs (Z_0, Z_1): unpacklo holds pieces p and p + 2, unpackhi p + 1 and p + 3.
        const __m256d lo[4] = {_mm256_unpacklo_pd(bot00, top00), _mm256_unpacklo_pd(bot01, top01),
                               _mm256_unpacklo_pd(bot10, top10), _mm256_unpacklo_pd(bot11, top11)};
        const __m256d hi[4] = {_mm256_unpackhi_pd(bot00, top00), _mm256_unpackhi_pd(bot01, top01),
                               _mm256_unpackhi_pd(bot10, top10), _mm256_unpackhi_pd(bot11, top11)};
        // At x·kPad² + y·kPad from corner (0,0,0): (0,0), (0,1), (1,0), (1,1).
        constexpr int kOffset[4] = {0, kPad, kPad * kPad, kPad * kPad + kPad};
        for (int j = 0; j < 4 && p + j < n; ++j) {
            const int q = p + j;
            const int lxq = batch.cell[0][q], lyq = batch.cell[1][q], lzq = batch.cell[2][q];
            double* c = values + TileBuffer<1>::index(lxq, lyq, lzq);
            for (int i = 0; i < 4; ++i) {
                const __m256d v = (j & 1) ? hi[i] : lo[i];
                const __m128d pair = (j & 2) ? _mm256_extractf128_pd(v, 1) : _mm256_castpd256_pd128(v);
                double* at = c + kOffset[i];
                _mm_storeu_pd(at, _mm_add_pd(_mm_loadu_pd(at), pair));
            }
            tile.mark(lxq, lyq, lzq);
        }
    }
    batch.count = 0;
}

}  // namespace

bool hasAvx2() { return __builtin_cpu_supports("avx2"); }

void depositTrilinearAvx2(TileBuffer<1>& tile, const Segment* segments, const uint32_t* ids, size_t count) {
    PieceBatch batch;
    for (size_t i = 0; i < count; ++i) {
        if (i + kPrefetch < count) {
            const char* ahead = reinterpret_cast<const char*>(&segments[ids[i + kPrefetch]]);
            _mm_prefetch(ahead, _MM_HINT_T0);
            _mm_prefetch(ahead + sizeof(Segment) - 1, _MM_HINT_T0);
        }
        const Segment& s = segments[ids[i]];
        const __m128d span = _mm_max_pd(_mm_andnot_pd(_mm_set1_pd(-0.0), _mm_sub_pd(_mm_loadu_pd(&s.b.x()), _mm_loadu_pd(&s.a.x()))),
                                        _mm_set_sd(std::abs(s.b.z() - s.a.z())));
        if (!(std::max(_mm_cvtsd_f64(span), _mm_cvtsd_f64(_mm_unpackhi_pd(span, span))) <= kMaxSpan)) {
            depositTrilinearReference(tile, s);
            continue;
        }
        walkTile(s, tile.origin, Collect{&batch});
        if (batch.count > 0) depositBatch(tile, s, batch);
    }
}

}  // namespace hp::voxel_tiles

#pragma GCC pop_options
