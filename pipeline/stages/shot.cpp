#include "pipeline/stages/shot.h"

#include "core/log.h"
#include "pipeline/batch/progress.h"
#include "pipeline/batch/output.h"
#include "pipeline/stages/overlap_lane.h"
#include "pipeline/stages/stages.h"

#include <sys/resource.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <memory>
#include <mutex>
#include <optional>

namespace fs = std::filesystem;

namespace hp {

ShotSettings resolveShot(const Scene& scene, const RunOptions& options) {
    ShotSettings shot;
    shot.fps = scene.number("fps");
    shot.seed = scene.integer("seed");
    shot.force = options.force;
    shot.frames = options.frames ? *options.frames : scene.frames("frames");
    shot.requireCache = options.cacheOnly;
    shot.wholeRunOutputs = !options.noReport;
    shot.overlap = !options.noOverlap;
    fs::path out = options.outputDir;
    if (out.empty()) {
        const std::string& configured = scene.text("output.directory");
        out = configured.empty() ? fs::path("out") / fs::path(scene.name()).stem() : fs::path(configured);
        // A directory named in the scene is relative to the scene's folder.
        if (!configured.empty() && out.is_relative()) out = scene.directory() / out;
    }
    shot.outputDir = fs::absolute(out).lexically_normal();
    return shot;
}

namespace {

/// Peak resident set of this process so far, MB (getrusage: ru_maxrss is KiB
/// on Linux). Logged per stage with --verbose: the peak only grows, so the
/// stage that raised it is the one that needed the memory (docs/hardening.md).
double peakResidentMb() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_maxrss) / 1024.0;
}

/// Process CPU time, all threads (llvmpipe's, TBB's): with the wall time it
/// says how many cores a stage kept busy (-v logs both per stage and frame).
double processCpuSeconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

/// Wall and CPU seconds of a stretch of work, for -v.
struct StageClock {
    std::chrono::steady_clock::time_point wall = std::chrono::steady_clock::now();
    double cpu = processCpuSeconds();
    std::string text() const {
        const double w = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall).count();
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.2f s (%.2f CPU-s)", w, processCpuSeconds() - cpu);
        return buf;
    }
};

/// A failure is logged when it happens and listed again at the end of the run.
void recordFailure(RunReport& report, const std::string& what) {
    report.failures.push_back(what);
    logError(what);
}

}  // namespace

RunReport runFrames(FrameSource& source, std::vector<StagePtr>& stages, const ShotSettings& shot) {
    RunReport report;
    if (stages.empty()) {
        logWarning("nothing to do: the scene enables no output stage");
        return report;
    }
    std::mutex reportMutex;  // the overlap lane records its failures too
    auto fail = [&](const std::string& what) {
        const std::lock_guard<std::mutex> lock(reportMutex);
        recordFailure(report, what);
    };
    auto runStage = [&](FrameStage& stage, const FrameData& data) {
        try {
            const StageClock clock;
            stage.run(data);
            logVerbose("frame ", data.frame, " ", stage.name(), ": ", clock.text(), ", peak RSS ",
                       int(peakResidentMb()), " MB");
        } catch (const Error& e) {
            fail(cat("frame ", data.frame, " ", stage.name(), ": ", e.what()));
        }
        // Earlier frames' work the stage finished since (a file written beside this frame).
        for (const std::string& failure : stage.collectFailures(false)) fail(failure);
    };
    // One core (--threads 1, or a --jobs child given one) gets no second lane.
    const bool overlap = shot.overlap &&
                         tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism) > 1 &&
                         std::any_of(stages.begin(), stages.end(), [](const StagePtr& s) { return s->overlaps(); });
    std::optional<OverlapLane> lane;  // destroyed (joined) before the locals its jobs use
    if (overlap) lane.emplace();
    Progress progress("frames", shot.frames.size());
    for (int frame : shot.frames) {
        // Decide first which stages still have work, so a fully written frame
        // costs no simulation or head evaluation when the source allows it.
        std::vector<FrameStage*> todo;
        for (StagePtr& stage : stages) {
            const std::vector<std::filesystem::path> outputs = stage->outputs(frame);
            if (outputs.empty()) continue;  // the stage skips this frame (its <stage>.frames)
            if (!shot.force && allExist(outputs)) {
                ++report.outputsSkipped;
                logVerbose("frame ", frame, " ", stage->name(), ": outputs exist, skipped");
            } else {
                todo.push_back(stage.get());
            }
        }
        const bool needsData = std::any_of(todo.begin(), todo.end(), [](FrameStage* s) { return s->needsFrameData(); });
        FrameData data;
        data.frame = frame;
        data.time = frame / shot.fps;
        bool sourceFailed = false;
        if (needsData) {
            try {
                const StageClock clock;
                data = source.get(frame);
                for (const std::string& failure : data.failures) fail(cat("frame ", frame, ": ", failure));
                logVerbose("frame ", frame, " data (simulation or cache): ", clock.text(), ", peak RSS ",
                           int(peakResidentMb()), " MB");
            } catch (const FrameError& e) {
                // Without the frame's data no data stage can run; later frames may still work.
                fail(cat("frame ", frame, ": ", e.what()));
                sourceFailed = true;
            }
            // Any other error (a scene key, an unreadable head, a scalp that
            // grows no hair) would fail every frame the same way: it ends the
            // run with exit code 1, as a scene error found at load would.
        }
        // The main lane runs the frame's stages in order; those that overlap
        // run after them on the lane, beside the next frame's source and preview.
        std::vector<FrameStage*> later;
        for (FrameStage* stage : todo) {
            if (sourceFailed && stage->needsFrameData()) continue;
            if (lane && stage->overlaps()) {
                later.push_back(stage);
                continue;
            }
            if (lane && stage->exclusive()) lane->drain();
            runStage(*stage, data);
        }
        if (!later.empty()) {
            // A copy: the source reuses its buffers for the next frame.
            auto copy = std::make_shared<const LaneFrame>(data);
            lane->post([copy, later, &runStage] {
                for (FrameStage* stage : later) runStage(*stage, copy->data);
            });
        }
        ++report.framesDone;
        progress.advance(cat("frame ", frame));
    }
    if (lane) lane->drain();
    // Work the stages left running (the last frames' files) ends before the run does.
    for (StagePtr& stage : stages)
        for (const std::string& failure : stage->collectFailures(true)) fail(failure);
    // Whole-run outputs (reports) once every frame is done.
    if (shot.wholeRunOutputs) finishStages(stages, shot, report);
    return report;
}

void finishStages(std::vector<StagePtr>& stages, const ShotSettings& shot, RunReport& report) {
    for (StagePtr& stage : stages) {
        try {
            stage->finish(shot);
        } catch (const Error& e) {
            recordFailure(report, cat(stage->name(), ": ", e.what()));
        }
    }
}

}  // namespace hp
