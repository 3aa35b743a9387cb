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

/// Grid nodes stored row by row (hair_grid.h's layout): node row
/// r = k·ny + j holds the nodes i in [lo[r], end[r]) at slot base[r] + i,
/// with one zero slot either side (base[r] + lo[r] − 1 and base[r] +
/// end[r]), so that a row's x neighbours are its slots' neighbours; a row
/// with lo ≥ end holds nothing and has no slots. Plane k's slots are
/// [planeStart[k], planeStart[k + 1]) (nz + 1 entries).
struct NodeRows {
    int nx = 0, ny = 0, nz = 0;
    const ptrdiff_t* base = nullptr;
    const int* lo = nullptr;
    const int* end = nullptr;
    const uint32_t* planeStart = nullptr;
};

/// The first sweep from E⁰ = 0 at a node of excess ex (NaN: a node
/// without hair, or a zero slot): E¹ = ex/(1 + 6c), 0 without hair.
inline float firstSweep(float ex, float inv) { return ex == ex ? ex * inv : 0.f; }

/// One Jacobi sweep on the stored rows of planes [k0, k1): out = (ex +
/// c·Σ_{6 neighbours} in)/(1 + 6c) on nodes with hair (ex not NaN), 0 on
/// nodes without and on the zero slots; a neighbour not stored counts 0.
/// The six neighbours are added in jacobiSweep's order (x, y, z; minus,
/// plus) to a sum starting at +0, in SSE lanes (each lane rounds as the
/// scalar operation does): the same bits as jacobiSweep on a box whose
/// nodes with hair are the stored ones with ex not NaN. Pure: writes out's
/// slots of those planes only.
void sweepRows(const NodeRows& rows, const float* ex, float c, const float* in, float* out, int k0, int k1);

/// E after `sweeps` Jacobi sweeps from E⁰ = 0 on stored rows whose excess
/// ex lies on planes [e0, e1) only (0 or NaN on every other plane). On entry
/// `a` holds the first sweep, firstSweep(ex, 1/(1 + 6c)), on every slot;
/// `b` is scratch of the same size. Sweep s reaches s − 1 planes beyond
/// the excess, so it runs on planes [e0 − s + 1, e1 + s − 1) only (beyond
/// them E^s is exactly 0), each sweep's planes through `parallel`. Returns
/// the buffer holding E (a or b), every slot valid.
const float* relaxRows(const NodeRows& rows, const float* ex, float c, int sweeps, int e0, int e1, float* a,
                       float* b, const ParallelFor& parallel);

/// relaxRows on the nodes with occupied[n] != 0 and excess e[n] of a
/// box (every row stored whole); `out` receives box.size() values. For
/// tests: the same values as jacobiSweep K times from E⁰ = 0.
void relaxExcess(const NodeBox& box, const float* e, const uint8_t* occupied, float c, int sweeps, float* out,
                 const ParallelFor& parallel);

}  // namespace hp::volume
