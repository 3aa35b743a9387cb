// @brief Wisps against wisps: a short-range, position-level separation
// between vertices of different guides, neighbours found through a hashed
// grid (issue 30: crossing wisps must not pass through each other).
//
// The grid of hair_grid.h couples hair through smoothed fields; it damps
// relative motion but cannot stop a wisp that moves centimetres a substep
// through a sheet one or two cells thick. This step treats each guide
// vertex as the centre of its wisp, a bundle of N hairs of radius
//
//   r = sqrt(N / (π·λ₀))     (λ₀ the target density, hairs per m²),
//
// and keeps vertices of different guides at least d = 2r·scale apart, as a
// constraint solved after the strand solver's substep (position-based
// dynamics: Müller, Heidelberger, Hennix and Ratcliff, "Position Based
// Dynamics", 2007; the Jacobi form and the hashed neighbour grid of Macklin
// and Müller, "Position Based Fluids", 2013). For a pair i, j of inverse
// masses w_i, w_j (0: a root, kinematic):
//
//   C_ij = n·(x_i − x_j) − d_ij ≥ 0,
//   Δx_i = +ω·w_i/(w_i + w_j)·max(0, −C_ij)·n,   Δx_j = −ω·w_j/(w_i + w_j)·max(0, −C_ij)·n
//
// so m_i·Δx_i + m_j·Δx_j = 0: every pair keeps momentum by construction.
// n is the pair's current direction, or its direction at the substep's
// start when the pair has crossed since (n·(x⁰_i − x⁰_j) < 0): a vertex
// that tunnelled within one substep goes back to the side it came from.
// Pairs already closer than d at the substep's start (hair groomed into
// one sheet) are not thrown apart: their bound is
//
//   d_ij = min(d, δ⁰_ij),   δ⁰_ij = |x⁰_i − x⁰_j|:
//
// they may not come closer (spreading them, a fraction a substep, turned
// into velocity, added up to 3.7 times the crossing wisps' released energy;
// the grid's density push spreads hair). The solver turns the moves into
// velocity (Δv = Δx/h), then restores lengths.
//
// Neighbours: the pairs closer than d·1.1 are listed once a substep from a
// hashed grid (vertices sorted by cell with a stable counting sort), and
// listed again only if the sweeps have moved two vertices together by more
// than the 0.1·d margin. Off by default (scene key
// simulation.volume.contact_scale, 0; 1.5 holds the crossing wisps):
// docs/physics.md has what was measured, and why it is off.
//
// Determinism: each Jacobi sweep gathers every vertex's move from its
// neighbour list (read only; a list's order is the fixed scan order of the
// 27 cells around, whatever the thread that built it), then applies all
// moves: the same bits on any thread count.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace hp::volume {

using ParallelFor = std::function<void(size_t count, const std::function<void(size_t, size_t)>& f)>;

/// What the separation acts on (structure of arrays, `count` entries each).
struct ContactInput {
    Eigen::Vector3f* x = nullptr;         ///< positions after the substep, moved
    const Eigen::Vector3f* x0 = nullptr;  ///< positions at the substep's start
    const float* mass = nullptr;          ///< kg; 0: kinematic (a root), never moved
    size_t count = 0;
    size_t verticesPerGuide = 1;          ///< vertex k belongs to guide k / verticesPerGuide
    float distance = 0.f;                 ///< d, m
    float friction = 0.f;                 ///< μ, Coulomb friction between the pair
    int iterations = 4;                   ///< Jacobi sweeps
};

/// Wisp radius of N hairs packed at λ₀ hairs per cm²: sqrt(N/(π·λ₀)), m.
float wispRadius(float hairsPerGuide, float targetDensityPerCm2);

class WispContact {
  public:
    /// Separates the vertices; returns the pairs closer than their bound in
    /// the first sweep.
    size_t apply(const ContactInput& in, const ParallelFor& parallel);

  private:
    std::vector<Eigen::Vector3i> cell_;
    struct Sorted {
        Eigen::Vector3f x;
        uint32_t guide;
    };
    std::vector<uint32_t> bucketStart_, order_, fill_, key_, nbrStart_, nbr_, inline_;
    std::vector<Sorted> sorted_;  ///< positions and guides in bucket order
    std::vector<Eigen::Vector3f> move_;
};

}  // namespace hp::volume
