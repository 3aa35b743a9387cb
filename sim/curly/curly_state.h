// Internal to hp_sim (not included outside sim/): the curly guides' shared
// state and the Bullet worlds that advance them.
//
// The solver (sim/curly/curly_wet.cpp) partitions the guides into groups of
// `strandsPerWorld` consecutive guides, each group owning one Bullet world
// (sim/curly/curly_world.cpp). A group writes only its own guides' slice of
// CurlySet's arrays and reads the shared, per-step inputs (saturation,
// cohesion targets), so groups run in parallel and the result does not
// depend on the thread count.
#pragma once

#include "sim/curly/curly_dynamics.h"
#include "sim/curly/curly_wet.h"

#include <memory>
#include <vector>

namespace hp::curly {

/// Rest shape, inputs and state of every guide, structure of arrays. Guide
/// g's particle i is at g * n + i, its edge j at g * (n - 1) + j.
struct CurlySet {
    CurlyWetSettings settings;
    StrandCoefficients coefficients;
    size_t count = 0;
    int n = 0;  ///< particles per guide

    // Rest (fixed after initialize).
    std::vector<Vec3f> restLocal;     ///< per particle: rest shape in root-local coordinates
    std::vector<Vec3f> helix;         ///< per particle: the wet helix (eq. 6), root-local
    std::vector<float> edgeLength;    ///< per edge
    std::vector<Vec3f> bendTarget;    ///< per edge: t̄_i
    std::vector<float> coreLength;    ///< per edge: |b̄_i|
    std::vector<float> mass;          ///< per particle (the root's is unused: kinematic)

    // Inputs of the current step.
    std::vector<float> sigma;             ///< per particle saturation
    bool wet = false;                     ///< some particle has σ > 0 (and wet effects are on)
    std::vector<CohesionTarget> cohesion; ///< per particle, from the previous step's positions (empty: none)

    // State at the end of the last step and of the step before.
    std::vector<Vec3f> x, v, xPrev, vPrev;

    // Root targets of the current step: start (= end of the previous) and end.
    std::vector<Vec3f> rootPos0, rootPos1;
    std::vector<Quatf> rootRot0, rootRot1;

    size_t particle(size_t g, int i) const { return g * size_t(n) + size_t(i); }
    size_t edge(size_t g, int j) const { return g * size_t(n - 1) + size_t(j); }
    Vec3f rootPosition(size_t g, float a) const { return (1.f - a) * rootPos0[g] + a * rootPos1[g]; }
    Quatf rootRotation(size_t g, float a) const { return rootRot0[g].slerp(a, rootRot1[g]); }
    StrandRest rest(size_t g) const {
        StrandRest r;
        r.edgeLength = &edgeLength[edge(g, 0)];
        r.bendTarget = &bendTarget[edge(g, 0)];
        r.coreLength = &coreLength[edge(g, 0)];
        r.helix = &helix[particle(g, 0)];
        r.mass = &mass[particle(g, 0)];
        return r;
    }
    /// Puts guide g at rest (zero velocity) on its end-of-step root.
    void resetGuide(size_t g);
};

/// What one Bullet step needs.
struct SubstepContext {
    float h = 0.02f;        ///< Bullet step, s
    float alpha = 1.f;      ///< fraction of the solver step at this Bullet step's end
    ObstacleQuery head;     ///< the head at this Bullet step's end (collider may be null)
};

/// Counters of one group's Bullet step (summed in group order).
struct GroupCounters {
    size_t adhesion = 0;
    size_t failed = 0;  ///< strands whose implicit system was not finite
};

/// One Bullet world advancing guides [begin, end) of a CurlySet.
class CurlyWorld {
  public:
    virtual ~CurlyWorld() = default;
    /// One Bullet step of all its guides: reads and writes set.x / set.v.
    virtual GroupCounters substep(const SubstepContext& ctx) = 0;
    virtual size_t begin() const = 0;
    virtual size_t end() const = 0;
};

std::unique_ptr<CurlyWorld> makeCurlyWorld(CurlySet& set, size_t begin, size_t end);

}  // namespace hp::curly
