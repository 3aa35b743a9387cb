#include "pipeline/batch/frame_jobs.h"

#include "core/log.h"
#include "pipeline/stages/camera_track.h"
#include "pipeline/batch/child_process.h"
#include "pipeline/cli/cli.h"
#include "pipeline/batch/frame_range.h"
#include "pipeline/stages/hair_source.h"
#include "pipeline/batch/progress.h"
#include "pipeline/stages/shot_outputs.h"
#include "pipeline/stages/stages.h"

#include <algorithm>
#include <mutex>
#include <thread>

namespace fs = std::filesystem;

namespace hp {

std::vector<std::string> sceneArguments(const RunOptions& options, const ShotSettings& shot) {
    std::vector<std::string> args = {options.sceneFile.string(), "--out", shot.outputDir.string()};
    for (const std::string& set : options.sets) {
        args.push_back("--set");
        args.push_back(set);
    }
    return args;
}

bool framesOnCachedHair(const Scene& scene, const std::vector<StagePtr>& stages) {
    // A sim- or vdb-only run needs no camera: it simulates only its own frames.
    return cameraReadsStrandCache(scene) && std::any_of(stages.begin(), stages.end(), [](const StagePtr& s) {
               return s && (s->name() == "preview" || s->name() == "reference");
           });
}

void simulateFirst(const Scene& scene, const ShotSettings& shot, std::vector<StagePtr>& stages, RunReport& report) {
    const bool framing = framesOnCachedHair(scene, stages);
    StagePtr sim;
    std::vector<StagePtr> rest;
    for (StagePtr& s : stages) {
        if (s->name() == "sim") sim = std::move(s);
        else rest.push_back(std::move(s));
    }
    stages = std::move(rest);
    const bool hair = sceneHasHair(scene);
    const bool needsData =
        std::any_of(stages.begin(), stages.end(), [](const StagePtr& s) { return s->needsFrameData(); });
    // render/vdb: fill the cache first, as `run` does.
    if (!sim && hair && needsData && !shot.requireCache) sim = makeSimStage(scene, shot);
    if (!sim) return;
    ShotSettings simShot = shot;
    simShot.writesCache = true;
    simShot.requireCache = false;
    // Camera auto/follow frames the cached hair: the frames the cameras of the
    // rendered frames read must be simulated too (follow: the frames
    // themselves; auto: their whole cut-free segments). A sim or vdb run
    // frames nothing and simulates only its frames.
    if (framing) {
        const std::vector<int> read = cameraCacheFrames(scene, shot.frames);
        simShot.frames.insert(simShot.frames.end(), read.begin(), read.end());
        std::sort(simShot.frames.begin(), simShot.frames.end());
        simShot.frames.erase(std::unique(simShot.frames.begin(), simShot.frames.end()), simShot.frames.end());
        if (simShot.frames.size() > shot.frames.size())
            logVerbose("camera ", scene.text("render.camera.mode"), " frames whole segments of the clip: simulating ",
                       simShot.frames.size() - shot.frames.size(), " more frames (", formatFrameRange(simShot.frames),
                       ") than asked (", formatFrameRange(shot.frames), ")");
    }
    logInfo("simulating first (sequential), writing the strand cache",
            simShot.frames.size() > shot.frames.size() ? " of the frames the camera frames (camera auto)" : "");
    std::vector<StagePtr> simStages;
    simStages.push_back(std::move(sim));
    std::unique_ptr<FrameSource> source = makeFrameSource(scene, simShot);
    const RunReport r = runFrames(*source, simStages, simShot);
    report.outputsSkipped += r.outputsSkipped;
    report.failures.insert(report.failures.end(), r.failures.begin(), r.failures.end());
}

namespace {

int defaultChunk(size_t frames, int jobs) {
    // About four chunks per job: enough to balance frames of unequal cost
    // (a reference every 12th frame), few enough that the per-process start
    // (scene, head, GL context) stays small against the frames' work.
    return int(std::max<size_t>(1, (frames + size_t(jobs) * 4 - 1) / (size_t(jobs) * 4)));
}

}  // namespace

RunReport runShotInJobs(const Scene& scene, const RunOptions& options, const std::set<std::string>& only) {
    ShotSettings shot = resolveShot(scene, options);
    std::vector<StagePtr> all = makeStages(scene, shot, only);
    const bool hair = sceneHasHair(scene);
    const bool needsData =
        std::any_of(all.begin(), all.end(), [](const StagePtr& s) { return s->name() != "sim" && s->needsFrameData(); });
    if (hair && needsData && !shot.requireCache && !scene.flag("cache.enabled")) {
        // Without the cache every child would simulate the shot again.
        logWarning("--jobs ", options.jobs, " needs the strand cache (cache.enabled: false): running in one process");
        std::unique_ptr<FrameSource> source = makeFrameSource(scene, shot);
        return runFrames(*source, all, shot);
    }
    RunReport report;
    std::vector<StagePtr> stages = std::move(all);
    simulateFirst(scene, shot, stages, report);  // leaves the frame-parallel stages

    const std::vector<int> todo = framesWithWork(stages, shot.frames, shot.force);
    if (!shot.force)
        for (const StageProgress& p : stageProgress(stages, shot.frames)) report.outputsSkipped += p.done();
    if (!stages.empty() && !todo.empty()) {
        const int jobs = std::max(1, options.jobs);
        const size_t chunk = size_t(options.chunk > 0 ? options.chunk : defaultChunk(todo.size(), jobs));
        const std::vector<std::vector<int>> chunks = splitFrames(todo, chunk);
        const int cores = options.threads > 0 ? options.threads : int(std::max(1u, std::thread::hardware_concurrency()));
        const int threads = std::max(1, cores / jobs);
        std::string names;
        for (const StagePtr& s : stages) names += (names.empty() ? "" : ",") + s->name();
        const std::string exe = currentExecutable().string();
        std::vector<ChildTask> tasks;
        for (const std::vector<int>& frames : chunks) {
            ChildTask t;
            t.label = "frames " + formatFrameRange(frames);
            t.argv = {exe, "run"};
            for (const std::string& a : sceneArguments(options, shot)) t.argv.push_back(a);
            for (const std::string& a : {std::string("--frames"), formatFrameRange(frames), std::string("--stages"), names,
                                         std::string("--no-report"), std::string("--threads"), std::to_string(threads)})
                t.argv.push_back(a);
            if (hair) t.argv.push_back("--cache-only");
            if (shot.force) t.argv.push_back("--force");
            if (options.noOverlap) t.argv.push_back("--no-overlap");
            t.argv.push_back(logLevel() == LogLevel::Verbose ? "-v" : "-q");
            tasks.push_back(std::move(t));
        }
        logInfo("--jobs ", jobs, ": ", todo.size(), " frames in ", chunks.size(), " chunks of up to ", chunk,
                " frames (stages ", names, ", ", threads, " thread", threads == 1 ? "" : "s", " each)");

        // Children's messages come through with their chunk named; their
        // "error:" lines are the failures to report.
        std::vector<std::vector<std::string>> errors(tasks.size());
        Progress progress("chunks", tasks.size());
        auto onLine = [&](size_t i, const std::string& line) {
            if (line.rfind("error: ", 0) == 0) {
                const std::string what = line.substr(7);
                if (std::find(errors[i].begin(), errors[i].end(), what) == errors[i].end()) errors[i].push_back(what);
            }
            logLine(LogLevel::Quiet, cat("[", tasks[i].label, "] ", line));
        };
        auto onDone = [&](size_t i, const ChildResult& r) {
            progress.advance(cat(tasks[i].label, r.ok() ? "" : ": " + r.describe()));
        };
        const std::vector<ChildResult> results = runChildren(tasks, jobs, onLine, onDone);
        for (size_t i = 0; i < results.size(); ++i) {
            if (results[i].ok()) {
                report.framesDone += chunks[i].size();
                continue;
            }
            // Exit code 2 means frames failed and said why; anything else
            // (a crash, a kill, a usage error) fails the whole chunk.
            if (results[i].exitCode != kExitFrameFailed || errors[i].empty())
                report.failures.push_back(cat(tasks[i].label, ": the child process ended with ", results[i].describe()));
            for (const std::string& e : errors[i]) report.failures.push_back(e);
        }
    }
    if (shot.wholeRunOutputs) finishStages(stages, shot, report);
    return report;
}

}  // namespace hp
