// The hair-hair grid (equations and determinism: sim/volume/hair_grid.h).
#include "sim/volume/hair_grid.h"

#include "core/errors.h"
#include "sim/volume/excess_diffusion.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <emmintrin.h>

namespace hp {

void VolumeSettings::validate() const {
    auto check = [](bool ok, const char* what) {
        if (!ok) throw Error(cat("volume settings: ", what));
    };
    check(cellSize > 0.f, "cell size must be positive");
    check(targetDensity > 0.f, "target density must be positive");
    check(friction >= 0.f, "friction must be ≥ 0");
    check(relaxTime >= 0.f, "relax time must be ≥ 0");
    check(contactScale >= 0.f, "contact scale must be ≥ 0");
    check(contactIterations >= 1, "contact iterations must be ≥ 1");
}

}  // namespace hp

namespace hp::volume {
namespace {

/// At most this many nodes (16 bytes each): hair spread wider than the
/// grid allows at Δ is gridded at 2Δ, 4Δ, ... for that step instead.
constexpr double kMaxNodes = 4.0e6;
/// The volume step's largest fraction per substep (hair_grid.h), so that
/// one push a substep can hold hair up against gravity's g·h² a substep.
/// The push is implicit (excess_diffusion.h), so any c is stable; what
/// bounds it is the energy the push gives hair it lifts. Measured on
/// tests/test_hair_grid.cpp with the rod's BDF2 (4 sweeps): c_max 1/2 leaves
/// the ball at 338 hairs/cm² (1.5x the target) and the crossing wisps gain
/// 1.5% of the energy their fall releases; c_max 1 (8 sweeps) gains 99% of it
/// (both before the guide solver restored the pushed lengths with the push:
/// 0.7% at 1/2 since, docs/physics.md).
constexpr float kMaxPush = 0.5f;
/// Jacobi sweeps of the implicit volume step (excess_diffusion.h): a smooth
/// excess gets (1 − ρ^K) of the exact implicit push, ρ = 6c/(1 + 6c) = 0.72
/// at the default c = 0.43, so 0.73 at 4 sweeps. Measured on the ball and
/// the crossing wisps (BDF2): 1 sweep 338 hairs/cm², 0.5% energy gain;
/// 4 sweeps 338, 1.5%; 8 sweeps 300, 1.6% (lengths then restored by the step).
/// With the lengths restored with the push, one sweep (E = e/(1 + 6c), read
/// straight from the nodes) left the ball at 300 and the energy lower, but
/// the default shot's hair did not come to rest after the head stopped
/// (ShotSimulation.HairHangsUnderGravityAndSwingsWithTheHead: 10.5 m/s at
/// frame 120; 2 sweeps 0.30, 3 sweeps 1.19, 4 sweeps 0.016 m/s), so 4 stay.
constexpr int kSweeps = 4;

/// Chunks of the counting sort by node row (any number gives the same order).
constexpr size_t kSortChunks = 8;
/// Vertices below which apply() runs on the calling thread.
constexpr size_t kParallelVertices = 8192;

}  // namespace

HairGrid::HairGrid(const VolumeSettings& s) : s_(s) { s_.validate(); }

float HairGrid::blendFraction(float h) const { return 1.f - std::exp(-s_.friction * h); }

float HairGrid::pushFraction(float h) const {
    return s_.relaxTime > 0.f ? kMaxPush * (1.f - std::exp(-h / s_.relaxTime)) : 0.f;
}

GridStats HairGrid::apply(const GridInput& in, const ParallelFor& parallel) {
    GridStats st;
    const size_t n = in.count;
    // Below this many vertices the passes run on the calling thread: waking
    // workers costs more than the work (same bits either way).
    const bool serial = n < kParallelVertices;
    auto run = [&](size_t count, const std::function<void(size_t, size_t)>& f) {
        if (serial) f(0, count);
        else parallel(count, f);
    };
    // Head-local positions are computed where they are read (three times:
    // cheaper than storing and loading them), in SSE from the inverse's
    // columns, p = ((c0·x + c1·y) + c2·z) + c3: the order Eigen's
    // Isometry3f product adds in, so the same bits.
    const Eigen::Matrix4f toLocal = in.head.inverse().matrix();
    const __m128 col[4] = {_mm_loadu_ps(toLocal.data()), _mm_loadu_ps(toLocal.data() + 4),
                           _mm_loadu_ps(toLocal.data() + 8), _mm_loadu_ps(toLocal.data() + 12)};
    auto local = [&col](const Vec3f& x) {
        return _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(col[0], _mm_set1_ps(x.x())), _mm_mul_ps(col[1], _mm_set1_ps(x.y()))),
                                     _mm_mul_ps(col[2], _mm_set1_ps(x.z()))),
                          col[3]);
    };
    const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.f);
    auto valid = [&](size_t i, __m128 p) {  // a mass, and x, y, z finite (p − p is 0, not NaN)
        return in.mass[i] > 0.f && (_mm_movemask_ps(_mm_cmpord_ps(_mm_sub_ps(p, p), zero)) & 7) == 7;
    };

    // Head-local positions and their bounds (min and max do not depend on
    // the order or the chunks), and the copy of x the caller asked for.
    std::atomic<float> bound[6];
    for (int a = 0; a < 3; ++a) {
        bound[a] = INFINITY;
        bound[3 + a] = -INFINITY;
    }
    run(n, [&](size_t b, size_t e) {
        if (in.before) std::copy(in.x + b, in.x + e, in.before + b);
        __m128 lo4 = _mm_set1_ps(INFINITY), hi4 = _mm_set1_ps(-INFINITY);
        for (size_t i = b; i < e; ++i) {
            const __m128 p = local(in.x[i]);
            if (valid(i, p)) {
                lo4 = _mm_min_ps(lo4, p);
                hi4 = _mm_max_ps(hi4, p);
            }
        }
        alignas(16) float lo[4], hi[4];
        _mm_store_ps(lo, lo4);
        _mm_store_ps(hi, hi4);
        for (int a = 0; a < 3; ++a) {
            for (float m = bound[a].load(); lo[a] < m && !bound[a].compare_exchange_weak(m, lo[a]);) {
            }
            for (float m = bound[3 + a].load(); hi[a] > m && !bound[3 + a].compare_exchange_weak(m, hi[a]);) {
            }
        }
    });
    const Vec3f lo(bound[0].load(), bound[1].load(), bound[2].load());
    const Vec3f hi(bound[3].load(), bound[4].load(), bound[5].load());
    if (!(lo.x() <= hi.x())) return st;  // nothing to couple

    float d = s_.cellSize;
    Eigen::Vector3i dims;
    Vec3f origin;
    for (;;) {
        origin = (lo / d).array().floor().matrix() * d;
        const Vec3f span = (hi - origin) / d;
        dims = Eigen::Vector3i(int(span.x()) + 2, int(span.y()) + 2, int(span.z()) + 2);
        if (double(dims.x()) * dims.y() * dims.z() <= kMaxNodes) break;
        d *= 2.f;
    }
    const int nx = dims.x(), ny = dims.y(), nz = dims.z();
    const size_t plane = size_t(nx) * size_t(ny), nodes = plane * size_t(nz);
    st.cellSize = d;
    st.nodes = nodes;
    const float invD = 1.f / d;
    // A vertex's base node (i, j, k) and trilinear fractions t: f = (p −
    // origin)/Δ, base min(max(f, 0), n − 2) truncated (f in (−1, 0), from
    // rounding below the origin, gives 0 like a clamped int(f)), t =
    // clamp(f − base, 0, 1); lane by lane, so the same bits as scalar code.
    const __m128 origin4 = _mm_setr_ps(origin.x(), origin.y(), origin.z(), 0.f);
    const __m128 top = _mm_setr_ps(float(nx - 2), float(ny - 2), float(nz - 2), 0.f);
    auto locate = [=](__m128 p, __m128& t) {
        const __m128 f = _mm_mul_ps(_mm_sub_ps(p, origin4), _mm_set1_ps(invD));
        const __m128i base = _mm_cvttps_epi32(_mm_min_ps(_mm_max_ps(f, zero), top));
        t = _mm_min_ps(_mm_max_ps(_mm_sub_ps(f, _mm_cvtepi32_ps(base)), zero), one);
        return base;
    };
    auto laneOf = [](__m128i v, int lane) {
        return _mm_cvtsi128_si32(lane == 0 ? v : lane == 1 ? _mm_shuffle_epi32(v, 0x55) : _mm_shuffle_epi32(v, 0xaa));
    };

    // Vertices by the node row (j, k) of their base node, in vertex order
    // within a row (a stable counting sort), their cells and (m, v) written
    // in that order. Every pass walks it: neighbouring entries read and
    // write the same few rows of nodes and read their own data in a stream
    // (in vertex order the guides cross the lattice, and every vertex's
    // nodes were a cache miss; in a sorted order read through an index,
    // every vertex's own data was). A row of slab k lies in slab k, so each
    // slab is a contiguous range.
    const size_t rows = size_t(ny) * size_t(nz);
    constexpr uint32_t kNone = ~0u;
    rowOf_.resize(n);
    // The counting sort in chunks of vertices: each chunk counts its rows
    // and the x span of each row's base nodes, the offsets interleave the
    // chunks row by row, then each chunk writes its vertices' entries
    // straight to their places (the cell found again: cheaper than storing
    // it). A stable sort's result is unique, so the chunks change nothing
    // but the time.
    const size_t chunks = serial ? 1 : kSortChunks;
    auto chunkBegin = [&](size_t ch) { return n * ch / chunks; };
    rowCount_.assign(chunks * rows, 0u);  // chunk-major: chunks on two threads share no cache line
    // A chunk's span of a row is set by its first vertex there (count 0 to
    // 1), so these need no clearing.
    chunkLo_.resize(chunks * rows);
    chunkHi_.resize(chunks * rows);
    run(chunks, [&](size_t cb, size_t ce) {
        for (size_t ch = cb; ch < ce; ++ch) {
            uint32_t* count = rowCount_.data() + ch * rows;
            int* spanLo = chunkLo_.data() + ch * rows;
            int* spanHi = chunkHi_.data() + ch * rows;
            for (size_t i = chunkBegin(ch), end = chunkBegin(ch + 1); i < end; ++i) {
                const __m128 p = local(in.x[i]);
                if (!valid(i, p)) {
                    rowOf_[i] = kNone;
                    continue;
                }
                __m128 t;
                const __m128i base = locate(p, t);
                const uint32_t r = uint32_t(size_t(laneOf(base, 2)) * size_t(ny) + size_t(laneOf(base, 1)));
                const int x = laneOf(base, 0);
                rowOf_[i] = r;
                if (count[r]++ == 0) {
                    spanLo[r] = spanHi[r] = x;
                } else {
                    spanLo[r] = std::min(spanLo[r], x);
                    spanHi[r] = std::max(spanHi[r], x);
                }
            }
        }
    });

    // The offsets, and the nodes the vertices can touch, stored row by
    // row: node row (j, k) holds the x span its four base rows (j − 1..j,
    // k − 1..k) reach, i_min to i_max + 1, so a node is N[rowBase[row] + i],
    // with a zero slot either side (the volume step's sweeps read a row's x
    // neighbours without a test). On B-sim's 845 guides this stores 42% of
    // the box's nodes (rod: 30,300 of 72,813; rope, its hair standing out
    // from the sphere: 51% of 181,476); the splat, the gathers and the
    // clear then touch less memory. The sums are the same, term by term,
    // as on the whole box. One serial loop over the rows: a row's layout
    // reads the spans of rows before it only.
    rowStart_.resize(rows + 1);
    spanLo_.resize(rows);
    spanHi_.resize(rows);
    rowBase_.resize(rows);
    rowLo_.resize(rows);
    rowEnd_.resize(rows);
    planeStart_.resize(size_t(nz) + 1);
    uint32_t total = 0;
    size_t stored = 0, storedNodes = 0;
    for (size_t r = 0; r < rows; ++r) {
        rowStart_[r] = total;
        int slo = std::numeric_limits<int>::max(), shi = -1;
        for (size_t ch = 0; ch < chunks; ++ch) {
            uint32_t& at = rowCount_[ch * rows + r];
            const uint32_t count = at;
            if (count) {
                slo = std::min(slo, chunkLo_[ch * rows + r]);
                shi = std::max(shi, chunkHi_[ch * rows + r]);
            }
            at = total;  // now chunk ch's next place in row r
            total += count;
        }
        spanLo_[r] = slo;
        spanHi_[r] = shi;
        const size_t j = r % size_t(ny), k = r / size_t(ny);
        if (j == 0) planeStart_[k] = uint32_t(stored);
        int ilo = slo, ihi = shi;  // base rows (j, k), (j − 1, k), (j, k − 1), (j − 1, k − 1)
        if (j > 0) ilo = std::min(ilo, spanLo_[r - 1]), ihi = std::max(ihi, spanHi_[r - 1]);
        if (k > 0) ilo = std::min(ilo, spanLo_[r - size_t(ny)]), ihi = std::max(ihi, spanHi_[r - size_t(ny)]);
        if (j > 0 && k > 0) ilo = std::min(ilo, spanLo_[r - size_t(ny) - 1]), ihi = std::max(ihi, spanHi_[r - size_t(ny) - 1]);
        if (ihi < 0) {
            rowBase_[r] = 0;  // no vertex reaches this row
            rowLo_[r] = rowEnd_[r] = 0;
            continue;
        }
        rowBase_[r] = ptrdiff_t(stored) + 1 - ilo;
        rowLo_[r] = ilo;
        rowEnd_[r] = ihi + 2;
        storedNodes += size_t(ihi + 2 - ilo);
        stored += size_t(ihi + 2 - ilo) + 2;
    }
    rowStart_[rows] = total;
    planeStart_[size_t(nz)] = uint32_t(stored);
    st.storedNodes = storedNodes;
    const size_t gridded = total;
    entries_.resize(gridded);
    order_.resize(gridded);
    if (nodes_.size() < stored) nodes_.resize(stored);
    Eigen::Vector4f* const N = nodes_.data();
    run(chunks, [&, N](size_t cb, size_t ce) {
        for (size_t ch = cb; ch < ce; ++ch) {
            // The nodes are cleared here, in chunks, before the splat.
            std::memset(static_cast<void*>(N + stored * ch / chunks), 0,
                        (stored * (ch + 1) / chunks - stored * ch / chunks) * sizeof(Eigen::Vector4f));
            uint32_t* at = rowCount_.data() + ch * rows;
            for (size_t i = chunkBegin(ch), end = chunkBegin(ch + 1); i < end; ++i) {
                if (rowOf_[i] == kNone) continue;
                const uint32_t o = at[rowOf_[i]]++;
                __m128 t;
                const __m128i base = locate(local(in.x[i]), t);
                Entry& en = entries_[o];
                // t and i in one 16-byte store's place (__m128 may alias):
                // lane 3 is overwritten by i next.
                _mm_store_ps(reinterpret_cast<float*>(&en), t);
                en.i = laneOf(base, 0);
                en.mv = Eigen::Vector4f(in.mass[i], in.v[i].x(), in.v[i].y(), in.v[i].z());
                order_[o] = uint32_t(i);
            }
        }
    });

    // Even slabs, then odd slabs: each writes node planes k and k+1 only
    // (their rows lie in that order in the node array, so apart from other
    // slabs of its parity).
    auto bySlab = [&](auto&& body) {  // body(first row, end row) of a slab's base rows
        for (int parity = 0; parity < 2; ++parity) {
            const size_t slabs = size_t(std::max(0, (nz - parity) / 2));
            run(slabs, [&](size_t b, size_t e) {
                for (size_t sl = b; sl < e; ++sl) {
                    const size_t k = 2 * sl + size_t(parity);
                    body(k * size_t(ny), (k + 1) * size_t(ny));
                }
            });
        }
    };
    const Entry* const C = entries_.data();
    const uint32_t* const vertexOf = order_.data();
    const ptrdiff_t* const RB = rowBase_.data();
    const uint32_t* const RS = rowStart_.data();
    const size_t sy = size_t(ny);

    // Splat: w·(m, m·v) on the eight nodes.
    bySlab([&, N, C, RB, RS, sy](size_t firstRow, size_t endRow) {
        for (size_t r = firstRow; r < endRow; ++r)
        for (size_t o = RS[r]; o < RS[r + 1]; ++o) {
            const Entry& c = C[o];
            // mp = (m, m·v) and w = wx·(wy·wz) for the four nodes of a
            // plane (lane di + 2·dj), lane by lane as scalar code would.
            const float m = c.mv[0];
            const __m128 mp = _mm_mul_ps(_mm_load_ps(c.mv.data()), _mm_setr_ps(1.f, m, m, m));
            const __m128 wx = _mm_setr_ps(1.f - c.t[0], c.t[0], 1.f - c.t[0], c.t[0]);
            const __m128 wy = _mm_setr_ps(1.f - c.t[1], 1.f - c.t[1], c.t[1], c.t[1]);
            const float wz[2] = {1.f - c.t[2], c.t[2]};
            for (int dk = 0; dk < 2; ++dk) {
                const __m128 w = _mm_mul_ps(wx, _mm_mul_ps(wy, _mm_set1_ps(wz[dk])));
                float* row0 = N[RB[r + size_t(dk) * sy] + c.i].data();
                float* row1 = N[RB[r + size_t(dk) * sy + 1] + c.i].data();
                float* at[4] = {row0, row0 + 4, row1, row1 + 4};
                _mm_store_ps(at[0], _mm_add_ps(_mm_load_ps(at[0]), _mm_mul_ps(_mm_shuffle_ps(w, w, 0x00), mp)));
                _mm_store_ps(at[1], _mm_add_ps(_mm_load_ps(at[1]), _mm_mul_ps(_mm_shuffle_ps(w, w, 0x55), mp)));
                _mm_store_ps(at[2], _mm_add_ps(_mm_load_ps(at[2]), _mm_mul_ps(_mm_shuffle_ps(w, w, 0xaa), mp)));
                _mm_store_ps(at[3], _mm_add_ps(_mm_load_ps(at[3]), _mm_mul_ps(_mm_shuffle_ps(w, w, 0xff), mp)));
            }
        }
    });

    // Node velocity V = P/M and density ratio r = λ/λ₀ are read on the fly:
    // r = M·lengthPerMass/(Δ³·λ₀), λ₀ from hairs per cm² to per m².
    const float toRatio = in.lengthPerMass / (d * d * d * s_.targetDensity * 1e4f);
    const float s = blendFraction(in.h), cPush = pushFraction(in.h), push = cPush * d * d;
    const Eigen::Matrix3f R = in.head.linear();
    const int* const RL = rowLo_.data();
    const int* const RE = rowEnd_.data();

    // The volume step's excess ex = max(0, r − 1) on the nodes with hair
    // (NaN on the others and on the zero slots), its first Jacobi sweep
    // E¹ = ex/(1 + 6c) (excess_diffusion.h) and the densest node, in one
    // pass over the stored nodes, plane by plane (a plane's slots are
    // contiguous), four nodes at a time; the planes holding excess bound
    // the later sweeps. Maxima and minima: the same whatever the order.
    const bool pushes = push > 0.f;
    if (pushes) {
        excess_.resize(stored);
        sweepA_.resize(stored);
        sweepB_.resize(stored);
    }
    const float inv = 1.f / (1.f + 6.f * cPush);
    std::atomic<float> maxR{0.f};
    std::atomic<int> excessLo{nz}, excessEnd{0};
    run(size_t(nz), [&, N, toRatio, inv, pushes](size_t b, size_t e) {
        const __m128 ratio4 = _mm_set1_ps(toRatio), inv4 = _mm_set1_ps(inv),
                     nan4 = _mm_set1_ps(std::numeric_limits<float>::quiet_NaN());
        float* const ex = excess_.data();
        float* const E1 = sweepA_.data();
        __m128 max4 = zero;
        int klo = nz, kend = 0;
        for (size_t k = b; k < e; ++k) {
            size_t q = planeStart_[k];
            const size_t qEnd = planeStart_[k + 1];
            __m128 above = zero;  // lanes with r > 1
            for (; q + 4 <= qEnd; q += 4) {
                const __m128 M = _mm_movelh_ps(_mm_unpacklo_ps(_mm_load_ps(N[q].data()), _mm_load_ps(N[q + 1].data())),
                                               _mm_unpacklo_ps(_mm_load_ps(N[q + 2].data()), _mm_load_ps(N[q + 3].data())));
                const __m128 r = _mm_mul_ps(M, ratio4);
                max4 = _mm_max_ps(max4, r);
                above = _mm_or_ps(above, _mm_cmpgt_ps(r, one));
                if (!pushes) continue;
                const __m128 has = _mm_cmpgt_ps(M, zero);
                const __m128 x = _mm_max_ps(_mm_sub_ps(r, one), zero);  // std::max(0.f, r − 1)
                _mm_storeu_ps(ex + q, _mm_or_ps(_mm_and_ps(has, x), _mm_andnot_ps(has, nan4)));
                _mm_storeu_ps(E1 + q, _mm_and_ps(has, _mm_mul_ps(x, inv4)));
            }
            float tailMax = 0.f;
            bool tailAbove = false;
            for (; q < qEnd; ++q) {
                const float M = N[q][0], r = M * toRatio;
                tailMax = std::max(tailMax, r);
                tailAbove = tailAbove || r > 1.f;
                if (!pushes) continue;
                ex[q] = M > 0.f ? std::max(0.f, r - 1.f) : std::numeric_limits<float>::quiet_NaN();
                E1[q] = firstSweep(ex[q], inv);
            }
            max4 = _mm_max_ps(max4, _mm_set1_ps(tailMax));
            if (tailAbove || _mm_movemask_ps(above) != 0) {
                klo = std::min(klo, int(k));
                kend = int(k) + 1;
            }
        }
        alignas(16) float m4[4];
        _mm_store_ps(m4, max4);
        const float localMax = std::max(std::max(m4[0], m4[1]), std::max(m4[2], m4[3]));
        for (float m = maxR.load(); localMax > m && !maxR.compare_exchange_weak(m, localMax);) {
        }
        for (int m = excessLo.load(); klo < m && !excessLo.compare_exchange_weak(m, klo);) {
        }
        for (int m = excessEnd.load(); kend > m && !excessEnd.compare_exchange_weak(m, kend);) {
        }
    });
    st.maxDensity = maxR.load() * s_.targetDensity;

    // The rest of the implicit volume step (excess_diffusion.h): K sweeps
    // from E⁰ = 0 reach K − 1 nodes beyond the excess, so only the planes
    // that near it are swept, and the same E as on the whole lattice.
    const bool relaxed = pushes && excessLo.load() < excessEnd.load();
    const float* E = nullptr;
    if (relaxed) {
        NodeRows nodeRows;
        nodeRows.nx = nx;
        nodeRows.ny = ny;
        nodeRows.nz = nz;
        nodeRows.base = RB;
        nodeRows.lo = RL;
        nodeRows.end = RE;
        nodeRows.planeStart = planeStart_.data();
        E = relaxRows(nodeRows, excess_.data(), cPush, kSweeps, excessLo.load(), excessEnd.load(), sweepA_.data(),
                      sweepB_.data(), run);
    }

    // One pass over the sorted vertices reads each vertex's eight nodes
    // once for friction, the density it reads and the volume push, four
    // vertices at a time, one in each SSE lane: every lane does a scalar
    // loop's operations on its vertex in the scalar order (SSE rounds each
    // lane as the scalar operation does), so the same bits; a lane past the
    // chunk's end repeats the last vertex and writes nothing.
    std::atomic<size_t> pushed{0};
    run(gridded, [&, N, E, C, vertexOf, RB, RS, sy, toRatio, s, push, invD](size_t b, size_t e) {
        size_t moved = 0;
        size_t row = size_t(std::upper_bound(RS, RS + rows + 1, uint32_t(b)) - RS) - 1;  // the row of entry b
        const __m128 ratio4 = _mm_set1_ps(toRatio);
        const __m128 dW[2] = {_mm_set1_ps(-invD), _mm_set1_ps(invD)};  // w' of the lower and upper node
        for (size_t o0 = b; o0 < e; o0 += 4) {
            const size_t lanes = std::min<size_t>(4, e - o0);
            size_t at[4];                    // entry of each lane
            ptrdiff_t node[4][4];            // lane, dj + 2·dk: the index of node (i, j + dj, k + dk)
            __m128 T[4];
            for (size_t l = 0; l < 4; ++l) {
                const size_t o = o0 + std::min(l, lanes - 1);
                while (o >= RS[row + 1]) ++row;
                at[l] = o;
                T[l] = _mm_load_ps(C[o].t);  // t and i's bits
                for (int dk = 0; dk < 2; ++dk)
                    for (int dj = 0; dj < 2; ++dj) node[l][dj + 2 * dk] = RB[row + size_t(dk) * sy + size_t(dj)] + C[o].i;
            }
            _MM_TRANSPOSE4_PS(T[0], T[1], T[2], T[3]);  // T[a]: t of axis a, lane by lane
            const __m128 wx[2] = {_mm_sub_ps(one, T[0]), T[0]}, wy[2] = {_mm_sub_ps(one, T[1]), T[1]},
                         wz[2] = {_mm_sub_ps(one, T[2]), T[2]};
            // Friction: V̄ = Σ_n (w_n/M_n)·P_n over the nodes with mass, and
            // r = Σ_n w_n·M_n·toRatio, node n = di + 2·dj + 4·dk in order.
            __m128 Vx = zero, Vy = zero, Vz = zero, r = zero;
            for (int dk = 0; dk < 2; ++dk)
                for (int dj = 0; dj < 2; ++dj)
                    for (int di = 0; di < 2; ++di) {
                        // Lane l's node (M, P), transposed to M, Px, Py, Pz lane by lane.
                        __m128 M = _mm_load_ps(N[node[0][dj + 2 * dk] + di].data());  // lane 0's, until transposed
                        __m128 Px = _mm_load_ps(N[node[1][dj + 2 * dk] + di].data());
                        __m128 Py = _mm_load_ps(N[node[2][dj + 2 * dk] + di].data());
                        __m128 Pz = _mm_load_ps(N[node[3][dj + 2 * dk] + di].data());
                        _MM_TRANSPOSE4_PS(M, Px, Py, Pz);
                        const __m128 w = _mm_mul_ps(_mm_mul_ps(wx[di], wy[dj]), wz[dk]);
                        const __m128 q = _mm_div_ps(w, M);
                        const __m128 has = _mm_cmpgt_ps(M, zero);
                        Vx = _mm_add_ps(Vx, _mm_and_ps(has, _mm_mul_ps(q, Px)));
                        Vy = _mm_add_ps(Vy, _mm_and_ps(has, _mm_mul_ps(q, Py)));
                        Vz = _mm_add_ps(Vz, _mm_and_ps(has, _mm_mul_ps(q, Pz)));
                        r = _mm_add_ps(r, _mm_mul_ps(w, _mm_mul_ps(M, ratio4)));
                    }
            alignas(16) float vx[4], vy[4], vz[4], rs[4];
            _mm_store_ps(vx, Vx);
            _mm_store_ps(vy, Vy);
            _mm_store_ps(vz, Vz);
            _mm_store_ps(rs, r);
            for (size_t l = 0; l < lanes; ++l) {
                const Vec3f v = C[at[l]].mv.tail<3>();
                in.v[vertexOf[at[l]]] = v + s * (Vec3f(vx[l], vy[l], vz[l]) - v);
            }
            // The volume push where a node a vertex reads holds excess
            // (elsewhere ∇E = 0): x ← x − c·Δ²·∇E/max(1, r̄), ∇E = Σ_n E_n·∇w_n,
            // ∇w_n = (w'x·wy·wz, wx·w'y·wz, wx·wy·w'z) as ((a·b)·c), w' = ∓1/Δ.
            if (!relaxed) continue;
            __m128 En[8];  // E of node n, lane by lane
            __m128 any = zero;
            for (int p = 0; p < 4; ++p) {  // p = dj + 2·dk: each lane's nodes di = 0, 1 in one 8-byte load
                __m128 pair[4];
                for (int l = 0; l < 4; ++l) pair[l] = _mm_loadl_pi(zero, reinterpret_cast<const __m64*>(E + node[l][p]));
                const __m128 lo01 = _mm_unpacklo_ps(pair[0], pair[1]), lo23 = _mm_unpacklo_ps(pair[2], pair[3]);
                const int dj = p & 1, dk = p >> 1;
                En[4 * dk + 2 * dj] = _mm_movelh_ps(lo01, lo23);
                En[4 * dk + 2 * dj + 1] = _mm_movehl_ps(lo23, lo01);
                any = _mm_or_ps(any, _mm_or_ps(_mm_cmpneq_ps(En[4 * dk + 2 * dj], zero),
                                                 _mm_cmpneq_ps(En[4 * dk + 2 * dj + 1], zero)));
            }
            if (_mm_movemask_ps(any) == 0) continue;
            __m128 gx = zero, gy = zero, gz = zero;
            for (int dk = 0; dk < 2; ++dk)
                for (int dj = 0; dj < 2; ++dj)
                    for (int di = 0; di < 2; ++di) {
                        const __m128 En_ = En[di + 2 * dj + 4 * dk];
                        gx = _mm_add_ps(gx, _mm_mul_ps(En_, _mm_mul_ps(_mm_mul_ps(dW[di], wy[dj]), wz[dk])));
                        gy = _mm_add_ps(gy, _mm_mul_ps(En_, _mm_mul_ps(_mm_mul_ps(wx[di], dW[dj]), wz[dk])));
                        gz = _mm_add_ps(gz, _mm_mul_ps(En_, _mm_mul_ps(_mm_mul_ps(wx[di], wy[dj]), dW[dk])));
                    }
            alignas(16) float g[3][4];
            _mm_store_ps(g[0], gx);
            _mm_store_ps(g[1], gy);
            _mm_store_ps(g[2], gz);
            for (size_t l = 0; l < lanes; ++l) {
                const Vec3f gv(g[0][l], g[1][l], g[2][l]);
                if (gv.squaredNorm() > 0.f) {
                    in.x[vertexOf[at[l]]] -= (push / std::max(1.f, rs[l])) * (R * gv);
                    ++moved;
                }
            }
        }
        pushed += moved;
    });
    st.pushed = pushed;

    return st;
}

}  // namespace hp::volume
