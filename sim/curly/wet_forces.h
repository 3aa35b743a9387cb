// Wet-hair effects of Kim, "Representation of Curl Exaggeration, Cohesion,
// Adhesion and Stiffness in Wet Curly Hair" (2023; Kim 2023 below): pure
// kernels with Kim 2023's equations, driven by a per-particle saturation
// σ ∈ [0, 1]. Every effect vanishes exactly at σ = 0, so dry hair is the
// plain curly model of sim/curly/curly_kernels.h.
//
// Where Kim 2023's printed equations are ambiguous, the reading taken here is
// stated at the kernel.
#pragma once

#include "sim/curly/curly_kernels.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace hp::curly {

/// Saturation of a particle at relative position s ∈ [0, 1] (root to tip):
/// the scene's value times a linear root-to-tip profile, clamped to [0, 1]:
///   σ(s) = clamp(σ_scene · ((1 - s)·root + s·tip), 0, 1).
float saturationAt(float scene, float root, float tip, float s);

// ---- Curl exaggeration (Kim 2023 §2, eq. 6-9) ------------------------------------

/// The rotation taking unit vector `from` onto unit vector `to` (Kim 2023 eq. 7-8,
/// Rodrigues): with γ = from × to and c = from·to,
///   M = I + Ψ + Ψ²(1 - c)/|γ|²,   Ψ = [γ]× (the cross-product matrix).
/// (Kim 2023 prints γ = p × h and "2Ψ"; that maps the strand onto the helix.
/// Its eq. 9 applies M to helix edges, so the rotation needed is the one from
/// the helix onto the strand, and the quadratic term is Ψ².) For `from` ≈ -`to`
/// it returns the half turn about an axis perpendicular to `from`.
Mat3f alignRotation(const Vec3f& from, const Vec3f& to);

/// Curl forces of eq. (9), one per edge: f_w,i = M (h_{i+1} - h_i) w_h w_s,i.
/// `helix` holds the n helix points of eq. (6) in root-local coordinates
/// (same particle count as the strand), `root` the root frame R. M is
/// alignRotation(R ĥ, p̂)·R with ĥ, p̂ the unit root-to-tip vectors of the
/// helix and of the strand: Kim 2023's rotation onto the strand's direction,
/// after the root frame has fixed the curl's phase about it (Kim 2023 leaves
/// the phase to the minimal rotation, which makes it jump when the head turns
/// about the strand). w_s,i = (σ_i + σ_{i+1})/2.
/// The force acts on the edge's child (+f) and parent (-f); on an inextensible
/// edge it turns the edge toward the rotated helix edge, so the wet strand is
/// drawn toward the helix. `force` receives n - 1 vectors.
void curlForces(const Vec3f* p, size_t n, const Vec3f* helix, const Mat3f& root, const float* sigma,
                float weight, Vec3f* force);

// ---- Cohesion (Kim 2023 §3, eq. 10) ----------------------------------------------

/// Neighbour search for the cohesion pass: a uniform grid over the points'
/// bounding box (the dense form of a spatial hash: a cell's key is its linear
/// index), filled by counting sort each step, so the order of its entries is
/// fixed by the points: deterministic. Entries carry a copy of their point
/// and group and cells are stored x-fastest, so a query reads 9 contiguous
/// runs (the 3×3 rows of its 27 cells) instead of chasing 27 hash buckets,
/// which at ~1 point per cell is what the search's time goes to.
class SpatialGrid {
  public:
    /// Indexes `count` points (with a group id each, e.g. their strand) for
    /// queries of radius `radius`. Cells are `radius` wide, wider where the
    /// bounding box would need more than ~4 cells per point (memory stays
    /// linear in the points).
    void build(const Vec3f* points, const uint32_t* groups, size_t count, float radius);
    size_t size() const { return entries_.size(); }
    /// The k-th point in grid order (cell by cell). Queries made in this
    /// order read neighbouring cells one after the other (cache-friendly).
    uint32_t ordered(size_t k) const { return entries_[k].index; }
    const Vec3f& orderedPoint(size_t k) const { return entries_[k].point; }
    uint32_t orderedGroup(size_t k) const { return entries_[k].group; }
    /// Calls f(j, p_j, group_j) for every point j within `radius` of x (and
    /// some farther ones: callers test the distance), each once, in a fixed
    /// order (the 27 cells around x, then the point order).
    template <typename F>
    void forEachNear(const Vec3f& x, F&& f) const;

  private:
    struct Entry {
        Vec3f point;
        uint32_t index;
        uint32_t group;
    };
    Vec3f origin_ = Vec3f::Zero();
    float inv_ = 1.f;
    int64_t nx_ = 0, ny_ = 0, nz_ = 0;
    std::vector<uint32_t> start_;  // cells + 1, x fastest
    std::vector<Entry> entries_;   // by cell, then point index
};

/// Cohesion of eq. (10) for one particle: the saturation-weighted,
/// kernel-averaged position of its neighbours on other strands,
///   p̄_i = Σ_j (p_j σ_j + p_i (1 - σ_j)) V_j W_ij / Σ_j V_j W_ij,
/// with W the poly6 kernel of radius r and V_j = m_j/ρ_j (equal for all
/// hair particles, so it cancels: Shepard normalisation of Kim 2023's sum).
/// The particle itself is part of the normalisation (j = i, as in SPH sums)
/// so that one far neighbour pulls weakly and the pull fades in smoothly.
/// The result is Kim 2023's second, cohesive position p^w_i, as an offset
/// from p_i with the tightness λ:
///   o_i = p^w_i - p_i = λ Σ_j σ_j (p_j - p_i) W_ij / (W_0 + Σ_j W_ij),
/// and `weight` = λ Σ_j σ_j W_ij / (W_0 + Σ_j W_ij) = -∂o_i/∂p_i (for the
/// implicit step). The solver pulls p_i toward p^w_i with a spring, so the
/// strands' own curl dynamics are never overwritten (Kim 2023's point: the
/// cohesive position does not disturb the curl motion, so clumps are stable).
struct CohesionTarget {
    Vec3f offset = Vec3f::Zero();
    float weight = 0.f;
    uint32_t neighbours = 0;
};

/// Cohesion targets for the points [begin, end) in `grid` order (the grid
/// built on all particles, grouped by strand), written to out[particle index].
/// Particles of the same strand never attract each other (no self-clumping of
/// a curl); dry neighbours (σ_j = 0) only dilute the average, as in eq. (10).
/// Each particle's result depends only on the positions, whatever the range
/// split: parallel calls over disjoint ranges are deterministic.
void cohesionTargets(const SpatialGrid& grid, const float* sigma, size_t begin, size_t end, float radius,
                     float tightness, CohesionTarget* out);

/// The poly6 kernel W(r, h) = 315/(64π h⁹) (h² - r²)³ for r < h, else 0.
float poly6(float r2, float h);

// ---- Adhesion (Kim 2023 §4, eq. 11-12) -------------------------------------------

/// The adhesion kernel of eq. (12) with the |φ| factors of eq. (11) cancelled:
///   A(r) = 0.007/h^3.25 · (-4r²/h + 6r - 2h)   for h/2 < r ≤ h, else 0,
/// zero at h/2 and h, largest at 3h/4 (Akinci et al.'s adhesion kernel
/// without its fourth root, as Kim 2023 prints it). r and h are taken in
/// centimetres: Kim 2023's constants give an adhesive pull of the order of
/// gravity in that unit (peak 0.00175·h^-2.25 times ν; in metres the same
/// constants would pull at ~10⁵ m/s²).
float adhesionKernel(float rCm, float hCm);

/// Adhesion acceleration of eq. (11) on a particle at signed distance φ from
/// the head (our φ: negative inside) with outward normal n:
///   a = -σ ν A(φ) n     for 0 < φ ≤ h (pulls toward the surface), else 0.
/// Kim 2023's field is positive inside the obstacle, so its "φ < 0" is the
/// outside of the head, and A's support (h/2, h] is a shell just outside the
/// contact distance: hair that touches the head and is pulled away is held
/// back while it is within h, and released beyond (the stretching of wet hair
/// on an obstacle, Kim 2023 Fig. 9). Dry hair (σ = 0) feels nothing.
/// `radius` h in metres.
Vec3f adhesionAcceleration(float phi, const Vec3f& normal, float sigma, float nu, float radius);

// ---- Stiffness (Kim 2023 §5, eq. 13) ---------------------------------------------

/// The saturation-dependent velocity factor of eq. (13): ζ = σγ0 + (1-σ)γ1.
/// Applied per reference step together with the global ξ:
///   v ← v · (ξ ζ)^(h/h_ref)     (perStepFactor),
/// which is step-size independent.
float wetVelocityFactor(float sigma, float gamma0, float gamma1);

// ---- template implementation --------------------------------------------------

template <typename F>
void SpatialGrid::forEachNear(const Vec3f& x, F&& f) const {
    if (entries_.empty() || !x.allFinite()) return;
    const Vec3f c = (x - origin_) * inv_;
    const int64_t cx = int64_t(std::floor(c.x())), cy = int64_t(std::floor(c.y())), cz = int64_t(std::floor(c.z()));
    const int64_t x0 = std::max<int64_t>(cx - 1, 0), x1 = std::min<int64_t>(cx + 1, nx_ - 1);
    if (x0 > x1) return;
    for (int64_t z = std::max<int64_t>(cz - 1, 0); z <= std::min<int64_t>(cz + 1, nz_ - 1); ++z)
        for (int64_t y = std::max<int64_t>(cy - 1, 0); y <= std::min<int64_t>(cy + 1, ny_ - 1); ++y) {
            const size_t row = size_t((z * ny_ + y) * nx_);
            for (uint32_t e = start_[row + size_t(x0)]; e < start_[row + size_t(x1) + 1]; ++e)
                f(entries_[e].index, entries_[e].point, entries_[e].group);
        }
}

}  // namespace hp::curly
