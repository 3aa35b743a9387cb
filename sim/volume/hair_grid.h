// @brief Hair against hair through a grid: the guides' mass, velocity and
// hair length splatted onto a grid that follows the head, then friction
// and volume read back from it (issue 30).
//
// The method is the hybrid Eulerian/Lagrangian one of Petrovic, Henne and
// Anderson, "Volumetric Methods for Simulation and Rendering of Hair"
// (Pixar technical memo 06-08, 2005) and McAdams, Selle, Ward, Sifakis and
// Teran, "Detail Preserving Continuum Simulation of Straight Hair"
// (SIGGRAPH 2009): strands stay Lagrangian; the grid only couples them.
//
// Each solver substep, with vertices i of mass m_i, hair length ℓ_i (the
// vertex's share of its segments times the hairs its guide stands for),
// head-local position p_i and velocity v_i, and trilinear weights w_ic
// (Σ_c w_ic = 1) on nodes c of spacing Δ:
//
//   splat     M_c = Σ_i w_ic m_i,   P_c = Σ_i w_ic m_i v_i,
//             λ_c = Σ_i w_ic ℓ_i / Δ³          (hair length per volume, 1/m²:
//                                               hairs crossing a unit section)
//   grid      V_c = P_c / M_c,   r_c = λ_c / λ₀,   e_c = max(0, r_c − 1)
//   friction  v_i ← v_i + s·(V̄_i − v_i),  V̄_i = Σ_c w_ic V_c,  s = 1 − exp(−k·h)
//   volume    (I − c·L)·E = e,   x_i ← x_i − c·Δ²·∇Ē(x_i) / max(1, r̄_i),
//             c = c_max·(1 − exp(−h/τ))
//
// Friction (PIC blend) conserves momentum exactly: Σ_i m_i V̄_i =
// Σ_c V_c Σ_i w_ic m_i = Σ_c P_c = Σ_i m_i v_i. It never adds kinetic
// energy: V̄_i is a mass-weighted average of the velocities near i (Jensen:
// Σ m_i |V̄_i|² ≤ Σ m_i |v_i|²) and the blend is a convex combination.
// The volume step moves positions only, never velocities (like the head's
// projection), so it adds no kinetic energy; the strand solver's next step
// restores lengths and clearance. Dividing by r̄ makes it a step of linear
// diffusion of the excess density (∂λ/∂t = D∇²λ where λ > λ₀, D = c·Δ²/h),
// taken implicitly: E is the excess at the end of the step, relaxed on the
// grid by a few Jacobi sweeps (L the 7-point Laplacian in units of Δ⁻²;
// excess_diffusion.h), so the push is stable for any c. Read explicitly
// (E = e) it is stable only for c ≤ 1/6, and the default τ gives c ≈ 0.4:
// with the rod's BDF2, which keeps what implicit Euler's numerical damping
// removed, the grid-scale jitter grew (a ball of strands piled to 863
// hairs/cm², 2.3x without the grid). The rod keeps a position history
// (BDF2), and moves it with the push (GuideGroup::displaced), so that the
// push is not read as motion and extrapolated. One push a substep is not a
// constraint: a pile under gravity settles where c·Δ·(r − 1)/r, the push a
// substep, matches the fall g·h² a substep, above the target.
//
// Determinism: the splat is a sum, so its order is fixed. Vertices are
// sorted by the node row (j, k) of their base node (a stable counting
// sort, in vertex order within a row); a row of slab k lies in slab k, and
// a vertex of slab k writes node planes k and k+1 only, so even slabs run
// in parallel, then odd ones. Every node therefore receives its terms in
// the same order whatever the thread count; the gathers read only. The
// grid's lattice is fixed to the head (origin a multiple of Δ in head
// coordinates), so it follows the head and a still head sees the same
// cells every step.
//
// Cost: every pass walks the sorted order, with each vertex's cell and
// (m, v) written into it by the sort, so the nodes a pass touches stay in
// the cache and its own data streams; the sort counts and scatters in
// chunks on the threads (a stable sort's result is unique). A node holds
// (M, P) only (λ_c = M_c·ℓ/m/Δ³: every vertex carries the same hair length
// per mass), and only the nodes the vertices reach are stored, row by row
// over each row's x span with a zero slot either side. After the splat one
// pass over the stored nodes finds the densest node, the excess and the
// first Jacobi sweep; the later sweeps run over the stored rows of the
// planes the excess reaches, four nodes at a time (excess_diffusion.h);
// and one pass over the vertices reads each vertex's eight nodes once for
// friction, the density it reads and the push (SSE lanes doing the scalar
// operations in the scalar order: the same bits).
// Measured in docs/benchmarks.md ("B-sim with the hair-hair grid").
#pragma once

#include "sim/volume/excess_diffusion.h"
#include "sim/volume/volume_settings.h"

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace hp::volume {

using Vec3f = Eigen::Vector3f;

// ParallelFor (f(begin, end) over [0, count) in the caller's arena): excess_diffusion.h.

/// The vertices the grid couples (structure of arrays, `count` entries each).
struct GridInput {
    Vec3f* x = nullptr;             ///< world positions, moved by the volume push
    Vec3f* v = nullptr;             ///< world velocities, blended by friction
    const float* mass = nullptr;    ///< kg; 0: kinematic (a root), neither splatted nor moved
    size_t count = 0;
    float lengthPerMass = 0.f;      ///< hair length a kilogram of guide stands for, m/kg
    Eigen::Isometry3f head = Eigen::Isometry3f::Identity();  ///< the frame the grid follows
    float h = 0.f;                  ///< substep, s
    /// If set, receives x as it was before the volume push (`count`
    /// entries), copied in a pass that reads x anyway.
    Vec3f* before = nullptr;
};

/// What one apply() did (diagnostics and tests).
struct GridStats {
    float cellSize = 0.f;           ///< Δ used, m (coarser than the setting when the hair spreads too far)
    size_t nodes = 0;               ///< nodes of the box round the hair
    size_t storedNodes = 0;         ///< of those, the nodes stored: those the vertices reach (hair_grid.cpp)
    float maxDensity = 0.f;         ///< largest density of a node a vertex reads, hairs per cm²
    size_t pushed = 0;              ///< vertices the volume step moved
};

/// The grid and its scratch, reused step after step.
class HairGrid {
  public:
    explicit HairGrid(const VolumeSettings& s);

    /// One coupling pass: splat, friction, volume (see the file comment).
    /// Results are the same bits for any thread count `parallel` uses.
    GridStats apply(const GridInput& in, const ParallelFor& parallel);

    /// Friction's blend fraction s and the volume step's c for a substep h.
    float blendFraction(float h) const;
    float pushFraction(float h) const;

  private:
    /// A gridded vertex in the passes' order: trilinear fractions t, the x
    /// index i of its base node (i, j, k) (its row (j, k) is where it is
    /// sorted), (m, v); 32 bytes.
    struct Entry {
        alignas(16) float t[3];
        int32_t i;
        Eigen::Vector4f mv;
    };
    VolumeSettings s_;
    std::vector<uint32_t> rowOf_;    ///< node row (j, k) of each vertex's base node; ~0: not gridded
    std::vector<uint32_t> rowStart_;  ///< first sorted vertex of each node row
    std::vector<uint32_t> rowCount_;  ///< the sort's counts, then places, per chunk and row
    /// Gridded vertices sorted by node row (hair_grid.cpp): their entries,
    /// written in that order so that every pass reads them in a stream, and
    /// their indices into GridInput.
    std::vector<Entry> entries_;
    std::vector<uint32_t> order_;
    std::vector<int> spanLo_, spanHi_;  ///< per base row: the least and largest i of its vertices
    std::vector<int> chunkLo_, chunkHi_;  ///< the same per chunk of the sort and row (set where it counts)
    std::vector<ptrdiff_t> rowBase_;   ///< per node row: node (i, j, k) is nodes_[rowBase_[row] + i]
    std::vector<int> rowLo_, rowEnd_;  ///< per node row: the stored i span [lo, end), a zero slot either side
    std::vector<uint32_t> planeStart_; ///< first stored node of each plane (and the count at the end)
    /// The volume step's excess (NaN where no hair) and its two sweep
    /// buffers, per stored node slot (excess_diffusion.h's NodeRows).
    std::vector<float> excess_, sweepA_, sweepB_;
    /// Per node (m, P): mass and momentum, one SSE packet, so the splat
    /// adds w·(m, m·v) in one operation. The hair
    /// length is M·lengthPerMass (the same for every vertex), not stored:
    /// the passes wait on the lattice's memory, not on arithmetic. Cleared
    /// by each call before its splat.
    std::vector<Eigen::Vector4f> nodes_;
};

}  // namespace hp::volume
