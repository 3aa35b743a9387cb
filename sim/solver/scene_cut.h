// Scene cuts: a clip that jumps to another shot (an edit, a camera cut, a
// re-posed character) moves the head, or a hair root, further in one
// simulation step than motion could. Dynamics across such a jump are
// meaningless (a strand would be flung at tens of m/s), so the solvers restart
// every strand at rest on the new pose instead (sim/guides/guides.h). The same test
// lets `hairpipe info` list the cuts of a clip before anything is simulated.
#pragma once

#include "sim/strands/strand.h"

#include <Eigen/Geometry>

namespace hp {

/// @brief How far the head and the roots moved over one step.
struct StepJump {
    float headMove = 0.f;  ///< translation of the head's rigid transform, m
    float headTurn = 0.f;  ///< rotation angle of the head's rigid transform, degrees
    float rootMove = 0.f;  ///< largest move of one root (or scalp vertex), m
};

/// @brief The jump from head pose `from` to `to` (rigid transforms, rest ->
/// world) with `rootMove` the largest root displacement over the step.
StepJump stepJump(const Eigen::Isometry3f& from, const Eigen::Isometry3f& to, float rootMove);

/// @brief True when `jump` is a scene cut: the head or a root moved more than
/// `maxDistance` metres, or the head turned more than `maxAngle` degrees.
bool isCut(const StepJump& jump, float maxDistance, float maxAngle);

/// @brief Whether the step after a cut step goes on with the same cut. A
/// file's sampler interpolates the jump between two keys linearly, so a jump
/// whose keys lie more than a step apart spreads over several steps: each
/// whole step inside it moves the same amount, the last one only what is
/// left of it. A step right after a cut continues it while it still moves
/// more than half the limits (isCut(jump, maxDistance / 2, maxAngle / 2));
/// a cut is one cut however many steps it spans.
bool continuesCut(const StepJump& jump, float maxDistance, float maxAngle);

}  // namespace hp
