// Guide strands simulated with Bullet (seed 000's "fios guia").
//
// A guide is a chain of `segments` segments rooted on the animated scalp. The
// solver advances all guides by one fixed step at a time, given where the
// roots are at the end of the step (the head moves them kinematically, with
// real velocities) and the head's collider. Two formulations share this
// interface (see sim/guides/guide_group.h for how each one maps onto Bullet):
//
// - `Rod` (default): each guide is an inextensible elastic rod with physical
//   parameters (E, G, ρ, fibre radius, hairs per guide), advanced by XPBD
//   with a direct banded solve per strand (sim/guides/rod_kernels.h,
//   sim/guides/rod_group.cpp); no Bullet world, Bullet only for strand-strand pairs.
// - `Rope` (the previous production formulation): each guide is a Bullet btSoftBody rope;
//   Bullet integrates gravity and solves the stretch links, interleaved with
//   the bend limits; the kernels of sim/guides/joint_kernels.h turn the joints
//   toward the (gravity pre-loaded) rest shape on Bullet's prediction and,
//   after the step, restore exact lengths and push vertices out of the
//   head's signed distance with Coulomb friction. Meets the length,
//   penetration and speed goals; sim/guides/rope_group.cpp says why it is built so.
// - `Rigid`: the seed's own arrangement, kept faithful for comparison: capsule
//   btRigidBody segments joined by btGeneric6DofSpring2Constraint (Unity's
//   ConfigurableJoint): locked linear motion, soft ±bend/±twist limits,
//   springs toward the rest pose, a projection limit; the head is a kinematic
//   Bullet triangle-mesh body.
//
// The stepping itself (time, head interpolation, scene cuts, written frames,
// statistics) is the skeleton every strand model shares
// (sim/solver/strand_solver.h). Bullet stays inside sim/*.cpp; this header
// is plain C++ and Eigen.
#pragma once

#include "sim/solver/step_stats.h"
#include "sim/strands/head.h"
#include "sim/strands/strand.h"

#include <memory>
#include <string>
#include <vector>

namespace hp {

enum class GuideFormulation { Rope, Rigid, Rod };

/// "rope" / "rigid" / "rod".
const char* formulationName(GuideFormulation f);
/// Inverse of formulationName; throws hp::Error naming the valid choices.
GuideFormulation parseFormulation(const std::string& name);

/// Everything the guide solver needs to know. Units: metres, seconds, kg,
/// degrees for angles. Defaults are seed 000's values where the seed gives one.
struct GuideSettings {
    GuideFormulation formulation = GuideFormulation::Rod;

    // Shape of a guide.
    int segments = 23;              ///< segments per guide (vertices = segments + 1)
    float length = 0.25f;           ///< rest length of a guide, m
    float collisionRadius = 0.001f; ///< capsule radius for head and strand-strand contact, m
    float rootRadius = 0.00004f;    ///< render radius at the root (written to StrandFrame), m
    float tipRadius = 0.00001f;     ///< render radius at the tip, m

    // Time stepping (seed: fixed step 0.02 s, 20 solver iterations).
    float timeStep = 0.02f;         ///< one step, s
    int substeps = 1;               ///< Bullet steps per step
    int iterations = 20;            ///< Bullet solver iterations per Bullet step

    // Material.
    float massPerLength = 0.005f;   ///< rope, rigid: kg/m (a guide stands for a clump of hairs)
    float bendStiffness = 5e-5f;    ///< rope, rigid: joint spring toward the rest pose, N·m/rad
    // Rod material (SI): μ = N·ρ·πr², EI = N·E·πr⁴/4, GJ = N·G·πr⁴/2, r = rootRadius (sim/guides/rod_kernels.h).
    float youngsModulus = 3.8e9f;   ///< rod: E, Pa
    float shearModulus = 1.3e9f;    ///< rod: G, Pa (GJ is reported; see sim/guides/rod_group.cpp for why it enters nothing)
    float density = 1300.f;         ///< rod: ρ, kg/m³
    float hairsPerGuide = 100.f;    ///< rod: N, the hairs of the wisp a guide stands for
    int rodSubsteps = 2;            ///< rod: XPBD steps per solver substep
    float bendDamping = 0.f;        ///< rigid only: joint spring damping, N·m·s/rad
    float damping = 1.0f;           ///< velocity decay rate, 1/s: v *= exp(-damping·t), any step size (rod: air drag)
    float friction = 0.2f;          ///< Coulomb friction against the head and between strands
    Vec3f gravity = Vec3f(0.f, -9.81f, 0.f);  ///< m/s²
    bool preload = true;            ///< pre-load the springs so the rest shape holds under gravity at t0

    // Joint limits (seed: ±30° about the bending axes, ±10° twist, soft).
    float bendLimit = 30.f;         ///< deg
    float twistLimit = 10.f;        ///< deg (rigid only: a rope has no twist)
    float limitStiffness = 1e-3f;   ///< spring pushing a joint back inside its limit, N·m/rad
    float projectionAngle = 5.f;    ///< beyond limit + this, a joint is snapped back (seed: projection limit), deg
    float projectionDistance = 0.1f;///< rigid only: joint separation snapped back, fraction of a segment

    // Contacts.
    bool headCollision = true;      ///< project vertices out of the head's signed distance each Bullet step
    bool strandCollision = false;   ///< strand-strand collision (seed table row 7); serialises contact solving

    // Scene cuts: a root or head jump beyond these in one step resets the guides to rest.
    float teleportDistance = 0.1f;  ///< m per step
    float teleportAngle = 45.f;     ///< deg per step

    // Guard: a vertex faster than this after a step is numerical, not
    // physical (a violent head turn moves tips a few m/s); its velocity is
    // scaled back to it so one bad step cannot pump energy into the next.
    // Rod and rope formulations; 0 disables the clamp.
    float maxSpeed = 50.f;          ///< m/s

    // Parallelism. Guides are partitioned into Bullet worlds of this many
    // strands (a fixed mapping, so results do not depend on the thread count).
    int strandsPerWorld = 16;
    int threads = 0;                ///< 0 = the ambient TBB limit

    /// Throws hp::Error naming the first setting out of range.
    void validate() const;
};

/// Drives all guides of a shot. Not thread-safe itself; parallel inside.
class GuideSolver {
  public:
    explicit GuideSolver(const GuideSettings& settings);
    ~GuideSolver();
    GuideSolver(const GuideSolver&) = delete;
    GuideSolver& operator=(const GuideSolver&) = delete;

    /// Creates the guides at `head.time`: one per root frame. The rest shape
    /// is `groom` (world-space vertices at head.time, segments + 1 per guide)
    /// or, when null, straight along each root normal. With `preload` the
    /// springs are pre-loaded so this shape is in equilibrium under gravity.
    void initialize(const std::vector<SurfaceFrame>& roots, const HeadPose& head,
                    const std::vector<std::vector<Vec3f>>* groom = nullptr);

    /// Advances one step to nextTime(). `roots` are the root frames at the end
    /// of the step (same order as initialize), `head` the head posed at the
    /// end of the step (head.time must be nextTime() within 1e-6 s; its collider
    /// may be null; its mesh is used only by the rigid formulation). A jump of
    /// the head transform or of a root beyond the teleport limits resets the
    /// guides to their rest shape at the new roots.
    const StepStats& step(const std::vector<SurfaceFrame>& roots, const HeadPose& head);

    /// Writes the guides at time() into `frame` (cleared first): positions,
    /// velocities, tapered radii, ids 0..N-1, guideCount = N.
    void write(StrandFrame& frame) const;
    /// Same at `time` in [time() - timeStep, time()]: positions interpolated
    /// between the last two steps, segment lengths restored exactly.
    void write(StrandFrame& frame, double time) const;

    /// Time of the state now: start time + steps · timeStep (no accumulated rounding).
    double time() const;
    /// Time the next step ends at: where to sample the head and the roots.
    double nextTime() const;
    size_t guideCount() const;
    const GuideSettings& settings() const;
    /// Statistics of the last step (all zero before the first).
    const StepStats& lastStats() const;
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
