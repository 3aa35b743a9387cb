// The hair-hair grid (equations and determinism: sim/volume/hair_grid.h).
#include "sim/volume/hair_grid.h"

#include "core/errors.h"

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
/// The volume step's largest fraction per substep (hair_grid.h): three
/// times explicit diffusion's bound of 1/6, so that one push a substep can
/// hold hair up against gravity's g·h² a substep. On the ball-drop test
/// (tests/test_hair_grid.cpp) 1/2 leaves the pile at 1.5x the target; 1
/// overshoots (1.85x) and lifts hair (the crossing wisps' energy rises).
constexpr float kMaxPush = 0.5f;

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
    if (nodes_.size() < nodes) nodes_.resize(nodes, Node{0, 0, 0, 0, 0});

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
    std::atomic<float> maxR{0.f};  // a maximum: the same whatever the order

    // Gather: friction, then the volume push (reads only the grid).
    const float s = blendFraction(in.h), push = pushFraction(in.h) * d * d;
    const Eigen::Matrix3f R = in.head.linear();
    std::atomic<size_t> pushed{0};
    run(n, [&](size_t b, size_t e) {
        size_t moved = 0;
        float localMax = 0.f;
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
                        const float ratio = nd.l * toRatio;
                        r += w * ratio;
                        localMax = std::max(localMax, ratio);
                        const float excess = std::max(0.f, ratio - 1.f);
                        grad += excess * Vec3f(dw[di] * wy[dj] * wz[dk], wx[di] * dw[dj] * wz[dk], wx[di] * wy[dj] * dw[dk]);
                    }
                }
            in.v[i] += s * (V - in.v[i]);
            if (push > 0.f && grad.squaredNorm() > 0.f) {
                in.x[i] -= (push / std::max(1.f, r)) * (R * grad);  // down the density gradient
                ++moved;
            }
        }
        pushed += moved;
        for (float m = maxR.load(); localMax > m && !maxR.compare_exchange_weak(m, localMax);) {
        }
    });
    st.pushed = pushed;
    st.maxDensity = maxR.load() * s_.targetDensity;

    // Leave the array all zeros for the next call: clear what the splat touched.
    bySlab([&](size_t i) {
        const Cell& c = cells_[i];
        for (int dk = 0; dk < 2; ++dk)
            for (int dj = 0; dj < 2; ++dj) {
                Node* row = &nodes_[index(c.i, c.j + dj, c.k + dk)];
                row[0] = row[1] = Node{0, 0, 0, 0, 0};
            }
    });
    return st;
}

}  // namespace hp::volume
