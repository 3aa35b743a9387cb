// The second lane of the frame stages: the work of frame N that needs neither
// the GL context (bound to the main thread) nor the machine to itself (the
// VDB, the compare) runs on a worker thread while the main thread reads frame
// N+1 and previews it, so the cores the preview leaves idle (its
// single-threaded set-up, readback and image encoding) do the VDB instead.
#pragma once

#include "sim/strands/head.h"
#include "sim/strands/strand.h"
#include "pipeline/stages/stage.h"

#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace hp {

/// What a stage on the lane reads of its frame: a copy of the strands and
/// the head, since the source reuses its buffers for the next frame. Stages
/// that overlap read nothing else of FrameData (simulation statistics and
/// the guide record belong to the sim stage, which stays on the main lane).
struct LaneFrame {
    explicit LaneFrame(const FrameData& source);
    LaneFrame(const LaneFrame&) = delete;
    LaneFrame& operator=(const LaneFrame&) = delete;
    StrandFrame strands;
    HeadPose head;
    FrameData data;  ///< points into this copy
};

/// One worker thread running posted jobs in order, at most one at a time and
/// one ahead of the caller: post() waits for the previous job, so two frames
/// are in memory at most. A job's exception other than the ones it handles
/// itself is rethrown by the next post() or drain().
class OverlapLane {
  public:
    OverlapLane();
    ~OverlapLane();  ///< waits for the running job, then ends the thread
    OverlapLane(const OverlapLane&) = delete;
    OverlapLane& operator=(const OverlapLane&) = delete;

    void post(std::function<void()> job);
    /// Returns once every posted job has run.
    void drain();

  private:
    void loop();
    void waitIdle(std::unique_lock<std::mutex>& lock);
    std::mutex mutex_;
    std::condition_variable changed_;
    std::function<void()> job_;  ///< empty: idle
    std::exception_ptr error_;
    bool stop_ = false;
    std::thread thread_;  ///< last: started once the members above exist
};

}  // namespace hp
