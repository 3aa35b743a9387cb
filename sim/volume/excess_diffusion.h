// @brief The hair-hair grid's volume step as implicit diffusion of the
// density excess: stable for any step (sim/volume/hair_grid.h uses it).
//
// The volume step moves hair down the gradient of its excess density
// e = max(0, λ/λ₀ − 1): a step of linear diffusion ∂e/∂t = D·∇²e with
// c = D·h/Δ² on a grid of spacing Δ. Taken explicitly (the push reads the
// excess as it is) it is stable only for c ≤ 1/6 on the 7-point stencil:
// the grid-scale mode, Laplacian eigenvalue −12/Δ², changes by −12c of
// itself a step and overshoots (grows with alternating sign) beyond that.
// Taken implicitly (backward Euler: Bridson, "Fluid Simulation for
// Computer Graphics", 2008, ch. 10 on implicit viscosity and diffusion;
// the volume step itself after Petrovic, Henne and Anderson 2005 and
// McAdams et al. 2009) the push reads the excess at the end of the step,
//
//   (I − c·L)·E = e,   L the 7-point Laplacian in units of Δ⁻²,
//   x_i ← x_i − c·Δ²·∇E(x_i) / max(1, r̄_i),
//
// and every Fourier mode of eigenvalue μ ∈ [−12, 0] is scaled by
// 1/(1 − c·μ) ∈ (0, 1]: no overshoot for any c. E lives on the occupied
// nodes (those that hold hair); nodes without hair hold E = 0 (Dirichlet:
// there is no excess to spread where there is no hair).
//
// The system is solved by K Jacobi sweeps from E⁰ = 0:
//
//   E^{k+1}_n = (e_n + c·Σ_{m ∈ N(n)} E^k_m) / (1 + 6c)      (n occupied)
//
// i.e. the first K terms of the Neumann series of (I − c·L)⁻¹. Per mode,
// E^K = e/(1 + 6c)·Σ_{j<K} ρ^j with ρ = c·(μ + 6)/(1 + 6c) ∈ (−1, 1): for
// ρ ≥ 0 the partial sums rise monotonically to the exact E; for ρ < 0
// (the grid-scale modes) they stay between e·(1 + ρ)/(1 + 6c) and
// e/(1 + 6c), so the push's change of such a mode, −c·μ·E^K ≤
// 12c/(1 + 6c)·e < 2e, never grows it, whatever c and K. Smooth modes
// (ρ → 6c/(1 + 6c)) take K sweeps to approach the exact solve: the push is
// then (1 − ρ^K) of the exact one. Each sweep reads only the previous
// sweep's values, so the result does not depend on the order or the
// thread count.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace hp::volume {

/// Runs f(begin, end) over [0, count) in parallel chunks (the caller's arena).
using ParallelFor = std::function<void(size_t count, const std::function<void(size_t, size_t)>& f)>;

/// A box of nx × ny × nz grid nodes, x fastest (node (i, j, k) at
/// (k·ny + j)·nx + i).
struct NodeBox {
    int nx = 0, ny = 0, nz = 0;
    size_t size() const { return size_t(nx) * size_t(ny) * size_t(nz); }
};

/// One Jacobi sweep of (I − c·L)·E = e on the node planes [k0, k1) of the
/// box: out_n = (e_n + c·Σ_{6 neighbours m} in_m)/(1 + 6c) on occupied
/// nodes (occupied[n] != 0), 0 elsewhere. Neighbours outside the box count
/// as 0. Pure: reads e, occupied, in; writes out on those planes only.
void jacobiSweep(const NodeBox& box, const float* e, const uint8_t* occupied, float c, const float* in, float* out,
                 int k0, int k1);

/// The occupied nodes of a box and their excess e, listed plane by plane
/// (plane k's at [k·plane, k·plane + count[k]), ascending): what the sweeps
/// visit. Reused call after call.
struct OccupiedNodes {
    NodeBox box;
    std::vector<uint32_t> node;     ///< box index
    std::vector<uint8_t> inside;    ///< its neighbours in the box (bits −x, +x, −y, +y, −z, +z)
    std::vector<float> excess;      ///< e there
    std::vector<uint32_t> count;    ///< per plane
    std::vector<float> values;      ///< the sweeps' second buffer

    /// Sizes the lists for `b` (counts 0).
    void reset(const NodeBox& b);
    /// Lists node (i, j, k) of the box, excess e; within a plane in
    /// ascending order, any plane from one thread at a time.
    void add(int i, int j, int k, float e) {
        const size_t plane = size_t(box.nx) * size_t(box.ny);
        const size_t t = size_t(k) * plane + count[size_t(k)]++;
        node[t] = uint32_t(size_t(k) * plane + size_t(j) * size_t(box.nx) + size_t(i));
        inside[t] = uint8_t(unsigned(i > 0) | unsigned(i + 1 < box.nx) << 1 | unsigned(j > 0) << 2 |
                            unsigned(j + 1 < box.ny) << 3 | unsigned(k > 0) << 4 | unsigned(k + 1 < box.nz) << 5);
        excess[t] = e;
    }
    /// Lists the nodes with m > 0 of row (j, k) of the box, excess
    /// max(0, m·toRatio − 1), from x-row `m` (box.nx values, stride
    /// `stride` floats); rows of a plane in ascending order, any plane from
    /// one thread at a time.
    void addRow(int j, int k, const float* m, size_t stride, float toRatio) {
        const size_t plane = size_t(box.nx) * size_t(box.ny), first = size_t(k) * plane;
        size_t t = first + count[size_t(k)];
        uint32_t* nd = node.data();
        uint8_t* in = inside.data();
        float* ex = excess.data();
        const unsigned jk = unsigned(j > 0) << 2 | unsigned(j + 1 < box.ny) << 3 | unsigned(k > 0) << 4 |
                            unsigned(k + 1 < box.nz) << 5;
        const uint32_t row = uint32_t(first + size_t(j) * size_t(box.nx));
        for (int i = 0; i < box.nx; ++i) {
            const float mi = m[size_t(i) * stride];
            if (!(mi > 0.f)) continue;
            nd[t] = row + uint32_t(i);
            in[t] = uint8_t(jk | unsigned(i > 0) | unsigned(i + 1 < box.nx) << 1);
            ex[t++] = std::max(0.f, mi * toRatio - 1.f);
        }
        count[size_t(k)] = uint32_t(t - first);
    }
};

/// E after `sweeps` Jacobi sweeps from E⁰ = 0 (the file comment) on the
/// listed nodes, 0 on the others; the planes of each sweep run through
/// `parallel`; `out` receives E (box.size() values). The same values, term
/// by term, as jacobiSweep over the whole box with the nodes listed as the
/// occupied ones.
void relaxListed(OccupiedNodes& list, float c, int sweeps, float* out, const ParallelFor& parallel);

/// relaxListed on the nodes with occupied[n] != 0 and excess e[n].
void relaxExcess(const NodeBox& box, const float* e, const uint8_t* occupied, float c, int sweeps, float* out,
                 OccupiedNodes& scratch, const ParallelFor& parallel);

}  // namespace hp::volume
