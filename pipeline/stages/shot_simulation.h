// The sequential part of a shot: the head animation moves the scalp, the
// guide model (rigid chain or curly-wet) is stepped at its fixed time step,
// and the followers are rebuilt from the guides at every output frame.
//
// Time: the shot starts at the scene's first frame (frames.front() / fps),
// whatever subset of frames a run asks for. Guides step at a fixed step: the
// largest one not above the model's time step (simulation.time_step, 0.02 s
// as in Gomes 2024) that divides the frame interval, so every frame is a step's
// end (0.02 s itself at 25 or 50 fps; three steps of 13.9 ms at 24 fps).
// Writing a frame between two steps instead would interpolate each root
// along the chord of its arc, off the turning scalp. The solvers' damping
// does not depend on the step size.
#pragma once

#include "pipeline/groom/groom_settle.h"
#include "pipeline/head/head_setup.h"
#include "pipeline/batch/strand_cache.h"
#include "pipeline/scene/scene.h"
#include "sim/guides/guides.h"
#include "sim/strands/strand.h"

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>

namespace hp {

/// The largest step <= maxStep that divides the frame interval, so every
/// frame falls on a step and is written without interpolation (a root
/// interpolated between two steps cuts the chord of its arc on a turning head).
float frameAlignedStep(double fps, double maxStep);

/// What the simulation measured for one output frame.
struct SimFrameStats {
    int frame = 0;
    double time = 0.0;
    StepStats guides;             ///< folded over the guide steps since the previous frame
    size_t followerProjected = 0;  ///< follower vertices pushed out of the head
    /// Followers at the output frame (they are rebuilt per frame, not per step).
    struct FollowerFigures {
        double maxLengthError = 0, meanLengthError = 0;  ///< |segment length / rest - 1|
        size_t penetrationCount = 0;  ///< vertices left inside the head (signed distance < 0)
        double maxPenetration = 0;    ///< m
        size_t bent = 0, pinned = 0;  ///< pinch: vertices bent out, vertices pinned (FollowerStats)
    } followers;
    double headMs = 0;             ///< sampling the head animation (all steps)
    double followerMs = 0;         ///< rebuilding the followers
    double totalMs = 0;            ///< the whole frame
    size_t strands = 0, vertices = 0;
    double saturation = -1;        ///< curly-wet: mean saturation; -1 otherwise
    /// The groom's settling (first frame of a run only): seconds simulated
    /// (-1: none), final kinetic energy, whether it came to rest.
    double settleSeconds = -1, settleEnergy = 0;
    bool settleConverged = false, settleCached = false;
    /// One JSON object (a line of the run's statistics): the guides' figures
    /// at the top level (as before) and again under "guides", the followers'
    /// under "followers".
    std::string json() const;
};

class GuideModel;  // the guide solver behind one interface (shot_simulation.cpp)

class ShotSimulation {
  public:
    /// Loads the head, places the roots (or binds hair.groom.file), settles a
    /// procedural groom (hair.groom.settle, through `settleCache`), builds
    /// the guide model and the followers, and initialises everything at
    /// `startFrame`. Throws SceneError/AssetError for bad scene settings or assets.
    /// `rebuildOnly`: set up only to rebuild cached frames (rebuild()); says so in the log.
    ShotSimulation(const Scene& scene, double fps, int startFrame, const SettleCache& settleCache = {},
                   bool rebuildOnly = false);
    ~ShotSimulation();

    /// Advances to `frame` (>= frame()) and returns all strands there (guides
    /// first). Every clip frame between is produced on the way (the
    /// followers carry state from frame to frame). Throws FrameError if the simulation produced non-finite values.
    const StrandFrame& advanceTo(int frame);

    int frame() const { return frame_; }
    const HeadPose& pose() const { return pose_; }
    const SimFrameStats& stats() const { return stats_; }
    const HeadSetup& head() const { return head_; }
    size_t guideCount() const;
    size_t followerCount() const;
    /// Per strand of the current frame (guides, then followers): the head's
    /// parts it ignores (bit k: part k; sim/collision/mesh_parts.h), those
    /// its root lies inside at this frame's pose. Depth "inside" is measured
    /// with pose().collider->signedDistanceIgnoring(p, nullptr, mask). The
    /// guides (rod) collide so, with the masks of each step's pose, and so
    /// do the followers, with the masks of the frame's pose.
    const std::vector<uint32_t>& ignoredParts() const { return ignoredParts_; }

    /// False for models whose state cannot be restored bit for bit (the rigid
    /// formulation keeps orientations and warm-start impulses inside Bullet).
    bool canCheckpoint() const;
    /// Writes the complete simulation state at frame() (the solver state; the
    /// frame's strands themselves are the strand cache's job).
    void saveCheckpoint(const std::filesystem::path& file) const;
    /// Restores the state saved by saveCheckpoint at the frame whose strands
    /// are `strands` (read back from the strand cache, followers rebuilt) and
    /// whose cached guide record is `source` (none from a version 1 cache).
    /// Afterwards the simulation continues exactly as the run that saved it.
    void restoreCheckpoint(const std::filesystem::path& file, const StrandFrame& strands,
                           const std::optional<FollowerSource>& source = std::nullopt);

    /// The current frame as strand cache version 2 stores it: its guides and
    /// follower pins, and the frame before's when its velocities need it.
    /// None when the frame before is unknown (resumed from a version 1 cache).
    std::optional<CachedGuides> cachedGuides() const;

    /// @brief The whole strands of a frame cached as guides (version 2): the
    /// followers rebuilt on this simulation's groom from the cached guides,
    /// pins and the head's pose at the cached time, bit for bit what the
    /// simulation wrote (the frame before first, when the velocities need it,
    /// unless the previous call rebuilt it). Use a simulation that is not
    /// stepped. Throws AssetError naming `file` when the cache does not fit
    /// the scene (counts, or pins that come back differently).
    const StrandFrame& rebuild(const CachedGuides& cached, const std::string& file);

  private:
    void rebuildOne(const FollowerSource& source, bool previousInBuffer, const std::string& file);
    /// Steps the guides to `frame` and produces its strands (advanceTo's one frame).
    void stepTo(int frame);
    void produceFrame(double time);
    /// ignoredParts() at the pose `mesh`; hands the guides theirs.
    void updateIgnoredParts(const TriangleMesh& mesh);
    /// The followers' block of ignoredParts() (null on a head of one part).
    const uint32_t* followerIgnoredParts() const;
    /// The guides' rest shape at t0: imported, combed or straight, settled.
    void initializeGuides(const GuideSettings& settings, const struct ImportedGroom* imported,
                          const SettleCache& settleCache);

    const Scene& scene_;
    double fps_;
    int frame_;
    std::vector<int> clip_;  ///< the scene's frames (a copy: callers may pass a temporary scene)
    HeadSetup head_;
    GroomRoots roots_;
    std::unique_ptr<GuideModel> model_;
    std::unique_ptr<class Followers> followers_;
    std::vector<SurfaceFrame> guideFrames_, followerFrames_;
    HeadPose pose_;
    StrandFrame strands_;
    SimFrameStats stats_;
    StepStats pending_;  ///< steps since the last output frame
    double pendingHeadMs_ = 0;
    size_t pendingSteps_ = 0;
    std::vector<uint32_t> ignoredParts_;  ///< ignoredParts()
    SettledGroom settled_;  ///< the settling's report (strands moved into the model)
    bool settleRan_ = false;
    std::optional<FollowerSource> source_, previousSource_;  ///< cachedGuides()
    std::optional<std::pair<int, double>> rebuilt_;          ///< frame and time strands_ was rebuilt at
};

}  // namespace hp
