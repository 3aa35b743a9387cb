// What a shot's outputs say about its progress: which stage-frames are done
// (all their files exist), which folders they live in, and the temporaries a
// killed run left there. Shared by the scheduler's commands, `--jobs` and
// `hairpipe farm status`, which judge progress from files alone.
#pragma once

#include "pipeline/stages/stage.h"

#include <set>

namespace hp {

/// Progress of one stage over a list of frames.
struct StageProgress {
    std::string stage;
    std::vector<int> frames;   ///< frames the stage runs on (its <stage>.frames subset)
    std::vector<int> missing;  ///< of those, frames with an output missing (or empty)
    size_t done() const { return frames.size() - missing.size(); }
};

/// Per stage, the frames it covers and those not yet written.
std::vector<StageProgress> stageProgress(const std::vector<StagePtr>& stages, const std::vector<int>& frames);

/// Frames on which some stage still has work: an output missing, or any
/// output at all when `force`.
std::vector<int> framesWithWork(const std::vector<StagePtr>& stages, const std::vector<int>& frames, bool force);

/// The folders the stages write into over `frames`.
std::set<std::filesystem::path> outputFolders(const std::vector<StagePtr>& stages, const std::vector<int>& frames);

/// Removes temporaries left in the stages' folders (and extra `folders`) by
/// killed runs on this host (see removeStaleTemporaries) and says so.
void cleanStaleTemporaries(const std::vector<StagePtr>& stages, const std::vector<int>& frames,
                           std::set<std::filesystem::path> folders = {});

/// Splits `frames` (sorted) into consecutive runs of at most `size` frames.
std::vector<std::vector<int>> splitFrames(const std::vector<int>& frames, size_t size);

}  // namespace hp
