// `hairpipe farm submit|status`: a shot as farm jobs (pipeline/farm/farm_plan.h)
// on Slurm or on this machine, and its progress from the output folder.
#include "core/log.h"
#include "pipeline/cli/commands.h"
#include "pipeline/farm/farm_engine.h"
#include "pipeline/farm/farm_status.h"

#include <iostream>
#include <thread>

namespace hp {

namespace {

int submit(const CommandLine& cl) {
    const std::string engine = cl.value("--engine", "slurm");
    if (engine != "slurm" && engine != "local")
        throw UsageError("option --engine expects slurm or local, got '" + engine + "'");
    for (const char* option : {"--partition", "--cpus"})
        if (engine == "local" && cl.has(option))
            throw UsageError(cat("option ", option, " is for --engine slurm"));
    if (engine == "slurm" && cl.has("--threads"))
        logWarning("--threads: Slurm tasks use their allocation (--cpus) when they have one");
    CommandContext ctx(cl);
    FarmOptions farm;
    if (cl.has("--chunk")) farm.chunk = size_t(integerOption(cl, "--chunk", 1, 1000000));
    farm.partition = cl.value("--partition");
    if (cl.has("--cpus")) farm.cpus = int(integerOption(cl, "--cpus", 1, 4096));
    const int defaultWorkers = std::max(1, int(std::thread::hardware_concurrency()) / 2);
    if (cl.has("--jobs")) farm.maxParallel = int(integerOption(cl, "--jobs", 1, 4096));
    FarmPlan plan = makeFarmPlan(ctx.scene, ctx.options, farm);
    plan.engine = engine;
    writeFarmScripts(plan);
    std::cout << plan.describe();
    if (cl.has("--dry-run")) {
        std::cout << "dry run: nothing submitted; to submit: "
                  << (engine == "slurm" ? "bash " + (plan.folder() / "submit-slurm.sh").string()
                                        : "hairpipe farm submit --engine local (same options)")
                  << "\n";
        return int(kExitOk);
    }
    if (engine == "local") {
        const int workers = farm.maxParallel > 0 ? farm.maxParallel : defaultWorkers;
        return runFarmLocally(plan, workers, ctx.options.threads);
    }
    const auto jobs = submitToSlurm(plan);
    if (!cl.has("--wait")) {
        std::cout << "progress: hairpipe farm status " << ctx.options.sceneFile.string()
                  << (ctx.options.outputDir.empty() ? "" : " --out " + ctx.options.outputDir.string()) << "\n";
        return int(kExitOk);
    }
    return waitForSlurm(plan, jobs);
}

int status(const CommandLine& cl) {
    CommandContext ctx(cl);
    const FarmStatus s = farmStatus(ctx.scene, ctx.options);
    std::cout << s.text;
    return s.complete ? int(kExitOk) : int(kExitFrameFailed);
}

}  // namespace

CommandSpec farmCommandSpec() {
    CommandSpec c{"farm", "submit|status [options] scene.yaml",
                  "run a shot as farm jobs (Slurm, or locally) and report its progress"};
    c.details =
        "farm submit: writes a plan into <output>/farm/ and runs it. The plan is one\n"
        "simulation job (hairpipe sim, the strand cache), a job array of frame chunks\n"
        "(preview, reference, vdb, compare; each task reads the cache) that depends on it\n"
        "(afterok), and a final job that writes the compare report over all frames. The\n"
        "output folder must be shared storage that every node sees at the same path. The\n"
        "scripts (sim.sh, frames.sh, report.sh, submit-slurm.sh) stay there to inspect or\n"
        "resubmit (e.g. sbatch --array=3 frames.sh); logs go to farm/logs/.\n"
        "  --engine slurm  submits with sbatch (SLURM_CONF and the usual Slurm settings apply)\n"
        "  --engine local  runs the same scripts here, --jobs chunks at a time\n\n"
        "farm status: per stage, frames done of total and the missing frames; the plan's\n"
        "tasks (ok, failed with their errors, queued); temporaries of running or killed\n"
        "tasks. Judged from the files, so it needs no scheduler. Exit code 0 when the shot\n"
        "is complete, 2 otherwise.";
    c.options = {
        {"--engine", "slurm|local", "submit: where the jobs run (default slurm)"},
        {"--chunk", "N", "submit: frames per array task (default 8)"},
        {"--jobs", "N", "submit: array tasks at once (local default: half the cores; Slurm: %N)"},
        {"--partition", "P", "submit: Slurm partition"},
        {"--cpus", "N", "submit: Slurm CPUs per task (each task's threads)"},
        {"--wait", "", "submit --engine slurm: wait for the jobs and report like the local engine"},
        {"--dry-run", "", "submit: write the plan and scripts, submit nothing"},
    };
    c.run = [](const CommandLine& cl) {
        if (cl.positional.empty()) throw UsageError("hairpipe farm: expected 'submit' or 'status' (see --help)");
        CommandLine rest = cl;
        const std::string what = rest.positional.front();
        rest.positional.erase(rest.positional.begin());
        if (what == "submit") return submit(rest);
        if (what == "status") {
            for (const char* option : {"--engine", "--chunk", "--jobs", "--partition", "--cpus", "--wait", "--dry-run"})
                if (cl.has(option)) throw UsageError(cat("option ", option, " is for farm submit"));
            return status(rest);
        }
        throw UsageError("hairpipe farm: unknown subcommand '" + what + "' (submit or status)");
    };
    return c;
}

}  // namespace hp
