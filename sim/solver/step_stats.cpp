#include "sim/solver/step_stats.h"

#include <algorithm>
#include <cstdio>

namespace hp {

void StepStats::accumulate(const StepStats& s) {
    maxLengthError = std::max(maxLengthError, s.maxLengthError);
    meanLengthError = std::max(meanLengthError, s.meanLengthError);
    penetrationCount = std::max(penetrationCount, s.penetrationCount);
    maxPenetration = std::max(maxPenetration, s.maxPenetration);
    kineticEnergy = s.kineticEnergy;
    nanCount += s.nanCount;
    if (firstNonFinite < 0) firstNonFinite = s.firstNonFinite;
    clampedCount += s.clampedCount;
    pinnedCount = std::max(pinnedCount, s.pinnedCount);
    strandContacts = std::max(strandContacts, s.strandContacts);
    maxHairDensity = std::max(maxHairDensity, s.maxHairDensity);
    volumePushed = std::max(volumePushed, s.volumePushed);
    meanSaturation = s.meanSaturation;
    meanCohesionNeighbours = s.meanCohesionNeighbours;
    adhesionCount = std::max(adhesionCount, s.adhesionCount);
    implicitFailures += s.implicitFailures;
    msPerStep = (msPerStep * double(steps) + s.msPerStep * double(s.steps)) / double(steps + s.steps);
    steps += s.steps;
    reset = reset || s.reset;
    cuts += s.cuts;
}

void StepStats::setCounters(const StepStats& c) {
    clampedCount = c.clampedCount;
    strandContacts = c.strandContacts;
    pinnedCount = c.pinnedCount;
    maxHairDensity = c.maxHairDensity;
    volumePushed = c.volumePushed;
    meanCohesionNeighbours = c.meanCohesionNeighbours;
    adhesionCount = c.adhesionCount;
    implicitFailures = c.implicitFailures;
}

std::string StepStats::json(int frame, double time) const {
    char buf[640];
    std::snprintf(buf, sizeof buf,
                  "{\"frame\": %d, \"time\": %.6f, \"max_length_error\": %.3e, \"mean_length_error\": %.3e, "
                  "\"penetrations\": %zu, \"max_penetration_m\": %.3e, \"kinetic_energy_j\": %.6e, "
                  "\"nan\": %zu, \"clamped\": %zu, \"pinned\": %zu, \"strand_contacts\": %zu, \"ms_per_step\": %.3f, "
                  "\"steps\": %zu, \"reset\": %s, \"cuts\": %zu}",
                  frame, time, maxLengthError, meanLengthError, penetrationCount, maxPenetration, kineticEnergy,
                  nanCount, clampedCount, pinnedCount, strandContacts, msPerStep, steps, reset ? "true" : "false", cuts);
    return buf;
}

}  // namespace hp
