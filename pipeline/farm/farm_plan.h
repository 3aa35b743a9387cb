// A shot as farm jobs: the plan `hairpipe farm submit` writes and runs.
//
//   sim.sh      one job: `hairpipe sim` (sequential; the strand cache)
//   frames.sh   a job array, task k = chunk k of the frames: `hairpipe run
//               --frames <chunk> --stages <frame stages> --cache-only
//               --no-report`; depends on sim (afterok)
//   report.sh   one job after the array (afterany): `hairpipe run --stages
//               compare`, which compares what the chunks left uncompared and
//               writes the compare report once over all frames
//   submit-slurm.sh  the sbatch commands with their dependencies
//   plan.txt    the plan in words (chunks and their frames), for `farm status`
//
// The scripts are plain bash (#SBATCH lines are comments to bash), so the
// local engine runs the very same files, and a TD can read, edit and resubmit
// them (`sbatch --array=3,7 farm/frames.sh` reruns two chunks). Every task
// writes status/<task>.exit with its exit code when it ends and logs to
// logs/<task>.log; outputs go to the shot's output folder (shared storage on
// a farm), each file written atomically, so any task can be rerun.
#pragma once

#include "pipeline/scene/scene.h"
#include "pipeline/stages/shot.h"

namespace hp {

struct FarmOptions {
    size_t chunk = 8;         ///< frames per array task
    std::string partition;    ///< Slurm partition; empty: the default one
    int cpus = 0;             ///< Slurm --cpus-per-task; 0: not requested
    int maxParallel = 0;      ///< array tasks at once (local workers; Slurm %N); 0: no limit
};

/// What runs where. Built from the scene and the command line; the scripts
/// are written by writeFarmScripts.
struct FarmPlan {
    std::string name;                   ///< the scene's name, for job names
    std::string engine = "slurm";       ///< "slurm" or "local", recorded in plan.txt
    std::filesystem::path hairpipe;     ///< the executable the tasks run
    std::filesystem::path workDir;      ///< where the scene path is valid (the submitting folder)
    RunOptions options;                 ///< scene file, overrides, --frames, --force
    ShotSettings shot;                  ///< resolved output folder and frames
    FarmOptions farm;
    bool simulate = false;              ///< the scene has hair: a sim job
    bool cacheOnly = false;             ///< frame tasks read strands only from the cache
    bool simulateClip = false;          ///< the sim job runs the whole clip: the camera frames its cached hair
    std::vector<std::string> frameStages;  ///< stages the array runs (preview, reference, vdb, compare)
    std::vector<std::vector<int>> chunks;  ///< array task k (1-based) = chunks[k-1]
    bool report = false;                ///< a final compare-report job

    std::filesystem::path folder() const { return shot.outputDir / "farm"; }
    std::filesystem::path script(const std::string& task) const { return folder() / (task + ".sh"); }
    std::filesystem::path log(const std::string& task) const { return folder() / "logs" / (task + ".log"); }
    std::filesystem::path statusFile(const std::string& task) const { return folder() / "status" / (task + ".exit"); }
    /// One line per job for humans.
    std::string describe() const;
};

/// The plan for a scene (stages it enables, its frames or options.frames).
/// Throws UsageError when there is nothing to run or too many chunks.
FarmPlan makeFarmPlan(const Scene& scene, const RunOptions& options, const FarmOptions& farm);

/// Writes sim.sh, frames.sh, report.sh, submit-slurm.sh and plan.txt into
/// plan.folder() (each atomically) and clears earlier status files.
void writeFarmScripts(const FarmPlan& plan);

/// Chunks of a plan folder as plan.txt lists them ("task k: frames"), and
/// which stages and frames it covers; empty when there is no plan.
struct WrittenPlan {
    std::string engine;
    std::string frames;                    ///< the shot's frames ("1-84")
    std::vector<std::string> chunkFrames;  ///< task k (1-based) = chunkFrames[k-1]
    bool simulate = false, report = false;
};
WrittenPlan readFarmPlan(const std::filesystem::path& folder);

}  // namespace hp
