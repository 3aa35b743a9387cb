// Statistics of a strand solver's step, one type for every strand model
// (sim/guides/guides.h, sim/curly/curly_wet.h): what the skeleton measures
// for all of them, and the counters a model fills in for its own kernels
// (zero where a model has no such kernel).
#pragma once

#include <cstddef>
#include <string>

namespace hp {

/// @brief Measurements of one step (or accumulated over many: see accumulate()).
struct StepStats {
    // Measured on every model's state at the end of the step.
    double maxLengthError = 0;      ///< max |segment length / rest - 1|
    double meanLengthError = 0;     ///< mean |segment length / rest - 1|
    size_t penetrationCount = 0;    ///< free vertices inside the head (signed distance < 0)
    double maxPenetration = 0;      ///< deepest vertex below the head surface, m (0 = none)
    double kineticEnergy = 0;       ///< J, end of step
    size_t nanCount = 0;            ///< non-finite vertex positions or velocities
    long firstNonFinite = -1;       ///< lowest strand index with a non-finite value (-1: none)
    double msPerStep = 0;           ///< wall-clock milliseconds of step()
    size_t cuts = 0;                ///< scene cuts that began in the step(s): one per cut, however many steps it spans
    bool reset = false;             ///< a teleport / scene cut reset the strands this step

    // Guides (sim/guides/guides.h).
    size_t clampedCount = 0;        ///< vertex velocities scaled back to maxSpeed
    size_t strandContacts = 0;      ///< strand-strand contacts resolved in the step
    size_t pinnedCount = 0;         ///< rod: vertices pinned (no place outside the head at their length)
    double maxHairDensity = 0;      ///< hair-hair grid: densest node in the step, hairs per cm² (sim/volume/hair_grid.h)
    size_t volumePushed = 0;        ///< hair-hair grid: vertex pushes of the volume step in the step (all substeps)

    // Curly and wet guides (sim/curly/curly_wet.h).
    double meanSaturation = 0;      ///< mean σ over the free particles
    double meanCohesionNeighbours = 0; ///< mean other-strand neighbours within the cohesion radius
    size_t adhesionCount = 0;       ///< particles held by adhesion in the last Bullet step
    /// Strand-substeps whose linearly implicit spring system was not finite:
    /// those strands moved under gravity and constraints alone for that
    /// substep (their seed forces were skipped). Non-zero means the settings
    /// are too stiff for the step; the pipeline warns.
    size_t implicitFailures = 0;

    size_t steps = 1;               ///< steps folded in (for the running mean of msPerStep)

    /// @brief Folds `s` into running maxima; sums of the failure counts
    /// (non-finite values, clamps, implicit failures); the last value of the
    /// state's measures (kinetic energy, saturation, neighbours); the mean of ms.
    void accumulate(const StepStats& s);
    /// @brief Copies the model's counters (the fields after `reset`) from `c`.
    void setCounters(const StepStats& c);
    /// @brief One JSON object on one line (for a per-frame statistics file, JSON lines).
    std::string json(int frame, double time) const;
};

}  // namespace hp
