// The hair-hair grid (equations and determinism: sim/volume/hair_grid.h).
#include "sim/volume/hair_grid.h"

#include "core/errors.h"
#include "sim/volume/excess_diffusion.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>

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
constexpr int kSweeps = 4;

/// Lattices of at most this many nodes per gridded vertex are cleared
/// with one memset (845 B-sim guides: 20k vertices on 100k-180k nodes; the
/// memset took half the time of clearing each vertex's eight nodes).
constexpr size_t kClearByFill = 32;
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
    // Head-local positions are computed where they are read (twice: cheaper
    // than storing and loading them).
    const Eigen::Isometry3f toLocal = in.head.inverse();
    auto valid = [&](size_t i, const Vec3f& p) { return in.mass[i] > 0.f && p.allFinite(); };

    // Head-local positions and their bounds (min and max do not depend on
    // the order or the chunks).
    std::atomic<float> bound[6];
    for (int a = 0; a < 3; ++a) {
        bound[a] = INFINITY;
        bound[3 + a] = -INFINITY;
    }
    run(n, [&](size_t b, size_t e) {
        Vec3f lo = Vec3f::Constant(INFINITY), hi = Vec3f::Constant(-INFINITY);
        for (size_t i = b; i < e; ++i) {
            const Vec3f p = toLocal * in.x[i];
            if (valid(i, p)) {
                lo = lo.cwiseMin(p);
                hi = hi.cwiseMax(p);
            }
        }
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
    auto index = [nx, ny](int i, int j, int k) {
        return (size_t(k) * size_t(ny) + size_t(j)) * size_t(nx) + size_t(i);
    };
    // Written field by field into the array: a Cell built on the stack and
    // copied whole stalled on store forwarding (perf: 70% of this pass).
    auto cellOf = [&](size_t i, const Vec3f& p, Cell& c) {
        const Vec3f f = (p - origin) * invD;
        // int() truncates: floor for f ≥ 0, and f > −1 (rounding below the
        // origin) gives 0 either way after the clamp, with t clamped to 0.
        c.i = std::clamp(int(f.x()), 0, nx - 2);
        c.j = std::clamp(int(f.y()), 0, ny - 2);
        c.k = std::clamp(int(f.z()), 0, nz - 2);
        c.tx = std::clamp(f.x() - float(c.i), 0.f, 1.f);
        c.ty = std::clamp(f.y() - float(c.j), 0.f, 1.f);
        c.tz = std::clamp(f.z() - float(c.k), 0.f, 1.f);
        c.node = uint32_t(index(c.i, c.j, c.k));
        c.vertex = uint32_t(i);
    };

    // The node array is all zeros between calls (apply() clears the nodes it
    // touched before returning), so only growth costs a fill.
    if (nodes_.size() < nodes) nodes_.resize(nodes, Eigen::Vector4f::Zero());

    // Vertices by the node row (j, k) of their base node, in vertex order
    // within a row (a stable counting sort), their cells and (m, v) copied
    // in that order. Every pass walks it: neighbouring entries read and
    // write the same few rows of nodes and read their own data in a stream
    // (in vertex order the guides cross the lattice, and every vertex's
    // nodes were a cache miss; in a sorted order read through an index,
    // every vertex's own data was). A row of slab k lies in slab k, so each
    // slab is a contiguous range.
    const size_t rows = size_t(ny) * size_t(nz);
    constexpr uint32_t kNone = ~0u;
    vertexCells_.resize(n);
    rowOf_.resize(n);
    run(n, [&](size_t b, size_t e) {
        for (size_t i = b; i < e; ++i) {
            const Vec3f p = toLocal * in.x[i];
            if (!valid(i, p)) {
                rowOf_[i] = kNone;
                continue;
            }
            Cell& c = vertexCells_[i];
            cellOf(i, p, c);
            rowOf_[i] = uint32_t(size_t(c.k) * size_t(ny) + size_t(c.j));
        }
    });
    rowStart_.assign(rows + 1, 0u);
    for (size_t i = 0; i < n; ++i)
        if (rowOf_[i] != kNone) ++rowStart_[rowOf_[i] + 1];
    for (size_t r = 0; r < rows; ++r) rowStart_[r + 1] += rowStart_[r];
    const size_t gridded = rowStart_[rows];
    fill_.assign(rowStart_.begin(), rowStart_.end() - 1);
    cells_.resize(gridded);
    for (size_t i = 0; i < n; ++i)
        if (rowOf_[i] != kNone) cells_[fill_[rowOf_[i]]++].vertex = uint32_t(i);
    massVel_.resize(gridded);
    run(gridded, [&](size_t b, size_t e) {
        for (size_t o = b; o < e; ++o) {
            const size_t i = cells_[o].vertex;
            cells_[o] = vertexCells_[i];
            massVel_[o] = Eigen::Vector4f(in.mass[i], in.v[i].x(), in.v[i].y(), in.v[i].z());
        }
    });
    auto slabStart = [&](size_t k) { return rowStart_[k * size_t(ny)]; };

    // Even slabs, then odd slabs: each writes node planes k and k+1 only.
    auto bySlab = [&](auto&& body) {  // body(first, end) over a slab's range of the order
        for (int parity = 0; parity < 2; ++parity) {
            const size_t slabs = size_t(std::max(0, (nz - parity) / 2));
            run(slabs, [&](size_t b, size_t e) {
                for (size_t sl = b; sl < e; ++sl) {
                    const size_t k = 2 * sl + size_t(parity);
                    body(size_t(slabStart(k)), size_t(slabStart(k + 1)));
                }
            });
        }
    };
    Eigen::Vector4f* const N = nodes_.data();
    const Cell* const C = cells_.data();
    const size_t sx = size_t(nx);

    // Splat: w·(m, m·v) on the eight nodes.
    bySlab([&, N, C, sx, plane](size_t first, size_t end) {
        for (size_t o = first; o < end; ++o) {
            const Cell& c = C[o];
            const float m = massVel_[o][0];
            const Eigen::Vector4f mp(m, m * massVel_[o][1], m * massVel_[o][2], m * massVel_[o][3]);
            const float wx[2] = {1.f - c.tx, c.tx}, wy[2] = {1.f - c.ty, c.ty}, wz[2] = {1.f - c.tz, c.tz};
            for (int dk = 0; dk < 2; ++dk)
                for (int dj = 0; dj < 2; ++dj) {
                    Eigen::Vector4f* row = N + c.node + size_t(dk) * plane + size_t(dj) * sx;
                    const float wyz = wy[dj] * wz[dk];
                    for (int di = 0; di < 2; ++di) row[di] += (wx[di] * wyz) * mp;
                }
        }
    });

    // Node velocity V = P/M and density ratio r = λ/λ₀ are read on the fly:
    // r = M·lengthPerMass/(Δ³·λ₀), λ₀ from hairs per cm² to per m².
    const float toRatio = in.lengthPerMass / (d * d * d * s_.targetDensity * 1e4f);
    const float s = blendFraction(in.h), cPush = pushFraction(in.h), push = cPush * d * d;

    // Friction, and the density each vertex reads: the densest node a
    // vertex reads and the box of nodes above the target (minima and
    // maxima: the same whatever the order), in one pass over the nodes.
    std::atomic<float> maxR{0.f};
    std::atomic<int> boxLo[3] = {nx, ny, nz}, boxHi[3] = {-1, -1, -1};
    auto lower = [](std::atomic<int>& a, int v) {
        for (int m = a.load(); v < m && !a.compare_exchange_weak(m, v);) {
        }
    };
    auto raise = [](std::atomic<int>& a, int v) {
        for (int m = a.load(); v > m && !a.compare_exchange_weak(m, v);) {
        }
    };
    ratio_.resize(gridded);
    run(gridded, [&, N, C, sx, plane, toRatio, s](size_t b, size_t e) {
        float localMax = 0.f;
        int lo3[3] = {nx, ny, nz}, hi3[3] = {-1, -1, -1};
        for (size_t o = b; o < e; ++o) {
            const Cell& c = C[o];
            const float wx[2] = {1.f - c.tx, c.tx}, wy[2] = {1.f - c.ty, c.ty}, wz[2] = {1.f - c.tz, c.tz};
            Eigen::Vector4f V = Eigen::Vector4f::Zero();  // (Σ w, V̄): lane 0 unused
            float r = 0.f, cornerMax = 0.f;
            unsigned above = 0;  // bit di + 2·dj + 4·dk: that node is above the target
            for (int dk = 0; dk < 2; ++dk)
                for (int dj = 0; dj < 2; ++dj) {
                    const Eigen::Vector4f* row = N + c.node + size_t(dk) * plane + size_t(dj) * sx;
                    for (int di = 0; di < 2; ++di) {
                        const Eigen::Vector4f& nd = row[di];
                        const float w = wx[di] * wy[dj] * wz[dk];
                        if (nd[0] > 0.f) V += (w / nd[0]) * nd;
                        const float ratio = nd[0] * toRatio;
                        r += w * ratio;
                        cornerMax = std::max(cornerMax, ratio);
                        above |= unsigned(ratio > 1.f) << (di + 2 * dj + 4 * dk);
                    }
                }
            const Vec3f v = massVel_[o].tail<3>();
            in.v[c.vertex] = v + s * (V.tail<3>() - v);
            ratio_[o] = r;
            localMax = std::max(localMax, cornerMax);
            if (above) {
                // Per axis: the low face holds an above-target node if any
                // node with offset 0 does, the high face if any with 1 does.
                constexpr unsigned low[3] = {0x55, 0x33, 0x0f};
                const int at[3] = {c.i, c.j, c.k};
                for (int a = 0; a < 3; ++a) {
                    lo3[a] = std::min(lo3[a], (above & low[a]) ? at[a] : at[a] + 1);
                    hi3[a] = std::max(hi3[a], (above & ~low[a] & 0xff) ? at[a] + 1 : at[a]);
                }
            }
        }
        for (int a = 0; a < 3; ++a) {
            lower(boxLo[a], lo3[a]);
            raise(boxHi[a], hi3[a]);
        }
        for (float m = maxR.load(); localMax > m && !maxR.compare_exchange_weak(m, localMax);) {
        }
    });
    st.maxDensity = maxR.load() * s_.targetDensity;

    // The volume step's excess, relaxed implicitly on the box of nodes
    // above the target grown by the sweeps' reach, kept in relaxed_ for the
    // gather. K sweeps from E⁰ = 0 reach K − 1 nodes beyond the excess (E¹
    // is nonzero only on it, each sweep one node further), so beyond that
    // margin E is 0, and a node at the margin reads 0 from outside it
    // either way: the same E as on the whole lattice.
    NodeBox eBox;  // empty: no excess anywhere
    int eLo[3] = {0, 0, 0};
    if (push > 0.f && boxHi[0].load() >= 0) {
        const int sweeps = kSweeps, reach = kSweeps - 1;
        int hi3[3];
        const int top[3] = {nx - 1, ny - 1, nz - 1};
        for (int a = 0; a < 3; ++a) {
            eLo[a] = std::max(0, boxLo[a].load() - reach);
            hi3[a] = std::min(top[a], boxHi[a].load() + reach);
        }
        eBox.nx = hi3[0] - eLo[0] + 1;
        eBox.ny = hi3[1] - eLo[1] + 1;
        eBox.nz = hi3[2] - eLo[2] + 1;
        // The box's nodes with hair and their excess, listed plane by plane.
        occupied_.reset(eBox);
        relaxed_.resize(eBox.size());
        run(size_t(eBox.nz), [&, N, toRatio](size_t b, size_t e) {
            for (size_t k = b; k < e; ++k)
                for (int j = 0; j < eBox.ny; ++j)
                    occupied_.addRow(j, int(k), N[index(eLo[0], eLo[1] + j, eLo[2] + int(k))].data(), 4, toRatio);
        });
        relaxListed(occupied_, cPush, sweeps, relaxed_.data(), run);
    }
    const float* const E = relaxed_.data();
    const int ebx = eBox.nx, eby = eBox.ny, ebz = eBox.nz, elx = eLo[0], ely = eLo[1], elz = eLo[2];
    // E at a node: relaxed_ inside the box (0 on nodes without hair), 0 outside.
    auto excessAt = [=](int i, int j, int k) {
        const unsigned bi = unsigned(i - elx), bj = unsigned(j - ely), bk = unsigned(k - elz);
        if (bi >= unsigned(ebx) || bj >= unsigned(eby) || bk >= unsigned(ebz)) return 0.f;
        return E[(size_t(bk) * size_t(eby) + size_t(bj)) * size_t(ebx) + size_t(bi)];
    };

    // The volume push (reads only the grid): down the gradient of the
    // relaxed excess, divided by the density the vertex reads.
    std::atomic<size_t> pushed{0};
    if (eBox.size() > 0) {
        const Eigen::Matrix3f R = in.head.linear();
        const size_t ex = size_t(ebx), exy = size_t(ebx) * size_t(eby);
        run(gridded, [&, C, push, invD, ex, exy](size_t b, size_t e) {
            size_t moved = 0;
            for (size_t o = b; o < e; ++o) {
                const Cell& c = C[o];
                const float wx[2] = {1.f - c.tx, c.tx}, wy[2] = {1.f - c.ty, c.ty}, wz[2] = {1.f - c.tz, c.tz};
                const float dw[2] = {-invD, invD};
                // The eight nodes' E: straight from the box when the cell
                // lies inside it (most do: the box reaches kSweeps − 1 beyond
                // the excess), else node by node (0 outside).
                float Ec[8];
                const unsigned bi = unsigned(c.i - elx), bj = unsigned(c.j - ely), bk = unsigned(c.k - elz);
                if (bi < unsigned(ebx - 1) && bj < unsigned(eby - 1) && bk < unsigned(ebz - 1)) {
                    const float* base = E + size_t(bk) * exy + size_t(bj) * ex + bi;
                    for (int q = 0; q < 8; ++q) Ec[q] = base[size_t(q >> 2) * exy + size_t((q >> 1) & 1) * ex + size_t(q & 1)];
                } else {
                    for (int q = 0; q < 8; ++q) Ec[q] = excessAt(c.i + (q & 1), c.j + ((q >> 1) & 1), c.k + (q >> 2));
                }
                Vec3f grad = Vec3f::Zero();
                for (int dk = 0; dk < 2; ++dk)
                    for (int dj = 0; dj < 2; ++dj)
                        for (int di = 0; di < 2; ++di)
                            grad += Ec[di + 2 * dj + 4 * dk] *
                                    Vec3f(dw[di] * wy[dj] * wz[dk], wx[di] * dw[dj] * wz[dk], wx[di] * wy[dj] * dw[dk]);
                if (grad.squaredNorm() > 0.f) {
                    in.x[c.vertex] -= (push / std::max(1.f, ratio_[o])) * (R * grad);
                    ++moved;
                }
            }
            pushed += moved;
        });
    }
    st.pushed = pushed;

    // Leave the array all zeros for the next call. A lattice of at most
    // kClearByFill nodes a vertex is cleared whole (a memset streams at
    // memory speed), a sparser one node by node where the splat wrote.
    if (nodes <= kClearByFill * gridded) {
        std::memset(static_cast<void*>(N), 0, nodes * sizeof(Eigen::Vector4f));
        return st;
    }
    bySlab([&, N, C, sx, plane](size_t first, size_t end) {
        for (size_t o = first; o < end; ++o)
            for (int dk = 0; dk < 2; ++dk)
                for (int dj = 0; dj < 2; ++dj) {
                    Eigen::Vector4f* row = N + C[o].node + size_t(dk) * plane + size_t(dj) * sx;
                    row[0] = row[1] = Eigen::Vector4f::Zero();
                }
    });
    return st;
}

}  // namespace hp::volume
