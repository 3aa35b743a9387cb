// One linearly implicit step of a curly strand (Kim 2023 / Iben et al. 2013):
// all of Kim 2023's forces on one strand, assembled into a block-tridiagonal
// system and solved for the velocity change. Plain C++ and Eigen, no physics
// world: the solver (sim/curly/curly_world.cpp) hands the result to Bullet as node
// forces, and Bullet integrates and solves the inextensible links.
//
// Why implicit: an explicit step of a spring k on a mass m is stable only for
// h²k/m < 4; the springs that hold a curl against gravity have h²k/m ≈ 150
// (bending) and ≈ 4·10⁴ (stretch) at the defaults and h = 0.02 s. Backward
// Euler linearised once (Baraff & Witkin 1998) is stable for any k:
//   (M + hC + h²K) Δv = h (f + M g + M a_ext) - h² K v,
// with K and C the stiffness and damping Jacobians of the pair springs (block
// tridiagonal: each spring couples particles i and i+1), the bending targets
// and the cohesive positions held fixed over the step. The root is
// kinematic: its velocity change is known and moves to the right-hand side.
#pragma once

#include "sim/curly/curly_kernels.h"
#include "sim/curly/wet_forces.h"
#include "sim/guides/rod_kernels.h"

#include <vector>

namespace hp::curly {

/// The rest state of one strand of n particles.
struct StrandRest {
    const float* edgeLength = nullptr;  ///< n-1: |ē_i|
    const Vec3f* bendTarget = nullptr;  ///< n-1: t̄_i = F̄_iᵀ ē_i, in the bending frames (plus the pre-load)
    const float* coreLength = nullptr;  ///< n-1: |b̄_i|, rest length of the smoothed edges
    const Vec3f* helix = nullptr;       ///< n: wet helix points (eq. 6), root-local
    const float* mass = nullptr;        ///< n: particle masses (mass[0] unused: the root is kinematic)
};

/// Coefficients of one step (settings after unit conversion).
struct StrandCoefficients {
    float ks = 0, cs = 0;        ///< stretch spring, N/m and N·s/m
    float kb = 0, cb = 0;        ///< bending spring
    float kc = 0, cc = 0;        ///< core spring
    float betaBend = 1, betaCore = 1;  ///< smoothing filter coefficients
    float curlWeight = 0;        ///< w_h, N/m (0: no curl exaggeration)
    float cohesionStiffness = 0; ///< κ, 1/s²: pull toward the cohesive position, per unit mass
    Vec3f gravity = Vec3f(0.f, -9.81f, 0.f);
};

/// Mass and spring constants of a guide derived from its wisp's material.
struct MaterialSprings {
    float massPerLength = 0;  ///< μ, kg/m
    float ks = 0;             ///< stretch spring, N/m
    float kb = 0;             ///< bending spring, N/m
    float kc = 0;             ///< core spring, N/m
};

/// Kim 2023's spring model made physical: μ, kb and kc of a guide whose rest
/// shape is a curl of radius R and pitch P (advance per turn), sampled by
/// inextensible edges of length l, from the wisp's material (rod::Material:
/// the same keys, μ = Nρπr², EI = NEπr⁴/4 and GJ = NGπr⁴/2, as the rod).
///
/// The load a hanging curl carries is an axial pull F. In the wire of a helix
/// (pitch angle α, tan α = P/(2πR)) it is a moment F·R, a twist F·R·cos α and
/// a bend F·R·sin α, so by Castigliano an edge's length l of wire stores
/// ½F²·c_l with
///   c_l = R² l (cos²α/GJ + sin²α/EI),
/// its share of the coil's axial compliance (the coil's is Σ c_l). In the
/// spring model the bending frames follow the smoothed curve, i.e. the curl's
/// axis, so the same pull, F·cos α across the edge, tilts the edge by
/// Δα = F cos α/(kb l) against its bending spring, and the edge's advance
/// along the axis grows by l cos α·Δα = F cos²α/kb. Equal compliance:
///   kb = cos²α / c_l.
/// The coil's whole axial stiffness is then in kb, so kc = 0 (a core spring
/// would add kc cos²α per edge on top of it; set it to get Kim 2023's stiffer
/// curls). A curl no wider than an edge is not resolved by the edges and c_l
/// vanishes with R: kb is capped by a straight rod's, the discrete joint
/// stiffness EI/l (the rod formulation's) felt at the edge's end,
///   kb ≤ EI/l³,
/// which is also kb for a straight rest shape (R = 0).
///
/// The stretch spring is not the fibre's EA/l (~10⁵ N/m, far beyond what the
/// once-linearised step carries at 0.02 s on particles of a few mg): Bullet's
/// links and the strain limit keep the edges inextensible and ks only helps
/// them, so it is set by the step, h²·ks/m = 10⁴ for a particle of mass
/// m = μ·l (`mass`, when ≥ 0, is the μ to use instead of the material's):
/// ks = 10⁴·m/h². (Measured: a pre-loaded hanging curl with the material's
/// kb loses its equilibrium within a second at h²·ks/m ≈ 4·10⁴, which is
/// Kim 2023's 5000 N/m on 0.005 kg/m and 24 particles; at 10⁴ it holds, and the
/// hanging extension does not change between ks = 30 and 300 N/m.)
MaterialSprings materialSprings(const rod::Material& material, float curlRadius, float curlPitch, float edgeLength,
                                float mass, float step);

/// Per-particle inputs of one step that are not positions or velocities.
struct StrandLoads {
    const float* sigma = nullptr;              ///< n saturations (null: dry)
    const CohesionTarget* cohesion = nullptr;  ///< n cohesive offsets (null: none)
    const Vec3f* acceleration = nullptr;       ///< n extra accelerations, e.g. adhesion (null: none)
};

/// Work space reused across strands (one per thread or group).
struct StrandScratch {
    std::vector<Vec3f> d, b, nu, curl, force, rhs;
    std::vector<Mat3f> frames, diag, upper;
    void resize(size_t n);
};

/// The implicit step. `x`, `v`: the strand at the step's start (n particles,
/// root first); `root`: the root frame R at the step's end; `rootVelocity`:
/// the root's velocity over the step. Writes Δv for every particle into `dv`
/// (dv[0] = rootVelocity - v[0]). Returns false if the system was not finite.
bool implicitStep(const Vec3f* x, const Vec3f* v, size_t n, const Mat3f& root, const Vec3f& rootVelocity,
                  const StrandRest& rest, const StrandCoefficients& k, const StrandLoads& loads, float h,
                  StrandScratch& s, Vec3f* dv);

/// The rest data of a strand from its rest positions `p` (root-local or world,
/// as long as `root` is the root frame in the same coordinates): edge lengths,
/// bending targets t̄_i and smoothed (core) edge lengths. With `preload`, the
/// bending targets are shifted so that the rest shape is an equilibrium under
/// gravity g: the weight hanging below each edge, W_i = g Σ_{k>i} m_k, is
/// carried by the bending spring, t_i = ē_i - W_i/kb (the spring pushes each
/// child up by exactly the weight it holds). When the strand later turns
/// relative to gravity, the part of the shift along the edge stretches it by
/// about kb|W_i|/(kb + ks)/kb, negligible with the stiff default ks.
void restData(const Vec3f* p, size_t n, const Mat3f& root, const StrandCoefficients& k, const float* mass,
              bool preload, float* edgeLength, Vec3f* bendTarget, float* coreLength);

}  // namespace hp::curly
