// The per-frame stages of a shot (preview, reference, VDB, compare, ...).
//
// Simulation is sequential; everything after it is independent per frame. A
// FrameSource yields each requested frame's data in increasing frame order
// (it runs the sequential part as needed); FrameStages turn that data into
// files. The scheduler (pipeline/stages/shot.h) skips a stage for a frame when all
// its outputs exist, unless --force, so an interrupted batch resumes.
#pragma once

#include "sim/strands/head.h"
#include "sim/strands/strand.h"

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace hp {

class Scene;
struct SimFrameStats;
struct CachedGuides;

/// What the stages of one frame read. Pointers are null for parts the shot
/// does not have (e.g. no head, no hair).
struct FrameData {
    int frame = 0;
    double time = 0.0;  ///< seconds: frame / fps
    const HeadPose* head = nullptr;
    const StrandFrame* strands = nullptr;
    /// Set when the strands were simulated for this frame (not read from the
    /// strand cache): what the simulation measured.
    const SimFrameStats* simulation = nullptr;
    /// The frame's guides and follower pins (strand cache version 2): what the
    /// sim stage writes with cache.followers: rebuild. Null when unknown.
    const CachedGuides* guides = nullptr;
    /// Side outputs of the source that could not be written (a checkpoint on
    /// a full disk). The frame counts as failed, but its data is sound, so
    /// the stages still run.
    std::vector<std::string> failures;
};

/// Settings fixed for a whole run: resolved from the scene and the command line.
struct ShotSettings {
    std::filesystem::path outputDir;  ///< absolute
    std::vector<int> frames;          ///< the frames to produce, sorted
    double fps = 24.0;
    long seed = 1;
    bool force = false;               ///< rewrite existing outputs
    /// The run writes the strand cache (the "sim" stage runs), so the
    /// simulation also writes its checkpoints for resuming.
    bool writesCache = false;
    /// Strands come only from the strand cache: a frame without its cache
    /// file fails instead of being simulated (chunks of a parallel or farm
    /// run, which must not each re-simulate the shot).
    bool requireCache = false;
    /// Call each stage's finish() at the end (whole-run outputs such as the
    /// compare report); false for one chunk of a larger run, whose last step
    /// writes them once over all frames.
    bool wholeRunOutputs = true;
    /// Run the stages that allow it (FrameStage::overlaps) on a second lane,
    /// beside the next frame's work (pipeline/stages/overlap_lane.h); false
    /// runs every stage in turn (`run --no-overlap`). The outputs are the same.
    bool overlap = true;
};

class FrameSource {
  public:
    virtual ~FrameSource() = default;
    /// Data for `frame`; called with increasing frames. The returned data
    /// stays valid until the next call.
    virtual FrameData get(int frame) = 0;
};

class FrameStage {
  public:
    virtual ~FrameStage() = default;
    virtual std::string name() const = 0;
    /// Absolute paths this stage writes for `frame`.
    virtual std::vector<std::filesystem::path> outputs(int frame) const = 0;
    /// Whether the stage reads FrameData (false for stages that only read
    /// other stages' files, such as compare), so the source can be skipped.
    virtual bool needsFrameData() const { return true; }
    /// Whether the stage may run on the overlap lane after its frame's other
    /// stages, beside the next frame's: it reads of FrameData only the strands
    /// and head (LaneFrame), holds no thread-bound state (a GL context), and
    /// no later stage of its frame reads its files.
    virtual bool overlaps() const { return false; }
    /// Whether the stage needs the machine to itself: the lane is drained
    /// before it starts (a reference whose time limit counts wall time would
    /// otherwise lose samples to the lane's work).
    virtual bool exclusive() const { return false; }
    /// Produces the outputs of one frame, each through writeAtomically.
    /// Throws hp::Error on failure; the scheduler records it and goes on.
    virtual void run(const FrameData& data) = 0;
    /// Failures of work the stage left running after run() returned (a
    /// frame's file still being written while the next frame is worked on),
    /// each as "frame N <stage>: what went wrong"; with `wait`, first waits
    /// for that work to end. The scheduler calls it after each run(), without
    /// waiting, and once after the last frame, waiting (before finish()), and
    /// records each failure like a failed frame (exit code 2).
    virtual std::vector<std::string> collectFailures(bool wait) { return {}; }
    /// Called once after the last frame of a run (also when frames failed or
    /// were skipped as already done), for outputs that cover the whole run,
    /// such as the compare stage's report. Throws hp::Error on failure; the
    /// scheduler records it like a failed frame (exit code 2).
    virtual void finish(const ShotSettings& shot) {}
};

using StagePtr = std::unique_ptr<FrameStage>;

}  // namespace hp
