// The solver skeleton every strand model plugs into (internal to hp_sim; the
// public face is sim/solver/strand_solver.h):
// fixed steps timed as start + steps·dt, the head interpolated between two
// poses over a step's substeps, scene cuts, the frames written (interpolated
// between the last two steps), statistics and checkpoints of the clock and
// the shared state. A model (the guides' GuideSolver, the curly guides'
// CurlyWetSolver) keeps only its own step: it implements StrandModel and
// holds a Skeleton that calls it.
//
// One step of Skeleton::step, for every model:
//  1. the roots' end-of-step targets; the state so far kept as the step before;
//  2. a scene cut (the head or a root jumps beyond the teleport limits in
//     one step, or the step after a cut still jumps beyond half of them:
//     one cut spread over several steps, sim/solver/scene_cut.h) resets the
//     strands to rest on the new roots; otherwise the model advances through `substeps` substeps,
//     each seeing the head interpolated (slerp, lerp) to the substep's end;
//  3. the model's end of step (guards, counters), the roots' targets and the
//     clock advance, the state is measured.
#pragma once

#include "sim/solver/head_contact.h"
#include "sim/solver/scene_cut.h"
#include "sim/solver/step_settings.h"
#include "sim/solver/step_stats.h"
#include "sim/solver/strand_state.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <memory>
#include <string>

namespace hp::solver {

/// @brief One substep of a solver step, as every model sees it.
struct Substep {
    float h = 0.02f;      ///< substep length, s
    float alpha = 1.f;    ///< fraction of the solver step at the substep's end
    Eigen::Isometry3f headTransform = Eigen::Isometry3f::Identity();  ///< rigid head pose at the substep's end
    strand::HeadQuery head;  ///< the head collider as seen at the substep's end (collider may be null)
};

/// @brief What a strand model supplies to the skeleton: its own step.
class StrandModel {
  public:
    virtual ~StrandModel() = default;
    /// @brief Before a step's substeps (or its reset), with the head at the step's end.
    virtual void beginStep(const HeadPose& head, bool cut) = 0;
    /// @brief A scene cut: every strand at rest on the end-of-step roots (state.x, state.v).
    virtual void resetToRest(const HeadPose& head) = 0;
    /// @brief One substep of every strand: reads and writes state.x / state.v.
    virtual void substep(const Substep& sub) = 0;
    /// @brief After the substeps (or the reset): guards, and the model's
    /// counters of the step written into `counters` (StepStats::setCounters).
    virtual void endStep(bool cut, StepStats& counters) = 0;
    /// @brief Statistics of the current state (the measured fields of StepStats).
    virtual StepStats measure(const Collider* collider) const = 0;
    /// @brief Strand g's positions x (state.vertices of them), interpolated at
    /// fraction a < 1 between the last two steps: restores its segment lengths.
    virtual void restoreLengths(size_t g, float a, Vec3f* x) const = 0;
};

/// @brief Runs a StrandModel's steps over a StrandState. Not thread-safe itself.
class Skeleton {
  public:
    /// @param name  for messages: "guide solver", "curly/wet solver"
    Skeleton(StrandModel& model, StrandState& state, std::string name, const StepSettings& settings);

    /// @brief Starts the clock at head.time with the head's pose (after the model set its state up).
    void start(const HeadPose& head);
    /// @brief Throws hp::Error unless started (`what`: the call, for the message).
    void requireStarted(const char* what) const;

    /// @brief One step to nextTime(); see the file comment. Throws hp::Error
    /// on a root count or head time that does not match.
    const StepStats& step(const std::vector<SurfaceFrame>& roots, const HeadPose& head);

    /// @brief Writes the strands at `time` in [time() - timeStep, time()] into
    /// `frame` (cleared first): positions and velocities interpolated between
    /// the last two steps (lengths restored by the model), tapered radii, ids
    /// 0..N-1, guideCount = N.
    void write(StrandFrame& frame, double time) const;

    /// Time of the state now: start time + steps · timeStep (no accumulated rounding).
    double time() const { return time_; }
    /// Time the next step ends at: where to sample the head and the roots.
    double nextTime() const { return startTime_ + double(steps_ + 1) * double(settings_.timeStep); }
    const StepStats& lastStats() const { return last_; }
    size_t count() const { return state_.count; }

    /// @brief Appends the clock (time, previous time, start time, steps, head pose) to a checkpoint.
    void saveClock(BlobWriter& w) const;
    /// @brief Reads what saveClock() wrote.
    void restoreClock(BlobReader& r);

    /// @brief Runs f(begin, end) over [0, count) in chunks of `grain`, in the
    /// solver's own TBB arena when it has a thread count.
    template <typename F>
    void parallel(size_t count, size_t grain, F&& f) const {
        auto loop = [&] {
            tbb::parallel_for(
                tbb::blocked_range<size_t>(0, count, grain),
                [&](const tbb::blocked_range<size_t>& r) { f(r.begin(), r.end()); }, tbb::simple_partitioner());
        };
        if (arena_) arena_->execute(loop);
        else loop();
    }

  private:
    StrandModel& model_;
    StrandState& state_;
    std::string name_;
    StepSettings settings_;
    std::shared_ptr<tbb::task_arena> arena_;
    double time_ = 0, prevTime_ = 0;
    double startTime_ = 0;  ///< head.time at start
    long steps_ = 0;        ///< steps since; time = startTime + steps·timeStep (no drift)
    Eigen::Isometry3f headTransform_ = Eigen::Isometry3f::Identity();
    bool inCut_ = false;  ///< the last step was (part of) a scene cut
    StepStats last_;
    bool started_ = false;
};

}  // namespace hp::solver
