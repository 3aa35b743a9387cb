// The hair-hair grid (equations and determinism: sim/volume/hair_grid.h).
#include "sim/volume/hair_grid.h"

#include "core/errors.h"
#include "sim/volume/excess_diffusion.h"

#include <algorithm>
#include <atomic>
#include <cmath>

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

/// At most this many nodes (20 bytes each): hair spread wider than the
/// grid allows at Δ is gridded at 2Δ, 4Δ, ... for that step instead.
constexpr double kMaxNodes = 4.0e6;
/// The volume step's largest fraction per substep (hair_grid.h), so that
/// one push a substep can hold hair up against gravity's g·h² a substep.
/// The push is implicit (excess_diffusion.h), so any c is stable; what
/// bounds it is the energy the push gives hair it lifts. Measured on
/// tests/test_hair_grid.cpp with the rod's BDF2 (4 sweeps): c_max 1/2 leaves
/// the ball at 338 hairs/cm² (1.5x the target) and the crossing wisps gain
/// 1.5% of the energy their fall releases; c_max 1 (8 sweeps) gains 99% of it.
constexpr float kMaxPush = 0.5f;
/// Jacobi sweeps of the implicit volume step (excess_diffusion.h): a smooth
/// excess gets (1 − ρ^K) of the exact implicit push, ρ = 6c/(1 + 6c) = 0.72
/// at the default c = 0.43, so 0.73 at 4 sweeps. Measured on the ball and
/// the crossing wisps (BDF2): 1 sweep 338 hairs/cm², 0.5% energy gain;
/// 4 sweeps 338, 1.5%; 8 sweeps 300, 1.6%.
constexpr int kSweeps = 4;

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
    local_.resize(n);
    const Eigen::Isometry3f toLocal = in.head.inverse();
    auto valid = [&](size_t i) { return in.mass[i] > 0.f && local_[i].allFinite(); };
    run(n, [&](size_t b, size_t e) {
        for (size_t i = b; i < e; ++i) local_[i] = toLocal * in.x[i];
    });

    // Bounds (min and max do not depend on order).
    Vec3f lo = Vec3f::Constant(INFINITY), hi = Vec3f::Constant(-INFINITY);
    for (size_t i = 0; i < n; ++i)
        if (valid(i)) {
            lo = lo.cwiseMin(local_[i]);
            hi = hi.cwiseMax(local_[i]);
        }
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
    auto cellOf = [&](size_t i) {
        const Vec3f f = (local_[i] - origin) * invD;
        Cell c;
        c.i = std::clamp(int(std::floor(f.x())), 0, nx - 2);
        c.j = std::clamp(int(std::floor(f.y())), 0, ny - 2);
        c.k = std::clamp(int(std::floor(f.z())), 0, nz - 2);
        c.tx = std::clamp(f.x() - float(c.i), 0.f, 1.f);
        c.ty = std::clamp(f.y() - float(c.j), 0.f, 1.f);
        c.tz = std::clamp(f.z() - float(c.k), 0.f, 1.f);
        return c;
    };
    auto index = [&](int i, int j, int k) { return (size_t(k) * size_t(ny) + size_t(j)) * size_t(nx) + size_t(i); };

    // The node array is all zeros between calls (apply() clears the nodes it
    // touched before returning), so only growth costs a fill.
    if (nodes_.size() < nodes) nodes_.resize(nodes, Node{0, 0, 0, 0, 0, 0});

    // Each vertex's cell once; then vertices by z slab, in vertex order
    // within a slab (a stable counting sort).
    cells_.resize(n);
    run(n, [&](size_t b, size_t e) {
        for (size_t i = b; i < e; ++i) cells_[i] = valid(i) ? cellOf(i) : Cell{-1, 0, 0, 0.f, 0.f, 0.f};
    });
    slabStart_.assign(size_t(nz) + 1, 0u);
    for (size_t i = 0; i < n; ++i)
        if (cells_[i].i >= 0) ++slabStart_[size_t(cells_[i].k) + 1];
    for (int k = 0; k < nz; ++k) slabStart_[size_t(k) + 1] += slabStart_[size_t(k)];
    order_.resize(slabStart_[size_t(nz)]);
    fill_.assign(slabStart_.begin(), slabStart_.end() - 1);
    for (size_t i = 0; i < n; ++i)
        if (cells_[i].i >= 0) order_[fill_[size_t(cells_[i].k)]++] = unsigned(i);

    // Even slabs, then odd slabs: each writes node planes k and k+1 only.
    auto bySlab = [&](auto&& vertexBody) {
        for (int parity = 0; parity < 2; ++parity) {
            const size_t slabs = size_t(std::max(0, (nz - parity) / 2));
            run(slabs, [&](size_t b, size_t e) {
                for (size_t sl = b; sl < e; ++sl) {
                    const size_t k = 2 * sl + size_t(parity);
                    for (unsigned o = slabStart_[k]; o < slabStart_[k + 1]; ++o) vertexBody(size_t(order_[o]));
                }
            });
        }
    };

    // Splat.
    const float lengthPerMass = in.lengthPerMass;
    bySlab([&](size_t i) {
        const Cell& c = cells_[i];
        const float m = in.mass[i], l = m * lengthPerMass;
        const Vec3f p = m * in.v[i];
        const float wx[2] = {1.f - c.tx, c.tx}, wy[2] = {1.f - c.ty, c.ty}, wz[2] = {1.f - c.tz, c.tz};
        for (int dk = 0; dk < 2; ++dk)
            for (int dj = 0; dj < 2; ++dj) {
                Node* row = &nodes_[index(c.i, c.j + dj, c.k + dk)];
                const float wyz = wy[dj] * wz[dk];
                for (int di = 0; di < 2; ++di) {
                    const float w = wx[di] * wyz;
                    Node& nd = row[di];
                    nd.m += w * m;
                    nd.l += w * l;
                    nd.px += w * p.x();
                    nd.py += w * p.y();
                    nd.pz += w * p.z();
                }
            }
    });

    // Node velocity V = P/M and density ratio r = λ/λ₀ are read on the fly.
    const float toRatio = 1.f / (d * d * d * s_.targetDensity * 1e4f);  // hairs per cm² -> per m²
    const float s = blendFraction(in.h), cPush = pushFraction(in.h), push = cPush * d * d;

    // The densest node a vertex reads, and the box of nodes above the
    // target (minima and maxima: the same whatever the order).
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
    run(n, [&](size_t b, size_t e) {
        float localMax = 0.f;
        int lo3[3] = {nx, ny, nz}, hi3[3] = {-1, -1, -1};
        for (size_t i = b; i < e; ++i) {
            const Cell& c = cells_[i];
            if (c.i < 0) continue;
            for (int dk = 0; dk < 2; ++dk)
                for (int dj = 0; dj < 2; ++dj)
                    for (int di = 0; di < 2; ++di) {
                        const float ratio = nodes_[index(c.i + di, c.j + dj, c.k + dk)].l * toRatio;
                        localMax = std::max(localMax, ratio);
                        if (ratio <= 1.f) continue;
                        const int at[3] = {c.i + di, c.j + dj, c.k + dk};
                        for (int a = 0; a < 3; ++a) {
                            lo3[a] = std::min(lo3[a], at[a]);
                            hi3[a] = std::max(hi3[a], at[a]);
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
    // above the target grown by the sweeps' reach (excess_diffusion.h:
    // beyond it E stays 0), written to the nodes' e.
    if (push > 0.f && boxHi[0].load() >= 0) {
        const int sweeps = kSweeps;
        int lo3[3], hi3[3];
        const int top[3] = {nx - 1, ny - 1, nz - 1};
        for (int a = 0; a < 3; ++a) {
            lo3[a] = std::max(0, boxLo[a].load() - sweeps);
            hi3[a] = std::min(top[a], boxHi[a].load() + sweeps);
        }
        NodeBox box;
        box.nx = hi3[0] - lo3[0] + 1;
        box.ny = hi3[1] - lo3[1] + 1;
        box.nz = hi3[2] - lo3[2] + 1;
        excess_.resize(box.size());
        relaxed_.resize(box.size());
        occupied_.resize(box.size());
        auto forBox = [&](auto&& body) {  // body(box index, node index), plane by plane
            run(size_t(box.nz), [&](size_t b, size_t e) {
                for (size_t k = b; k < e; ++k)
                    for (int j = 0; j < box.ny; ++j) {
                        size_t q = (k * size_t(box.ny) + size_t(j)) * size_t(box.nx);
                        const size_t row = index(lo3[0], lo3[1] + j, lo3[2] + int(k));
                        for (int i = 0; i < box.nx; ++i, ++q) body(q, row + size_t(i));
                    }
            });
        };
        forBox([&](size_t q, size_t node) {
            const Node& nd = nodes_[node];
            occupied_[q] = nd.m > 0.f;
            excess_[q] = std::max(0.f, nd.l * toRatio - 1.f);
        });
        relaxExcess(box, excess_.data(), occupied_.data(), cPush, sweeps, relaxed_.data(), sweepScratch_, run);
        forBox([&](size_t q, size_t node) {
            if (occupied_[q]) nodes_[node].e = relaxed_[q];
        });
    }

    // Gather: friction, then the volume push (reads only the grid).
    const Eigen::Matrix3f R = in.head.linear();
    std::atomic<size_t> pushed{0};
    run(n, [&](size_t b, size_t e) {
        size_t moved = 0;
        for (size_t i = b; i < e; ++i) {
            const Cell& c = cells_[i];
            if (c.i < 0) continue;
            const float wx[2] = {1.f - c.tx, c.tx}, wy[2] = {1.f - c.ty, c.ty}, wz[2] = {1.f - c.tz, c.tz};
            const float dw[2] = {-invD, invD};
            Vec3f V = Vec3f::Zero(), grad = Vec3f::Zero();
            float r = 0.f;
            for (int dk = 0; dk < 2; ++dk)
                for (int dj = 0; dj < 2; ++dj) {
                    const Node* row = &nodes_[index(c.i, c.j + dj, c.k + dk)];
                    for (int di = 0; di < 2; ++di) {
                        const Node& nd = row[di];
                        const float w = wx[di] * wy[dj] * wz[dk];
                        if (nd.m > 0.f) V += (w / nd.m) * Vec3f(nd.px, nd.py, nd.pz);
                        r += w * (nd.l * toRatio);
                        grad += nd.e * Vec3f(dw[di] * wy[dj] * wz[dk], wx[di] * dw[dj] * wz[dk], wx[di] * wy[dj] * dw[dk]);
                    }
                }
            in.v[i] += s * (V - in.v[i]);
            if (push > 0.f && grad.squaredNorm() > 0.f) {
                in.x[i] -= (push / std::max(1.f, r)) * (R * grad);  // down the gradient of the relaxed excess
                ++moved;
            }
        }
        pushed += moved;
    });
    st.pushed = pushed;

    // Leave the array all zeros for the next call: clear what the splat touched.
    bySlab([&](size_t i) {
        const Cell& c = cells_[i];
        for (int dk = 0; dk < 2; ++dk)
            for (int dj = 0; dj < 2; ++dj) {
                Node* row = &nodes_[index(c.i, c.j + dj, c.k + dk)];
                row[0] = row[1] = Node{0, 0, 0, 0, 0, 0};
            }
    });
    return st;
}

}  // namespace hp::volume
