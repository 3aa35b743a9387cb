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
#include <array>
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

/// The occupied nodes the sweeps visit and their excess e, listed plane by
/// plane (plane k's at [first[k], first[k] + count[k])), each with the
/// indices of its six neighbours (x−, x+, y−, y+, z−, z+) in the value
/// arrays. A neighbour that does not exist (outside the grid) is the
/// `zero` slot, and one not listed holds 0 too: adding either to the sum
/// adds nothing, not even a sign (the sum starts at +0 and every E is ≥ 0),
/// so the values are those of skipping it. Reused call after call.
struct OccupiedNodes {
    std::vector<uint32_t> node;                      ///< value index of the listed node
    std::vector<std::array<uint32_t, 6>> neighbour;  ///< value indices of its neighbours
    std::vector<float> excess;                       ///< e there
    std::vector<uint32_t> first, count;              ///< per plane
    size_t values = 0;                               ///< entries of a value array, the zero slot included
    uint32_t zero = 0;                               ///< the slot that stays 0
    std::vector<float> scratch;                      ///< the sweeps' second buffer

    /// Sizes the lists: `planes` planes, plane k's room from start[k] to
    /// start[k + 1] (start has planes + 1 entries), counts 0; value arrays
    /// of `valueCount` entries with slot `zeroSlot` kept 0.
    void reset(size_t planes, const uint32_t* start, size_t valueCount, uint32_t zeroSlot);
    /// Lists a node of plane k (any plane from one thread at a time).
    void add(size_t k, uint32_t at, const std::array<uint32_t, 6>& around, float e) {
        const size_t t = first[k] + count[k]++;
        node[t] = at;
        neighbour[t] = around;
        excess[t] = e;
    }
};

/// E after `sweeps` Jacobi sweeps from E⁰ = 0 (the file comment) on the
/// listed nodes, 0 in every other slot; the planes of each sweep run
/// through `parallel`; `out` receives E (list.values entries). The same
/// values, term by term, as jacobiSweep over a whole box whose occupied
/// nodes are the listed ones.
void relaxListed(OccupiedNodes& list, float c, int sweeps, float* out, const ParallelFor& parallel);

/// relaxListed on the nodes with occupied[n] != 0 and excess e[n] of a
/// box (value slots: the box's nodes, then the zero slot); `out` receives
/// box.size() values.
void relaxExcess(const NodeBox& box, const float* e, const uint8_t* occupied, float c, int sweeps, float* out,
                 OccupiedNodes& scratch, const ParallelFor& parallel);

}  // namespace hp::volume
