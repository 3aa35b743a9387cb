// Runs a shot: resolves settings, builds the frame source and the enabled
// stages, and schedules frames with resume and per-frame failure handling.
#pragma once

#include "pipeline/scene.h"
#include "pipeline/stage.h"

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

/// Runs `stages` over the shot's frames. Frame failures are collected, not thrown.
RunReport runFrames(FrameSource& source, std::vector<StagePtr>& stages, const ShotSettings& shot);

}  // namespace hp
