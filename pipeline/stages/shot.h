// Runs a shot: resolves settings, builds the frame source and the enabled
// stages, and schedules frames with resume and per-frame failure handling.
#pragma once

#include "pipeline/scene/scene.h"
#include "pipeline/stages/stage.h"

#include <optional>
#include <set>

namespace hp {

/// What the command line adds to the scene.
struct RunOptions {
    std::optional<std::vector<int>> frames;  ///< --frames; default: the scene's
    std::filesystem::path outputDir;         ///< --out; default: scene's output.directory
    bool force = false;
    /// Stage names to run (e.g. {"preview"}); empty = every stage the scene enables.
    std::set<std::string> only;
    /// --jobs: frame-parallel stages run in this many processes at once
    /// (pipeline/batch/frame_jobs.h); 1 runs everything in this process.
    int jobs = 1;
    int chunk = 0;               ///< --chunk: frames per child process; 0 = automatic
    bool cacheOnly = false;      ///< --cache-only: ShotSettings::requireCache
    bool noReport = false;       ///< --no-report: not ShotSettings::wholeRunOutputs
    bool noOverlap = false;      ///< --no-overlap: not ShotSettings::overlap
    /// The command line's scene overrides (--set, --seed as seed=N) and
    /// --threads, so child processes can be given the same scene.
    std::vector<std::string> sets;
    int threads = 0;             ///< --threads; 0 = not given
    /// The scene file as given (relative to the current folder): outputs
    /// record the scene by this name, so children get it unchanged.
    std::filesystem::path sceneFile;
};

ShotSettings resolveShot(const Scene& scene, const RunOptions& options);

/// The frame source for a scene (head animation, simulation, followers).
std::unique_ptr<FrameSource> makeFrameSource(const Scene& scene, const ShotSettings& shot);

/// The stages the scene enables, filtered by `only`.
std::vector<StagePtr> makeStages(const Scene& scene, const ShotSettings& shot, const std::set<std::string>& only);

/// Result of a batch.
struct RunReport {
    size_t framesDone = 0;
    size_t outputsSkipped = 0;  ///< stage-frames skipped because their files existed
    std::vector<std::string> failures;  ///< "frame 12 preview: ..." per failed stage-frame
};

/// Runs `stages` over the shot's frames, then (shot.wholeRunOutputs) their
/// finish. Frame failures are collected, not thrown.
RunReport runFrames(FrameSource& source, std::vector<StagePtr>& stages, const ShotSettings& shot);

/// Calls each stage's finish (whole-run outputs), adding failures to `report`.
void finishStages(std::vector<StagePtr>& stages, const ShotSettings& shot, RunReport& report);

}  // namespace hp
