// Solver kernels of the `rod` formulation: a guide as an inextensible
// elastic rod (discrete elastic rod bending, Bergou et al. 2008) advanced by
// XPBD (Macklin et al. 2016) with a direct banded solve per strand (Deul et
// al. 2018: the constraints of a chain give a banded system). Pure functions
// on plain arrays, testable without a physics world.
//
// Notation: x_i vertices (x_0 the kinematic root), e_j = x_{j+1} - x_j,
// d_j = e_j/|e_j|, l_j rest length, w_i inverse mass, h the step.
// Joint j couples segment j with its parent, segment j-1; joint 0's parent
// is a ghost segment along the root frame's rest direction of segment 0
// (the clamped boundary condition θ(0) = 0 of a follicle).
#pragma once

#include "sim/guides/rod_lanes.h"
#include "sim/solver/damping.h"
#include "sim/solver/head_contact.h"
#include "sim/solver/length_kernels.h"
#include "sim/solver/strand_state.h"

#include <Eigen/Core>

#include <vector>

namespace hp::rod {

using Vec2f = Eigen::Vector2f;
using strand::Mat3f;

/// The section of one hair and the wisp a guide stands for. A guide is a
/// wisp of N identical fibres that slide freely along each other (no shear
/// coupling between them), so every sectional quantity adds up:
///   μ  = N·ρ·π r²          mass per length, kg/m
///   EI = N·E·π r⁴/4        bending stiffness, N·m²
///   GJ = N·G·π r⁴/2        twist stiffness, N·m²
/// and the wisp's gravity bending length (EI/μg)^(1/3) is that of one fibre.
/// The fibre is the one drawn: its radius tapers linearly from `radius` at
/// the root to `tipRadius` at the tip (strand::taperedRadius, hair.radius.*),
/// r(t) = r0 + (r1 - r0)·t at arc-length fraction t, so μ and EI vary along
/// the strand (EI by (r1/r0)⁴: 1/81 at the tip for 60 → 20 µm).
struct Material {
    float youngs = 3.8e9f;      ///< E, Pa
    float shear = 1.3e9f;       ///< G, Pa
    float density = 1300.f;     ///< ρ, kg/m³
    float radius = 4e-5f;       ///< r0, m: at the root (hair.radius.root)
    float tipRadius = 4e-5f;    ///< r1, m: at the tip (hair.radius.tip); = radius for a uniform fibre
    float hairsPerGuide = 100.f;///< N

    double area() const { return M_PI * double(radius) * radius; }
    /// At the root.
    double massPerLength() const { return double(hairsPerGuide) * density * area(); }
    double bendStiffness() const { return double(hairsPerGuide) * youngs * area() * radius * radius / 4.0; }
    double twistStiffness() const { return double(hairsPerGuide) * shear * area() * radius * radius / 2.0; }

    double radiusAt(double t) const { return double(radius) + (double(tipRadius) - radius) * t; }
    /// EI at arc-length fraction t: N·E·π r(t)⁴/4.
    double bendStiffnessAt(double t) const {
        const double r = radiusAt(t);
        return double(hairsPerGuide) * youngs * M_PI * r * r * r * r / 4.0;
    }
    /// Mass of the stretch of fibre between fractions t0 and t1, of length
    /// l: N·ρ·π ∫ r² = N·ρ·π·l·(r_a² + r_a·r_b + r_b²)/3, r linear in between.
    double segmentMass(double t0, double t1, double l) const {
        const double a = radiusAt(t0), b = radiusAt(t1);
        return double(hairsPerGuide) * density * M_PI * l * (a * a + a * b + b * b) / 3.0;
    }
    /// Mean mass per length over the strand (segmentMass over [0, 1] per length).
    double meanMassPerLength() const { return segmentMass(0.0, 1.0, 1.0); }
};

/// Constant data of one strand of `vertices` vertices for rodStep.
struct RodStrand {
    int vertices = 0;
    const float* restLength = nullptr;     ///< l_j, vertices - 1 entries
    const float* invMass = nullptr;        ///< w_i, vertices entries (w_0 = 0: kinematic root)
    const Vec2f* restCurvature = nullptr;  ///< c_j, vertices - 1 entries (joint j; see bendConstraint)
    Vec3f ghostDir = Vec3f::UnitY();       ///< rest direction of segment 0 in the root frame (root-local)
    double bendStiffness = 0;              ///< EI, N·m² (0: the strand does not bend)
    /// EI_j per joint (vertices - 1 entries), N·m²: a tapered fibre's
    /// (Material::bendStiffnessAt at joint j's vertex); null: bendStiffness
    /// at every joint.
    const double* jointStiffness = nullptr;
};

/// EI at joint j.
inline double stiffnessAt(const RodStrand& s, int j) { return s.jointStiffness ? s.jointStiffness[j] : s.bendStiffness; }

/// Voronoi length of joint j: l̄_0 = l_0/2 (the clamped end's half
/// segment), else (l_{j-1} + l_j)/2.
inline float voronoiLength(const RodStrand& s, int j) {
    return j == 0 ? 0.5f * s.restLength[0] : 0.5f * (s.restLength[j - 1] + s.restLength[j]);
}

/// Strands advanced together by rodSteps: each in one SIMD lane
/// (sim/guides/rod_lanes.h) through the assembly and the solves; a lane's
/// arithmetic is that of a lone strand, so the result does not depend on
/// how strands are batched.
constexpr int kLanes = 4;

/// Scratch for rodSteps, reused between calls (one per thread), lane-major
/// (sim/guides/rod_step.cpp): entry k holds the four lanes' values.
struct RodScratch {
    std::vector<lanes::V3<lanes::F4>> y;     ///< positions, per vertex
    std::vector<lanes::V3<lanes::F4>> start; ///< x̄, per vertex: where the step starts (x, or BDF2's extrapolation)
    std::vector<lanes::V3<lanes::F4>> grad;  ///< constraint gradients, per row × 3 vertices
    std::vector<lanes::V3<lanes::F4>> dir;   ///< stretch pass: segment directions
    std::vector<lanes::F4> w, rest, cosine;  ///< inverse masses, rest lengths, d_j·d_{j+1}
    std::vector<lanes::D4Store> band;             ///< banded systems, (bandwidth + 1) per row
    std::vector<lanes::D4Store> rhs, invD;        ///< right-hand sides (then Δλ), 1/pivots
    std::vector<lanes::D4Store> diag, lambda;     ///< stretch pass: pivots and right-hand side
    /// Curled strands (rod_holonomy.cpp): per joint K_j = C_j + c_j (two
    /// rows) and the reference twist's gradients ∂m_j/∂e_j, ∂m_j/∂e_{j-1};
    /// per row α̃ and the right-hand side -C; the iterations' vectors.
    std::vector<lanes::F4> curlA, curlB;
    std::vector<lanes::V3<lanes::F4>> twistEdge, twistParent;
    std::vector<lanes::D4Store> alphaRow, b, r, z, p, ap, q;
    std::vector<lanes::D4Store> wide;  ///< the float data above widened (rod_holonomy.cpp)
};

/// One strand's state and root target for rodSteps.
struct RodStepTarget {
    const RodStrand* strand = nullptr;
    Vec3f* x = nullptr;                      ///< positions at the step's start; the step's end on return
    Vec3f* v = nullptr;                      ///< velocities, likewise
    Vec3f rootPos = Vec3f::Zero();           ///< root position at the step's end
    Mat3f rootFrame = Mat3f::Identity();     ///< root frame at the step's end
    /// BDF2's history (rodSteps): positions and velocities at the previous
    /// step's start, x_{n-1} and v_{n-1}; they receive x_n and v_n. Null:
    /// the first-order step (implicit Euler). Every strand of a batch has
    /// history or none does.
    Vec3f* xBack = nullptr;
    Vec3f* vBack = nullptr;
    /// The head's parts this strand ignores (strand::HeadQuery::ignoreParts).
    uint32_t ignoreParts = 0;
};

/// The step BDF2 takes from the history (x_{n-1}, v_{n-1}) and the state
/// (x_n, v_n): the second-order backward differentiation formula
///   x_{n+1} - 4/3 x_n + 1/3 x_{n-1} = 2/3 h v_{n+1}
///   v_{n+1} - 4/3 v_n + 1/3 v_{n-1} = 2/3 h a(x_{n+1})
/// is, with x̄ = (4x_n - x_{n-1})/3, v̄ = (4v_n - v_{n-1})/3 and h' = 2h/3,
///   x_{n+1} = x̄ + h'·v̄ + h'²·a(x_{n+1}),   v_{n+1} = (x_{n+1} - x̄)/h',
/// an implicit Euler step of length h' from (x̄, v̄): the XPBD step below
/// with x̄, v̄, h' in place of x, v, h. From rest (x_{n-1} = x_n, v = 0) it
/// is exactly the implicit Euler step of h'. Returns h'.
inline float bdf2Step(float h) { return 2.f * h / 3.f; }
inline Vec3f bdf2Extrapolate(const Vec3f& now, const Vec3f& back) { return (4.f * now - back) / 3.f; }

/// History of a strand that moved at constant velocity v (x_{n-1} = x - h·v,
/// v_{n-1} = v; at rest, x_{n-1} = x): then x̄ = x + h·v/3 and v̄ = v, so
/// x̄ + h'·v̄ = x + h·v, the displacement of the step h, and a start or a
/// restart (scene cut, reset) needs no separate first-order step.
/// rodSteps restarts so each vertex that the head placed or pinned: the
/// contact removed its velocity into the head, v_{n+1} ≈ v_n - (v_n·n)n,
/// and the history would extrapolate that change, v̄ = v_{n+1} +
/// (v_{n+1} - v_n)/3, into a velocity away from the surface of a third of
/// the impact speed: a bounce the contact does not have.
inline void bdf2Start(const Vec3f* x, const Vec3f* v, int n, float h, Vec3f* xBack, Vec3f* vBack) {
    for (int i = 0; i < n; ++i) {
        xBack[i] = x[i] - h * v[i];
        vBack[i] = v[i];
    }
}

/// The bending constraint of joint j, in the parent's transported frame
/// (a_j, b_j = d_{j-1} × a_j, both ⊥ d_{j-1}):
///   κb_j = 2 d_{j-1} × d_j / (1 + d_{j-1}·d_j)   (|κb| = 2 tan(θ/2), θ the turn)
///   C_j = (κb_j·a_j, κb_j·b_j) - c_j
/// with energy E_j = EI_j/(2 l̄_j) |C_j|², l̄_j = (l_{j-1} + l_j)/2, l̄_0 = l_0/2
/// (the clamped end's Voronoi half-segment). Returns C_j and writes the
/// gradients of its two rows with respect to x_{j-1}, x_j, x_{j+1} (the
/// frame is held fixed: exact for the energy's gradient when c_j = 0, since
/// κb ⊥ d_{j-1}; the frame's turn with d_{j-1} is neglected otherwise).
/// For j = 0, `parent` is the ghost direction and g[·][0] is left zero.
Vec2f bendConstraint(const Vec3f& parentDir, float parentLen, const Vec3f& e, const Vec3f& a, const Vec2f& c,
                     bool ghost, Vec3f g[2][3]);

/// A unit vector ⊥ d taken from the root frame R (its tangent, else its
/// bitangent): the start of the transported frame at the ghost segment.
Vec3f frameStart(const Mat3f& R, const Vec3f& d);

/// Writes the rest curvatures c_j (vertices - 1 entries) of the shape x with
/// root frame R: C_j(x) = 0, so x is the stress-free shape.
void restCurvature(const RodStrand& s, const Vec3f* x, const Mat3f& R, Vec2f* c);

/// A rest turn |c_j| (either component, rad) at or below which a joint
/// counts as straight: a straight groom's rest curvatures are its
/// coordinates' rounding, up to 1.6·10⁻⁶ (B-sim's straight guides without
/// pre-load); a pre-load's are 0.27 rad and more (B-sim's). The holonomy's
/// term is O(|c|·|K|), negligible below it.
constexpr float kStraightTurn = 1e-4f;

/// True where the strand bends (EI > 0) and some rest curvature c_j is not
/// zero (above kStraightTurn): there the transported frame's holonomy
/// enters the bending force, and rodSteps solves with the full Jacobian
/// (constraintJacobian).
bool curled(const RodStrand& s);

/// The Jacobian J of a strand's constraints at x with respect to the free
/// vertices x_1..x_{n-1} (3(n-1) square): row 3j, 3j+1 the bend rows of
/// joint j, 3j+2 its stretch row C = |e_j| - l_j (gradient ±d_j); column
/// 3(i-1)+k vertex i's coordinate k. C (if not null) receives C(x).
/// holonomy: the bend rows' gradient includes the frame's turn. The frame
/// of joint j is carried by parallel transport from the root through the
/// turns of joints 0..j-1, so it turns about d_{j-1} by the holonomy
/// ψ_j = -Σ_{k<j} m_k (m_k the reference twist of joint k; Bergou et al.
/// 2008, "Discrete elastic rods"), and turning the frame by δψ turns
/// K_j = (κb·a, κb·b) by δψ·(K_2, -K_1):
///   ∇C_j = ∇C_j|frame fixed + (K_2, -K_1) ⊗ ∇ψ_j,  ∇ψ_j = -Σ_{k<j} ∇m_k,
///   ∂m_k/∂e_{k-1} = κb_k/(2|e_{k-1}|),  ∂m_k/∂e_k = κb_k/(2|e_k|).
/// Then Σ_j EI_j/l̄_j·∇C_jᵀ C_j is the gradient of bendEnergy for any rest
/// curvature. Joint j's rows touch vertices up to j+1 only: block lower
/// triangular, and invertible (vertex j+1 meets joint j only through the
/// frame-fixed part, as without the holonomy).
void constraintJacobian(const RodStrand& s, const Vec3f* x, const Mat3f& R, bool holonomy, Eigen::MatrixXd& J,
                        Eigen::VectorXd* C);

/// The equilibrium matrix Jᵀ of a strand at x (constraintJacobian with the
/// holonomy, transposed: one column per constraint row, one row per free
/// coordinate). Square (3(n-1)) and invertible. The pre-load solves with it
/// (sim/guides/rod_preload.h): with the holonomy, the static equilibrium of
/// the step that rodSteps takes for a curled strand.
Eigen::MatrixXd equilibriumMatrix(const RodStrand& s, const Vec3f* x, const Mat3f& R);

/// The solve of step 2 for the curled lanes of rodSteps (rod_holonomy.cpp):
/// (J W Jᵀ + α̃) Δλ = -C with J = constraintJacobian(holonomy), by
/// conjugate gradients preconditioned with the banded factorization of the
/// frame-fixed system (sc.band, sc.invD after bandedFactor), from its
/// solution (sc.rhs). J W Jᵀ is applied in O(n): Jᵀ by suffix sums of the
/// twisting moments, J by prefix sums of the holonomy. Each lane iterates
/// until its own residual |r| ≤ 10⁻⁵|C| (at most 100 times), so a
/// strand's result does not depend on its batch. Lanes not in `curled` are
/// left as they are. Returns the iterations of all lanes.
int holonomyIterate(RodScratch& sc, int n, const bool curled[kLanes]);


/// One XPBD step of length h for one strand (x: positions at the step's
/// start, v: velocities; root at rootPos with frame rootFrame at the end):
///  1. y = x + h·v + h²·g (root: its target; the root's velocity is real);
///  2. one Newton step of XPBD on y: (J W Jᵀ + α̃) Δλ = -C(y), α̃ = l̄_j/(EI_j h²)
///     for bend rows, 0 for stretch rows (hard), J the constraint gradients,
///     W the inverse masses; the system is banded (bandwidth 8 over rows
///     ordered joint by joint) and solved by banded LDLᵀ in double;
///     y += W Jᵀ Δλ. For a curled strand (curled(s)) J includes the
///     frame's holonomy (constraintJacobian), so the step is the gradient
///     of bendEnergy: the banded solve then preconditions conjugate
///     gradients on the full system (holonomyIterate);
///  3. exact lengths and head clearance root to tip (strand::placeSegment);
///     a vertex that cannot be placed outside the head at its length is
///     pinned: put back at its length toward its place at the step's start,
///     or, if the head took that place too, at the place at its length
///     outside the head nearest it, else the least deep
///     (sim/collision/segment_escape.h) (counted in *pinned);
///  4. v = (y - x)/h, Coulomb friction against the head's surface velocity,
///     drag v·exp(-drag·h); x = y.
/// Returns the number of pinned vertices.
int rodStep(const RodStrand& s, Vec3f* x, Vec3f* v, const Vec3f& rootPos, const Mat3f& rootFrame,
            const Vec3f& gravity, float h, float drag, float friction, const strand::HeadQuery* head, float radius,
            RodScratch& scratch);

/// rodStep for `count` (1..kLanes) strands of the same vertex count at once,
/// in SIMD lanes up to the head placement: the same result per strand, bit
/// for bit, as one at a time. Returns the number of pinned vertices of all
/// of them.
int rodSteps(const RodStepTarget* targets, int count, const Vec3f& gravity, float h, float drag, float friction,
             const strand::HeadQuery* head, float radius, RodScratch& scratch);

/// One mass-weighted Newton step on the stretch constraints alone,
/// C_j = |x_{j+1} - x_j| - l_j: J W Jᵀ is tridiagonal,
///   A_jj = w_j + w_{j+1},  A_{j,j+1} = -w_{j+1} d_j·d_{j+1},
/// solved by the Thomas algorithm; x_j -= w_j d_j Δλ_j, x_{j+1} += w_{j+1} d_j Δλ_j.
/// Momentum-conserving, unlike follow-the-leader; it leaves a stretch error
/// of the second order, which the final exact placement then removes
/// without visible bias.
/// `w` the inverse masses (n entries), `rest` the rest lengths (n - 1).
/// The length pass of rodSteps, before its exact-length finish: one strand
/// run through the same four-lane code the step uses (rod_step.cpp).
void stretchSolve(Vec3f* x, const float* w, const float* rest, int n);

/// The part of the bending force that rod::bendConstraint's gradient leaves
/// out where the rest curvature is not zero, added to force[0..vertices-1]:
/// the frame (a_j, b_j) of joint j is carried by parallel transport from
/// the root through the turns of joints 0..j-1, so when the strand moves it
/// also turns about d_{j-1} by the change of the holonomy, δψ_j = -Σ_{k<j} δm_k,
/// with δm_k the reference twist of joint k (Bergou et al. 2008, "Discrete
/// elastic rods", and 2010, "Discrete viscous threads"):
///   ∂m_k/∂e_{k-1} = κb_k/(2|e_{k-1}|),   ∂m_k/∂e_k = κb_k/(2|e_k|).
/// Turning the frame by δψ turns K_j = (κb·a, κb·b) by δψ·(K_2, -K_1), so
///   τ_j = ∂E_j/∂ψ_j = EI_j/l̄_j·(c_2 K_1 - c_1 K_2)
/// and the force is F = Σ_k T_k ∇m_k with T_k = Σ_{j>k} τ_j (the twisting
/// moment carried past joint k toward the root). Zero when c = 0; with it,
/// the assembled force plus this one is -∇E (tests/test_rod.cpp).
void holonomyForce(const RodStrand& s, const Vec3f* x, const Mat3f& R, Vec3f* force);

/// Total bending energy Σ EI_j/(2 l̄_j)|C_j|² of a strand, J.
double bendEnergy(const RodStrand& s, const Vec3f* x, const Mat3f& rootFrame);

}  // namespace hp::rod
