// Running a farm plan (pipeline/farm/farm_plan.h): on this machine (the local
// engine, same scripts, bounded workers) or on Slurm (sbatch through the
// plan's submit-slurm.sh, then optionally waiting for the jobs), and reading
// back each task's result from its status file and log.
#pragma once

#include "pipeline/farm/farm_plan.h"

#include <utility>

namespace hp {

/// One task of a plan: "sim", "frames.3", "report".
struct FarmTask {
    std::string id;     ///< status and log file name
    std::string label;  ///< "chunk 3 (frames 5-6)"
};

/// The plan's tasks in run order, from its plan.txt.
std::vector<FarmTask> farmTasks(const WrittenPlan& plan);

/// What a task's files say.
struct FarmTaskResult {
    bool finished = false;  ///< its status file exists
    int exitCode = -1;
    std::vector<std::string> errors;  ///< the "error:" lines of its log
    bool ok() const { return finished && exitCode == 0; }
};
FarmTaskResult farmTaskResult(const std::filesystem::path& folder, const std::string& taskId);

/// Runs the plan here: the sim task, then the chunks with at most `workers`
/// at once (each with `threads` threads; 0: all cores / workers), then the
/// report; every task logs to the plan's logs/. As on Slurm, chunks run only
/// when the simulation succeeded and the report runs after all chunks.
/// Returns kExitOk, or kExitFrameFailed after listing the failed tasks.
int runFarmLocally(const FarmPlan& plan, int workers, int threads);

/// Submits the plan through its submit-slurm.sh; returns (task, job id)
/// pairs. Throws Error with sbatch's message when submission fails.
std::vector<std::pair<std::string, std::string>> submitToSlurm(const FarmPlan& plan);

/// The jobs' entries in Slurm's queue ("<id> <state> <reason>", one per job
/// or array task), or empty when none is queued or running any more. Sets
/// `error` when squeue cannot be run or reached.
std::vector<std::string> slurmQueue(const std::vector<std::string>& jobIds, std::string& error);

/// Polls Slurm until the jobs have left the queue, then reports the tasks'
/// results like runFarmLocally.
int waitForSlurm(const FarmPlan& plan, const std::vector<std::pair<std::string, std::string>>& jobs);

/// Logs each task's result and returns kExitOk or kExitFrameFailed.
int reportFarmTasks(const std::filesystem::path& folder, const WrittenPlan& plan);

}  // namespace hp
