#include "pipeline/farm/farm_status.h"

#include "pipeline/farm/farm_engine.h"
#include "pipeline/batch/frame_range.h"
#include "pipeline/stages/hair_source.h"
#include "pipeline/batch/output.h"
#include "pipeline/stages/shot_outputs.h"
#include "pipeline/stages/stages.h"

#include <fstream>
#include <map>
#include <sstream>

namespace fs = std::filesystem;

namespace hp {

namespace {

std::string pad(std::string s, size_t width) {
    if (s.size() < width) s.resize(width, ' ');
    return s;
}

/// Job ids of a Slurm submission (slurm-jobs.txt): task kind -> id.
std::map<std::string, std::string> slurmJobs(const fs::path& folder) {
    std::map<std::string, std::string> jobs;
    std::ifstream in(folder / "slurm-jobs.txt");
    std::string task, id;
    while (in >> task >> id) jobs[task] = id;
    return jobs;
}

/// Queue entries keyed by task id ("sim", "frames.3", "report").
std::map<std::string, std::string> queuedTasks(const std::map<std::string, std::string>& jobs,
                                               const std::vector<std::string>& queue) {
    std::map<std::string, std::string> byId;
    for (const auto& [task, id] : jobs) byId[id] = task;
    std::map<std::string, std::string> tasks;
    for (const std::string& line : queue) {
        std::istringstream in(line);
        std::string job, state, reason;
        in >> job >> state;
        std::getline(in, reason);
        if (reason.size() > 1 && reason != " None") state += " (" + reason.substr(1) + ")";
        const size_t underscore = job.find('_');
        const std::string base = job.substr(0, underscore);
        if (!byId.count(base)) continue;
        const std::string& kind = byId[base];
        if (kind == "frames") {
            const std::string index = underscore == std::string::npos ? "" : job.substr(underscore + 1);
            if (!index.empty() && index.front() == '[') tasks["frames.pending"] = state + " " + index;
            else tasks["frames." + index] = state;
        } else {
            tasks[kind] = state;
        }
    }
    return tasks;
}

}  // namespace

FarmStatus farmStatus(const Scene& scene, const RunOptions& options) {
    FarmStatus status;
    ShotSettings shot = resolveShot(scene, options);
    const fs::path folder = shot.outputDir / "farm";
    const WrittenPlan plan = readFarmPlan(folder);
    // Without --frames, the frames the plan was submitted for.
    if (!options.frames && !plan.frames.empty()) shot.frames = parseFrameRange(plan.frames);
    std::ostringstream out;
    out << scene.name() << ": frames " << formatFrameRange(shot.frames) << " (" << shot.frames.size() << ") -> "
        << shot.outputDir.string() << "\n\n";

    std::vector<StagePtr> stages = makeStages(scene, shot, {});
    bool complete = !stages.empty();
    out << "  " << pad("stage", 11) << pad("done", 7) << pad("total", 7) << "missing\n";
    for (const StageProgress& p : stageProgress(stages, shot.frames)) {
        std::string row = pad(p.stage, 11) + pad(std::to_string(p.done()), 7) + pad(std::to_string(p.frames.size()), 7) +
                          (p.missing.empty() ? "" : formatFrameRange(p.missing));
        out << "  " << row.substr(0, row.find_last_not_of(' ') + 1) << "\n";
        complete &= p.missing.empty();
    }
    if (stages.empty()) out << "  (the scene enables no stage)\n";
    if (scene.flag("compare.enabled") && !scene.text("compare.report").empty()) {
        const fs::path report = shot.outputDir / scene.text("compare.report");
        const bool written = fs::exists(report);
        out << "  compare report: " << report.string() << (written ? "" : " (not written yet)") << "\n";
        complete &= written;
    }
    std::set<fs::path> folders = outputFolders(stages, shot.frames);
    if (sceneHasHair(scene) && !shot.frames.empty())
        folders.insert(cachePath(scene, shot, "cache.checkpoint", shot.frames.front()).parent_path());
    if (const size_t n = findTemporaries(folders).size())
        out << "  " << n << " temporary file" << (n == 1 ? "" : "s")
            << " (.hairpipe-tmp-*): being written, or left by a killed task (the next run on that host removes them)\n";

    if (!plan.engine.empty()) {
        const std::map<std::string, std::string> jobs = slurmJobs(folder);
        std::map<std::string, std::string> queued;
        std::string slurmError;
        if (plan.engine == "slurm" && !jobs.empty()) {
            std::vector<std::string> ids;
            for (const auto& j : jobs) ids.push_back(j.second);
            queued = queuedTasks(jobs, slurmQueue(ids, slurmError));
        }
        out << "\nfarm plan (" << folder.string() << ", engine " << plan.engine << "):\n";
        size_t ok = 0, failed = 0, open = 0;
        for (const FarmTask& t : farmTasks(plan)) {
            const FarmTaskResult r = farmTaskResult(folder, t.id);
            std::string state;
            if (r.ok()) {
                state = "ok";
                ++ok;
            } else if (r.finished) {
                state = cat("FAILED, exit code ", r.exitCode, " (log: ", (folder / "logs" / (t.id + ".log")).string(), ")");
                ++failed;
            } else if (queued.count(t.id)) {
                state = queued[t.id];
                ++open;
            } else {
                state = fs::exists(folder / "logs" / (t.id + ".log")) ? "started, no result (running, or killed)"
                                                                       : "not run yet";
                ++open;
            }
            out << "  " << pad(t.label, 30) << state << "\n";
            if (r.finished && !r.ok())
                for (size_t e = 0; e < r.errors.size() && e < 5; ++e) out << "      " << r.errors[e] << "\n";
        }
        if (queued.count("frames.pending")) out << "  pending array tasks: " << queued["frames.pending"] << "\n";
        out << "  tasks: " << ok << " ok, " << failed << " failed, " << open << " not finished\n";
        if (!jobs.empty()) {
            out << "  slurm jobs:";
            for (const auto& [task, id] : jobs) out << " " << task << "=" << id;
            out << (slurmError.empty() ? "" : " (queue not available: " + slurmError + ")") << "\n";
        }
        complete &= failed == 0;
    }
    status.complete = complete;
    out << "\n" << (complete ? "complete" : "incomplete") << "\n";
    status.text = out.str();
    return status;
}

}  // namespace hp
