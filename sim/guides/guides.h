// Guide strands: the simulated strands of Gomes, "Estudo de Otimização de
// Simulação de Cabelo em Tempo Real Baseado em Física em Unity" (2024;
// Gomes 2024 below), which the followers copy.
//
// A guide is a chain of `segments` segments rooted on the animated scalp. The
// solver advances all guides by one fixed step at a time, given where the
// roots are at the end of the step (the head moves them kinematically, with
// real velocities) and the head's collider. Three formulations share this
// interface; what Bullet computes differs in each (sim/guides/guide_group.h):
//
// - `Rod` (default): each guide is an inextensible elastic rod with physical
//   parameters (E, ρ, the drawn tapered fibre, hairs per guide), advanced by XPBD
//   in BDF2 steps with a direct banded solve per strand (sim/guides/rod_kernels.h,
//   sim/guides/rod_group.cpp). Bullet integrates nothing here: it only finds
//   strand-strand contact pairs and their closest points (broadphase and
//   capsule narrowphase, sim/guides/strand_contacts.cpp) when
//   strandCollision is on, and distances to the colliders beside the head
//   (sim/collision/collision_world.h); dynamics, head contact and friction
//   are this project's kernels.
// - `Rope`: each guide is a Bullet btSoftBody rope. Bullet integrates
//   gravity and velocities and solves the stretch links (its Gauss-Seidel
//   link passes), interleaved with the bend limits; the kernels of
//   sim/guides/joint_kernels.h turn the joints toward the (gravity
//   pre-loaded) rest shape on Bullet's prediction and, after the step,
//   restore exact lengths and push vertices out of the head's signed
//   distance with Coulomb friction (sim/guides/rope_group.cpp says why).
// - `Rigid`: Gomes 2024's own arrangement, kept faithful for comparison, and the
//   one where Bullet computes everything: capsule btRigidBody segments
//   joined by btGeneric6DofSpring2Constraint (Unity's ConfigurableJoint):
//   locked linear motion, soft ±bend/±twist limits, springs toward the rest
//   pose, a projection limit; the head is a kinematic Bullet triangle-mesh
//   body.
//
// The stepping itself (time, head interpolation, scene cuts, written frames,
// statistics) is the skeleton every strand model shares
// (sim/solver/skeleton.h). Bullet stays inside sim/*.cpp; this header
// is plain C++ and Eigen.
#pragma once

#include "sim/solver/step_settings.h"
#include "sim/solver/strand_solver.h"
#include "sim/strands/head.h"
#include "sim/strands/strand.h"
#include "sim/volume/volume_settings.h"

#include <memory>
#include <string>
#include <vector>

namespace hp {

enum class GuideFormulation { Rope, Rigid, Rod };

/// The rod's time integrator (sim/guides/rod_kernels.h): `Bdf2`, the
/// second-order backward differentiation formula (keeps a swing's energy,
/// damps what the step cannot resolve), or `Euler`, implicit Euler (the
/// default; first order: damps every motion by ~π·ω·h per period).
enum class RodIntegrator { Euler, Bdf2 };
/// "euler" / "bdf2", and back (throws hp::Error naming the choices).
const char* rodIntegratorName(RodIntegrator i);
RodIntegrator parseRodIntegrator(const std::string& name);

/// "rope" / "rigid" / "rod".
const char* formulationName(GuideFormulation f);
/// Inverse of formulationName; throws hp::Error naming the valid choices.
GuideFormulation parseFormulation(const std::string& name);

/// Everything the guide solver needs to know (the step, scene cuts, render
/// radii and partition: StepSettings). Units: metres, seconds, kg, degrees
/// for angles. Defaults are Gomes 2024's Unity settings where it gives one.
struct GuideSettings : StepSettings {
    GuideFormulation formulation = GuideFormulation::Rod;

    // Shape of a guide.
    int segments = 23;              ///< segments per guide (vertices = segments + 1)
    float length = 0.25f;           ///< rest length of a guide, m
    float collisionRadius = 0.001f; ///< capsule radius for head and strand-strand contact, m

    // Time stepping (Gomes 2024: fixed step 0.02 s, 20 solver iterations; the step
    // and substeps: StepSettings).
    int iterations = 20;            ///< Bullet solver iterations per Bullet step

    // Material.
    float massPerLength = 0.005f;   ///< rope, rigid: kg/m (a guide stands for a clump of hairs)
    float bendStiffness = 5e-5f;    ///< rope, rigid: joint spring toward the rest pose, N·m/rad
    // Rod material (SI): μ = N·ρ·πr², EI = N·E·πr⁴/4, r the drawn fibre's radius tapering
    // from rootRadius to tipRadius (sim/guides/rod_kernels.h Material).
    // No shear modulus: the rod carries no twist (sim/guides/rod_group.cpp).
    float youngsModulus = 3.8e9f;   ///< rod: E, Pa
    float density = 1300.f;         ///< rod: ρ, kg/m³
    /// rod: N, the hairs of the wisp a guide stands for. Mass and EI both
    /// scale with N, drag is a rate and contacts are positions, so N cancels
    /// out of the rod's motion: only the energies reported scale with it.
    float hairsPerGuide = 100.f;
    /// rod: the fibre tapers as drawn (rootRadius → tipRadius: EI per joint,
    /// mass per segment); false: the root's section all along. Off by
    /// default: with it the default scene's settled groom stands up (docs/physics.md).
    bool taperedFibre = false;
    int rodSubsteps = 2;            ///< rod: XPBD steps per solver substep
    RodIntegrator rodIntegrator = RodIntegrator::Bdf2;  ///< rod: the time integrator (docs/physics.md: BDF2 keeps a swing's energy)
    int preloadProbes = 3;          ///< rod: probe steps refining the pre-load (rod::preload)
    float bendDamping = 0.f;        ///< rigid only: joint spring damping, N·m·s/rad
    float damping = 1.0f;           ///< velocity decay rate, 1/s: v *= exp(-damping·t), any step size (rod: air drag)
    float friction = 0.2f;          ///< Coulomb friction against the head and between strands
    Vec3f gravity = Vec3f(0.f, -9.81f, 0.f);  ///< m/s²
    bool preload = true;            ///< pre-load the springs so the rest shape holds under gravity at t0
    /// rod: the pre-load leans on the head where the groom lies on it (the head
    /// carries what lies on it, rest curvature what hangs free: rod::preload);
    /// false (the default until the shot's still head holds it: docs/physics.md):
    /// every vertex's full weight goes into rest curvature.
    bool preloadContact = false;
    float preloadReach = 0.001f;    ///< rod: a vertex within collisionRadius + this of the head leans on it, m
    /// rod: the pre-load changes joint j's rest curvature by at most this many
    /// times 1/ℓ_b (ℓ_b the bending length; rod::limitPreload); ≤ 0: no bound.
    float preloadLimit = 1.5f;

    // Joint limits (Gomes 2024: ±30° about the bending axes, ±10° twist, soft).
    float bendLimit = 30.f;         ///< deg
    float twistLimit = 10.f;        ///< deg (rigid only: a rope has no twist)
    float limitStiffness = 1e-3f;   ///< spring pushing a joint back inside its limit, N·m/rad
    float projectionAngle = 5.f;    ///< beyond limit + this, a joint is snapped back (Gomes 2024: projection limit), deg
    float projectionDistance = 0.1f;///< rigid only: joint separation snapped back, fraction of a segment

    // Contacts.
    bool headCollision = true;      ///< project vertices out of the head's signed distance each Bullet step
    bool strandCollision = false;   ///< strand-strand collision (Gomes 2024, Table 5.1 row 7); serialises contact solving
    /// Hair against hair through a grid (sim/volume/hair_grid.h): friction
    /// and volume, before every substep. Rod and rope formulations.
    VolumeSettings volume;


    // Guard: a vertex faster than this after a step is numerical, not
    // physical (a violent head turn moves tips a few m/s); its velocity is
    // scaled back to it so one bad step cannot pump energy into the next.
    // Rod and rope formulations; 0 disables the clamp.
    float maxSpeed = 50.f;          ///< m/s


    /// Throws hp::Error naming the first setting out of range.
    void validate() const;
    /// A guide's mass per length as its formulation has it, kg/m: rod
    /// N·ρ·πr² (hair.material) averaged over the taper, rope and rigid massPerLength.
    double guideMassPerLength() const;
};

/// Drives all guides of a shot (stepping, written frames, time, statistics:
/// StrandSolver; a step's head mesh is used only by the rigid formulation).
/// Not thread-safe itself; parallel inside.
class GuideSolver : public StrandSolver {
  public:
    explicit GuideSolver(const GuideSettings& settings);
    ~GuideSolver();

    /// Creates the guides at `head.time`: one per root frame. The rest shape
    /// is `groom` (world-space vertices at head.time, segments + 1 per guide)
    /// or, when null, straight along each root normal. With `preload` the
    /// springs are pre-loaded so this shape is in equilibrium under gravity.
    void initialize(const std::vector<SurfaceFrame>& roots, const HeadPose& head,
                    const std::vector<std::vector<Vec3f>>* groom = nullptr);

    const GuideSettings& settings() const;
    /// Per guide, the head's parts it ignores (bit k: part k; those its root
    /// lies inside, sim/collision/mesh_parts.h partsAroundRoots), after
    /// initialize: contact, pinning and the penetration statistics then use
    /// the head without them. Rod formulation (the rope's and rigid chain's
    /// Bullet steps see every part). Empty: none. Throws hp::Error on a size mismatch.
    void setIgnoredParts(std::vector<uint32_t> masks);
    /// Statistics of the current state without stepping (used after initialize).
    StepStats measure(const Collider* collider) const;

    /// The dynamic state (positions, velocities, root targets, time) as
    /// bytes, for checkpoints. Rope only: the rigid formulation keeps state
    /// inside Bullet (orientations, warm-start impulses) that cannot be
    /// restored bit for bit, so it throws hp::Error.
    std::vector<char> saveState() const;
    /// Restores saveState()'s bytes into a solver initialised identically
    /// (same settings, same roots at the same start time); the solver then
    /// continues exactly as the one that saved them. Throws hp::Error on a
    /// size mismatch.
    void restoreState(const std::vector<char>& state);

    /// Largest bend angle between consecutive segments (and the root normal)
    /// relative to the rest shape, and (rigid) the largest twist, in degrees.
    /// For tests and diagnostics.
    void jointAngles(float& maxBend, float& maxTwist) const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace hp
