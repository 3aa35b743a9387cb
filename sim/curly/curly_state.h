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
#include "sim/solver/skeleton.h"

#include <memory>
#include <vector>

namespace hp::curly {

/// Rest shape, inputs and state of every guide, structure of arrays (the
/// state and root targets: solver::StrandState). Guide g's particle i is at
/// g * n + i, its edge j at g * (n - 1) + j.
struct CurlySet : solver::StrandState {
    CurlyWetSettings settings;
    StrandCoefficients coefficients;
    int n = 0;  ///< particles per guide (= vertices)

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

    size_t particle(size_t g, int i) const { return g * size_t(n) + size_t(i); }
    size_t edge(size_t g, int j) const { return g * size_t(n - 1) + size_t(j); }
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

/// What one Bullet step needs: the skeleton's substep (h, alpha, the head
/// at this Bullet step's end, its collider possibly null).
using SubstepContext = solver::Substep;

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
