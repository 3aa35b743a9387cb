#include "sim/solver/scene_cut.h"

#include <cmath>

namespace hp {

StepJump stepJump(const Eigen::Isometry3f& from, const Eigen::Isometry3f& to, float rootMove) {
    StepJump j;
    j.headMove = (to.translation() - from.translation()).norm();
    j.headTurn = Eigen::AngleAxisf(to.linear() * from.linear().transpose()).angle() * float(180.0 / M_PI);
    j.rootMove = rootMove;
    return j;
}

bool isCut(const StepJump& jump, float maxDistance, float maxAngle) {
    return jump.headMove > maxDistance || jump.rootMove > maxDistance || jump.headTurn > maxAngle;
}

bool continuesCut(const StepJump& jump, float maxDistance, float maxAngle) {
    return isCut(jump, 0.5f * maxDistance, 0.5f * maxAngle);
}

}  // namespace hp
