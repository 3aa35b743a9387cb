// The scene cuts of a shot's clip, found without simulating: the same test
// the guide solver applies at each step (sim/solver/scene_cut.h), on the head's
// rigid motion and its scalp vertices. `hairpipe info` lists them.
#pragma once

#include "pipeline/head/head_setup.h"
#include "pipeline/scene/scene.h"
#include "sim/solver/scene_cut.h"

#include <vector>

namespace hp {

/// @brief One scene cut of the shot: one step, or the steps a jump the file
/// interpolates between two keys spreads over (scene_cut.h continuesCut).
struct ClipCut {
    double time = 0.0;   ///< shot time at the end of its last step (the first time of the new shot), s
    double start = 0.0;  ///< shot time at the end of its first step, s
    int steps = 1;       ///< steps it spans
    StepJump jump;       ///< what moved from the step before it to its end
};

/// @brief Steps the shot's head from `startTime` to `endTime` at `step`
/// seconds (the simulation's frame-aligned step) and returns every cut the
/// guide solver finds: a step whose jump exceeds simulation.cut_distance /
/// cut_angle, with the steps after it that continue it. The root move is
/// measured on the scalp's vertices (a root moves no farther than the
/// corners of its triangle).
std::vector<ClipCut> findClipCuts(const Scene& scene, const HeadSetup& head, double startTime, double endTime,
                                  double step);

}  // namespace hp
