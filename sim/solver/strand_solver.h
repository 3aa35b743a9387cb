// The public face every strand model's solver shares (GuideSolver in
// sim/guides/guides.h, CurlyWetSolver in sim/curly/curly_wet.h): stepping to
// the next fixed time, the frames written between two steps, the clock and
// the statistics. The work is the solver skeleton's (sim/solver/skeleton.h,
// internal to hp_sim); a model adds its initialisation, settings and
// checkpoints. Plain C++ and Eigen.
#pragma once

#include "sim/solver/step_stats.h"
#include "sim/strands/head.h"
#include "sim/strands/strand.h"

#include <vector>

namespace hp {

namespace solver {
class Skeleton;
}

/// @brief A strand model's solver, as every stage drives it. Not thread-safe
/// itself; parallel inside.
class StrandSolver {
  public:
    StrandSolver(const StrandSolver&) = delete;
    StrandSolver& operator=(const StrandSolver&) = delete;

    /// @brief Advances one step to nextTime().
    /// @param roots  the root frames at the end of the step (same order as initialize)
    /// @param head  the head posed at the end of the step: head.time must be
    ///   nextTime() within 1e-6 s; its collider may be null (no head contact)
    /// A jump of the head transform or of a root beyond the teleport limits
    /// (a scene cut) resets the strands to their rest shape at the new roots.
    /// Throws hp::Error before initialize or on a root count or time that does not match.
    const StepStats& step(const std::vector<SurfaceFrame>& roots, const HeadPose& head);

    /// @brief Writes the strands at time() into `frame` (cleared first):
    /// positions, velocities, tapered radii, ids 0..N-1, guideCount = N.
    void write(StrandFrame& frame) const;
    /// @brief The same at `time` in [time() - timeStep, time()]: positions and
    /// velocities interpolated between the last two steps, segment lengths
    /// restored (by the model: rest lengths for the guides, interpolated
    /// lengths for the curly guides). Throws hp::Error outside that span.
    void write(StrandFrame& frame, double time) const;

    /// @brief Time of the state now: start time + steps · timeStep (no accumulated rounding).
    double time() const;
    /// @brief Time the next step ends at: where to sample the head and the roots.
    double nextTime() const;
    /// @brief Strands simulated (one per root frame given to initialize).
    size_t guideCount() const;
    /// @brief Statistics of the last step (all zero before the first).
    const StepStats& lastStats() const;

  protected:
    StrandSolver() = default;
    ~StrandSolver() = default;
    /// The model's skeleton, set by the derived solver's constructor.
    solver::Skeleton* skeleton_ = nullptr;
};

}  // namespace hp
