#include "sim/solver/strand_solver.h"

#include "sim/solver/skeleton.h"

namespace hp {

const StepStats& StrandSolver::step(const std::vector<SurfaceFrame>& roots, const HeadPose& head) {
    return skeleton_->step(roots, head);
}
void StrandSolver::write(StrandFrame& frame) const { skeleton_->write(frame, skeleton_->time()); }
void StrandSolver::write(StrandFrame& frame, double time) const { skeleton_->write(frame, time); }
double StrandSolver::time() const { return skeleton_->time(); }
double StrandSolver::nextTime() const { return skeleton_->nextTime(); }
size_t StrandSolver::guideCount() const { return skeleton_->count(); }
const StepStats& StrandSolver::lastStats() const { return skeleton_->lastStats(); }

}  // namespace hp
