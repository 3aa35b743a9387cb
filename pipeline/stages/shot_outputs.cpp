#include "pipeline/stages/shot_outputs.h"

#include "core/log.h"
#include "pipeline/batch/output.h"

#include <algorithm>

namespace fs = std::filesystem;

namespace hp {

std::vector<StageProgress> stageProgress(const std::vector<StagePtr>& stages, const std::vector<int>& frames) {
    std::vector<StageProgress> out;
    for (const StagePtr& stage : stages) {
        StageProgress p;
        p.stage = stage->name();
        for (int frame : frames) {
            const std::vector<fs::path> outputs = stage->outputs(frame);
            if (outputs.empty()) continue;  // not one of the stage's frames
            p.frames.push_back(frame);
            if (!allExist(outputs)) p.missing.push_back(frame);
        }
        out.push_back(std::move(p));
    }
    return out;
}

std::vector<int> framesWithWork(const std::vector<StagePtr>& stages, const std::vector<int>& frames, bool force) {
    std::vector<int> out;
    for (int frame : frames)
        for (const StagePtr& stage : stages) {
            const std::vector<fs::path> outputs = stage->outputs(frame);
            if (!outputs.empty() && (force || !allExist(outputs))) {
                out.push_back(frame);
                break;
            }
        }
    return out;
}

std::set<fs::path> outputFolders(const std::vector<StagePtr>& stages, const std::vector<int>& frames) {
    std::set<fs::path> folders;
    for (const StagePtr& stage : stages)
        for (int frame : frames)
            for (const fs::path& p : stage->outputs(frame)) folders.insert(p.parent_path());
    return folders;
}

void cleanStaleTemporaries(const std::vector<StagePtr>& stages, const std::vector<int>& frames,
                           std::set<fs::path> folders) {
    const std::set<fs::path> more = outputFolders(stages, frames);
    folders.insert(more.begin(), more.end());
    if (const size_t n = removeStaleTemporaries(folders))
        logInfo("removed ", n, " temporary file", n == 1 ? "" : "s", " left by an interrupted run");
}

std::vector<std::vector<int>> splitFrames(const std::vector<int>& frames, size_t size) {
    std::vector<std::vector<int>> chunks;
    size = std::max<size_t>(size, 1);
    for (size_t i = 0; i < frames.size(); i += size)
        chunks.emplace_back(frames.begin() + long(i), frames.begin() + long(std::min(frames.size(), i + size)));
    return chunks;
}

}  // namespace hp
