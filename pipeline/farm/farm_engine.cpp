#include "pipeline/farm/farm_engine.h"

#include "core/log.h"
#include "pipeline/batch/child_process.h"
#include "pipeline/cli/cli.h"
#include "pipeline/batch/frame_range.h"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <thread>
#include <unistd.h>

namespace fs = std::filesystem;

namespace hp {

std::vector<FarmTask> farmTasks(const WrittenPlan& plan) {
    std::vector<FarmTask> tasks;
    if (plan.simulate) tasks.push_back({"sim", "sim"});
    for (size_t k = 0; k < plan.chunkFrames.size(); ++k)
        tasks.push_back({cat("frames.", k + 1), cat("chunk ", k + 1, " (frames ", plan.chunkFrames[k], ")")});
    if (plan.report) tasks.push_back({"report", "report"});
    return tasks;
}

FarmTaskResult farmTaskResult(const fs::path& folder, const std::string& taskId) {
    FarmTaskResult r;
    std::ifstream status(folder / "status" / (taskId + ".exit"));
    if (status >> r.exitCode) r.finished = true;
    std::ifstream log(folder / "logs" / (taskId + ".log"));
    std::string line;
    while (std::getline(log, line)) {
        const size_t at = line.find("error: ");
        if (at == std::string::npos) continue;
        const std::string what = line.substr(at + 7);
        if (std::find(r.errors.begin(), r.errors.end(), what) == r.errors.end()) r.errors.push_back(what);
    }
    return r;
}

namespace {

WrittenPlan written(const FarmPlan& plan) {
    WrittenPlan w;
    w.engine = plan.engine;
    w.simulate = plan.simulate;
    w.report = plan.report;
    for (const std::vector<int>& c : plan.chunks) w.chunkFrames.push_back(formatFrameRange(c));
    return w;
}

std::string bash() {
    const fs::path b = findProgram("bash");
    return b.empty() ? "/bin/bash" : b.string();
}

}  // namespace

int reportFarmTasks(const fs::path& folder, const WrittenPlan& plan) {
    std::vector<std::string> failures;
    for (const FarmTask& t : farmTasks(plan)) {
        const FarmTaskResult r = farmTaskResult(folder, t.id);
        if (r.ok()) continue;
        const fs::path log = folder / "logs" / (t.id + ".log");
        failures.push_back(cat(t.label, ": ", r.finished ? cat("exit code ", r.exitCode) : std::string("did not run to its end"),
                               " (log: ", log.string(), ")"));
        for (const std::string& e : r.errors) failures.push_back("  " + e);
    }
    if (failures.empty()) {
        logInfo("hairpipe farm: every task succeeded");
        return kExitOk;
    }
    logError("hairpipe farm: FAILURES:");
    for (const std::string& f : failures) logError(f);
    return kExitFrameFailed;
}

int runFarmLocally(const FarmPlan& plan, int workers, int threads) {
    workers = std::max(1, workers);
    if (threads <= 0) threads = std::max(1, int(std::thread::hardware_concurrency()) / workers);
    const std::vector<FarmTask> tasks = farmTasks(written(plan));
    auto task = [&](const std::string& id, const std::vector<std::string>& args) {
        ChildTask t;
        t.label = id;
        t.argv = {bash(), plan.script(id.substr(0, id.find('.'))).string()};
        t.argv.insert(t.argv.end(), args.begin(), args.end());
        t.env = {cat("HAIRPIPE_THREADS=", threads)};
        t.log = plan.log(id);
        return t;
    };
    auto done = [&](const std::string& label, const std::string& id, const ChildResult& r) {
        if (r.ok()) logInfo("farm (local): ", label, ": ok");
        else logError("farm (local): ", label, ": ", r.describe(), " (log: ", plan.log(id).string(), ")");
    };
    bool simulated = true;
    if (plan.simulate) {
        logInfo("farm (local): sim (log: ", plan.log("sim").string(), ")");
        const ChildResult r = runChildren({task("sim", {})}, 1, nullptr, nullptr).front();
        done("sim", "sim", r);
        simulated = r.ok();
    }
    if (!plan.chunks.empty() && simulated) {
        std::vector<ChildTask> chunks;
        std::vector<std::string> labels;
        for (size_t k = 0; k < plan.chunks.size(); ++k) {
            chunks.push_back(task(cat("frames.", k + 1), {std::to_string(k + 1)}));
            labels.push_back(tasks[(plan.simulate ? 1 : 0) + k].label);
        }
        logInfo("farm (local): ", chunks.size(), " chunks, ", workers, " at a time, ", threads, " thread",
                threads == 1 ? "" : "s", " each");
        runChildren(chunks, workers, nullptr,
                    [&](size_t i, const ChildResult& r) { done(labels[i], chunks[i].label, r); });
    } else if (!plan.chunks.empty()) {
        logError("farm (local): the simulation failed; the frame chunks depend on it and were not run");
    }
    if (plan.report) {
        const ChildResult r = runChildren({task("report", {})}, 1, nullptr, nullptr).front();
        done("report", "report", r);
    }
    return reportFarmTasks(plan.folder(), written(plan));
}

std::vector<std::pair<std::string, std::string>> submitToSlurm(const FarmPlan& plan) {
    if (findProgram("sbatch").empty())
        throw Error("hairpipe farm: sbatch not found on PATH (install Debian's slurm-wlm, or use --engine local)");
    std::string output;
    const ChildResult r = runCapture({bash(), (plan.folder() / "submit-slurm.sh").string()}, output);
    if (!r.ok())
        throw Error(cat("hairpipe farm: submission failed (", r.describe(), "):\n", output,
                        "(the scripts are in ", plan.folder().string(), ")"));
    logInfo(output.substr(0, output.find_last_not_of('\n') + 1));
    std::vector<std::pair<std::string, std::string>> jobs;
    std::ifstream in(plan.folder() / "slurm-jobs.txt");
    std::string task, id;
    while (in >> task >> id) jobs.emplace_back(task, id);
    return jobs;
}

std::vector<std::string> slurmQueue(const std::vector<std::string>& jobIds, std::string& error) {
    error.clear();
    if (jobIds.empty()) return {};
    if (findProgram("squeue").empty()) {
        error = "squeue not found";
        return {};
    }
    std::string ids;
    for (const std::string& id : jobIds) ids += (ids.empty() ? "" : ",") + id;
    std::string output;
    const ChildResult r = runCapture({"squeue", "-h", "-r", "-j", ids, "-o", "%i %T %r"}, output);
    if (!r.ok()) {
        // Jobs that ended long ago are unknown to squeue: that is not an error.
        if (output.find("Invalid job id") != std::string::npos) return {};
        error = output.empty() ? r.describe() : output.substr(0, output.find('\n'));
        return {};
    }
    std::vector<std::string> lines;
    std::istringstream in(output);
    std::string line;
    while (std::getline(in, line))
        if (!line.empty()) lines.push_back(line);
    return lines;
}

int waitForSlurm(const FarmPlan& plan, const std::vector<std::pair<std::string, std::string>>& jobs) {
    std::vector<std::string> ids;
    for (const auto& j : jobs) ids.push_back(j.second);
    std::string last;
    int failuresToReach = 0;
    for (;;) {
        std::string error;
        const std::vector<std::string> queue = slurmQueue(ids, error);
        if (!error.empty()) {
            // The controller may be briefly busy; give up after a minute.
            if (++failuresToReach > 30) throw Error("hairpipe farm: cannot query Slurm: " + error);
        } else {
            failuresToReach = 0;
            if (queue.empty()) break;
            const std::string now = cat(queue.size(), " job", queue.size() == 1 ? "" : "s", " queued or running");
            if (now != last) logInfo("farm (slurm): ", now);
            last = now;
        }
        ::sleep(2);
    }
    return reportFarmTasks(plan.folder(), written(plan));
}

}  // namespace hp
