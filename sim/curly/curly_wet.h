// Curly and wet guide strands (Kim 2023 on Iben et al. 2013), the
// second strand model beside the rigid-chain guides (sim/guides/guides.h), with the
// same shape of interface so the same driver can run either.
//
// A guide is a chain of particles (default 24) joined by Kim 2023's stretch,
// bending and core springs; wet hair adds curl exaggeration, cohesion between
// strands, adhesion to the head and saturation-dependent stiffness, all
// driven by a per-particle saturation σ that the pipeline animates per step
// (setSaturation). Arrangement (details in sim/curly/curly_world.cpp):
// - Kim 2023's forces are assembled per strand into one linearly implicit
//   (backward Euler) step (sim/curly/curly_dynamics.h), stable at 0.02 s;
// - Bullet does the dynamics: each guide is a btSoftBody rope in a
//   btSoftRigidDynamicsWorld; the implicit step's result enters as node forces
//   (addForce), Bullet integrates gravity and those forces and solves the
//   inextensible links;
// - head contact is the projection out of the head's signed distance with
//   Coulomb friction after each Bullet step (Bridson et al., as Kim 2023);
// - strain and root-to-tip velocity limiting (Selle et al.) and Kim 2023's
//   velocity scales ξ, ζ follow.
// Strands are split into fixed groups, one Bullet world each, advanced in
// parallel with TBB; cohesion reads the previous step's positions of all
// strands, so the result does not depend on the thread count.
//
// The stepping itself (time, head interpolation, scene cuts, written frames,
// statistics) is the skeleton every strand model shares
// (sim/solver/skeleton.h). Bullet stays inside sim/*.cpp; this header
// is plain C++ and Eigen.
#pragma once

#include "sim/guides/rod_kernels.h"
#include "sim/solver/step_settings.h"
#include "sim/solver/strand_solver.h"
#include "sim/strands/head.h"
#include "sim/strands/strand.h"

#include <memory>
#include <vector>

namespace hp {

/// A mass or spring constant of CurlyWetSettings left to the material
/// (any negative value means the same).
inline constexpr float kFromMaterial = -1.f;

/// Everything the curly/wet solver needs (the step, scene cuts, render radii
/// and partition: StepSettings). Units: metres, seconds, kg, degrees for
/// angles. Defaults are Kim 2023's values where it gives one.
struct CurlyWetSettings : StepSettings {
    // Shape of a guide. Rest shape: a helix along the root normal (unless a
    // groom is given to initialize), so a curly guide is curly at rest.
    int particles = 24;             ///< particles per guide (edges = particles - 1)
    float length = 0.25f;           ///< arc length of a guide, m
    float curlRadius = 0.01f;       ///< rest helix radius, m (0: straight)
    float curlPitch = 0.04f;        ///< rest helix advance per turn, m
    float collisionRadius = 0.001f; ///< clearance kept from the head, m

    // Time stepping (the step and substeps: StepSettings).
    int iterations = 8;             ///< Bullet link (inextensibility) iterations per Bullet step

    // Material and springs (Kim 2023 eq. 1, 4, 5). Mass and the stretch, bending
    // and core springs follow from `material` (the rod formulation's fibre
    // and wisp), the curl and the step where they are kFromMaterial (the
    // default): curly::materialSprings, sim/curly/curly_dynamics.h; so does
    // helixWeight (5 kb). A value ≥ 0 is used as given (Kim 2023's:
    // 0.005 kg/m, ks = 5000, kb = kc = 20 N/m, w_h = 100 N/m).
    rod::Material material;         ///< E, G, ρ, fibre radius, hairs per guide
    float massPerLength = kFromMaterial; ///< kg/m (a guide stands for a clump of hairs)
    Vec3f gravity = Vec3f(0.f, -9.81f, 0.f);  ///< m/s²
    bool preload = true;            ///< bending targets pre-loaded so the rest shape holds under gravity at t0
    float stretchStiffness = kFromMaterial; ///< ks, N/m (a numerical aid: Bullet's links keep edges inextensible)
    float stretchDamping = 0.05f;   ///< cs, N·s/m
    float bendStiffness = kFromMaterial; ///< kb, N/m
    float bendDamping = 0.02f;      ///< cb, N·s/m
    float bendSmoothing = 0.05f;    ///< α of the bending frames' smoothing filter, m
    float coreStiffness = kFromMaterial; ///< kc, N/m
    float coreDamping = 0.02f;      ///< cc, N·s/m
    float coreSmoothing = 0.05f;    ///< α_c of the core curve, m
    float maxStrain = 0.001f;       ///< strain limit |l/l̄ - 1| after each Bullet step
    float maxRelativeVelocity = 2.f;///< root-to-tip velocity limit |v_{i+1} - v_i|, m/s
    float friction = 0.2f;          ///< Coulomb friction against the head

    // Wet effects, driven by the saturation σ_i = clamp(σ·profile(s_i), 0, 1).
    bool wetEffects = true;         ///< false: σ is ignored (always dry)
    float saturation = 0.f;         ///< σ of the scene until setSaturation is called
    float saturationRoot = 1.f;     ///< profile factor at the root
    float saturationTip = 1.f;      ///< profile factor at the tip (linear in between)
    float helixRadius = 0.f;        ///< wet helix radius r (eq. 6), m; 0: the curl radius
    float helixPitch = 0.f;         ///< wet helix advance per turn (2π p of eq. 6), m; 0: the curl pitch
    float helixWeight = kFromMaterial; ///< w_h of eq. (9), N/m; kFromMaterial: 5 kb (a wet helix unlike the rest curl wins)
    bool cohesion = true;           ///< cohesion between wet strands (eq. 10)
    float cohesionTightness = 0.85f;///< λ (Kim 2023: 0.85)
    float cohesionRadius = 0.01f;   ///< kernel radius of the neighbour average, m
    float cohesionStiffness = 1e4f; ///< pull toward the cohesive position, per unit mass, 1/s²
    bool adhesion = true;           ///< adhesion to the head (eq. 11-12)
    float adhesionWeight = 1300.f;  ///< ν (Kim 2023: 1300)
    float adhesionRadius = 0.005f;  ///< h of A(r): the shell outside the head where wet hair is held, m
    float globalStiffness = 0.999995f; ///< ξ, velocity scale per reference step (Kim 2023: 0.999995)
    float wetStiffness = 0.9999f;   ///< γ0, ζ at σ = 1 (Kim 2023: 0.9999)
    float dryStiffness = 1.0f;      ///< γ1, ζ at σ = 0 (Kim 2023: 1.0)
    float stiffnessStep = 1e-4f;    ///< reference step of ξ and ζ, s: v ← v(ξζ)^(h/this)



    /// Throws hp::Error naming the first setting out of range.
    void validate() const;
    /// These settings with the material's mass and springs in place of every
    /// kFromMaterial (what the solver runs with: CurlyWetSolver::settings()).
    CurlyWetSettings resolved() const;
    /// Kim 2023's mass and spring constants (0.005 kg/m, ks = 5000, kb = kc = 20 N/m)
    /// instead of the material's.
    static CurlyWetSettings seedSprings();
};

/// Drives all curly guides of a shot (stepping, written frames, time,
/// statistics: StrandSolver; a step's collider may be null: no collision, no
/// adhesion). Not thread-safe itself; parallel inside.
class CurlyWetSolver : public StrandSolver {
  public:
    explicit CurlyWetSolver(const CurlyWetSettings& settings);
    ~CurlyWetSolver();

    /// Creates the guides at `head.time`: one per root frame. The rest shape
    /// is `groom` (world-space particles at head.time, `particles` per guide)
    /// or, when null, a helix of the curl radius and pitch along each root
    /// normal. The head is only used for its time here.
    void initialize(const std::vector<SurfaceFrame>& roots, const HeadPose& head,
                    const std::vector<std::vector<Vec3f>>* groom = nullptr);

    /// Sets the scene's saturation σ ∈ [0, 1] for the following steps; each
    /// particle gets σ times the root-to-tip profile. Call it per step (or per
    /// frame) with the scene's curve evaluated at that time.
    void setSaturation(float sigma);
    /// Sets every particle's saturation directly (guideCount()·particles
    /// values, guide-major, clamped to [0, 1]).
    void setSaturation(const std::vector<float>& perParticle);
    /// The per-particle saturations in use.
    const std::vector<float>& saturation() const;

    int particlesPerGuide() const;

    /// The dynamic state (positions, velocities, saturation, root targets,
    /// time) as bytes, for checkpoints; restoreState() puts it back into a
    /// solver initialised identically, which then continues bit for bit like
    /// the one that saved it (a particle's whole Bullet state is its position
    /// and velocity, reloaded every step).
    std::vector<char> saveState() const;
    void restoreState(const std::vector<char>& state);
    const CurlyWetSettings& settings() const;
    /// Statistics of the current state without stepping.
    StepStats measure(const Collider* collider) const;

    /// Curl radius and pitch fitted to each guide (sim/curly/curly_kernels.h
    /// fitHelix, leaving out the first `skip` edges), medians over the guides;
    /// for tests and diagnostics. {0, 0} when no guide is curly.
    Eigen::Vector2f measureCurl(size_t skip = 3) const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace hp
