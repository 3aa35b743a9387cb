#include "pipeline/farm/farm_plan.h"

#include "pipeline/batch/child_process.h"
#include "pipeline/batch/frame_jobs.h"
#include "pipeline/batch/frame_range.h"
#include "pipeline/stages/camera_track.h"
#include "pipeline/stages/hair_source.h"
#include "pipeline/batch/output.h"
#include "pipeline/stages/shot_outputs.h"
#include "pipeline/stages/stages.h"

#include <algorithm>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace hp {

namespace {

/// Slurm's default MaxArraySize is 1001 (task ids 0-1000).
constexpr size_t kMaxArrayTasks = 1000;

std::string joinQuoted(const std::vector<std::string>& words) {
    std::string out;
    for (const std::string& w : words) out += (out.empty() ? "" : " ") + shellQuote(w);
    return out;
}

/// A job name Slurm and shells accept: letters, digits, - _ . only.
std::string jobName(const std::string& what, const std::string& scene) {
    std::string n = "hp-" + what + "-" + scene;
    for (char& c : n)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
    return n;
}

/// The part every task script shares: #SBATCH lines, the folder, status
/// bookkeeping around `command` (which may use $task and $frames).
std::string taskScript(const FarmPlan& p, const std::string& what, const std::string& task, const std::string& logName,
                       const std::string& preamble, const std::string& command) {
    std::ostringstream s;
    s << "#!/bin/bash\n"
      << "# hairpipe farm task '" << what << "' of " << p.options.sceneFile.string() << " -> "
      << p.shot.outputDir.string() << "\n"
      << "# Written by `hairpipe farm submit`; run by Slurm (sbatch) or by `hairpipe farm submit\n"
      << "# --engine local`, or by hand: bash " << shellQuote(p.script(what).string())
      << (what == "frames" ? " TASK" : "") << "\n"
      << "#SBATCH --job-name=" << jobName(what, p.name) << "\n"
      << "#SBATCH --output=" << (p.folder() / "logs" / logName).string() << "\n";
    if (!p.farm.partition.empty()) s << "#SBATCH --partition=" << p.farm.partition << "\n";
    if (p.farm.cpus > 0) s << "#SBATCH --cpus-per-task=" << p.farm.cpus << "\n";
    s << "set -u\n"
      << "cd " << shellQuote(p.workDir.string()) << " || exit 1\n"
      << preamble
      << "status=" << shellQuote((p.folder() / "status").string()) << "\n"
      << "mkdir -p \"$status\" && rm -f \"$status/" << task << ".exit\"\n"
      << "# Threads: the Slurm allocation, or what the local engine hands out.\n"
      << "threads=\"${HAIRPIPE_THREADS:-${SLURM_CPUS_PER_TASK:-" << (p.options.threads > 0 ? std::to_string(p.options.threads) : "")
      << "}}\"\n"
      << "echo \"hairpipe farm: " << what << (what == "frames" ? " task $task (frames $frames)" : "")
      << " on $(hostname) at $(date '+%F %T')\"\n"
      << command << " ${threads:+--threads \"$threads\"}\n"
      << "rc=$?\n"
      << "echo \"$rc\" > \"$status/" << task << ".exit.tmp\" && mv -f \"$status/" << task << ".exit.tmp\" \"$status/"
      << task << ".exit\"\n"
      << "echo \"hairpipe farm: " << what << " ended with exit code $rc at $(date '+%F %T')\"\n"
      << "exit $rc\n";
    return s.str();
}

std::string submitScript(const FarmPlan& p) {
    std::ostringstream s;
    s << "#!/bin/bash\n"
      << "# Submits the plan in this folder to Slurm (what `hairpipe farm submit --engine slurm`\n"
      << "# runs): the simulation, the frame chunks as a job array that waits for it, and the\n"
      << "# compare report after the array. Job ids go to slurm-jobs.txt for `hairpipe farm status`.\n"
      << "set -euo pipefail\n"
      << "cd \"$(dirname \"$0\")\"\n"
      << "rm -f status/*.exit\n"
      << "jobid() { echo \"${1%%;*}\"; }  # --parsable prints id[;cluster]\n"
      << ": > slurm-jobs.txt\n";
    std::string after;
    if (p.simulate) {
        s << "sim=$(jobid \"$(sbatch --parsable sim.sh)\")\n"
          << "echo \"sim $sim\" >> slurm-jobs.txt\n";
        after = " --dependency=afterok:$sim --kill-on-invalid-dep=yes";
    }
    if (!p.chunks.empty()) {
        s << "frames=$(jobid \"$(sbatch --parsable --array=1-" << p.chunks.size()
          << (p.farm.maxParallel > 0 ? "%" + std::to_string(p.farm.maxParallel) : "") << after << " frames.sh)\")\n"
          << "echo \"frames $frames\" >> slurm-jobs.txt\n";
        after = " --dependency=afterany:$frames --kill-on-invalid-dep=yes";
    }
    if (p.report)
        s << "report=$(jobid \"$(sbatch --parsable" << after << " report.sh)\")\n"
          << "echo \"report $report\" >> slurm-jobs.txt\n";
    s << "echo \"submitted: $(tr '\\n' ' ' < slurm-jobs.txt)\"\n";
    return s.str();
}

}  // namespace

FarmPlan makeFarmPlan(const Scene& scene, const RunOptions& options, const FarmOptions& farm) {
    FarmPlan p;
    p.options = options;
    p.farm = farm;
    p.shot = resolveShot(scene, options);
    p.hairpipe = currentExecutable();
    p.workDir = fs::current_path();
    const std::string& name = scene.text("name");
    p.name = name.empty() ? options.sceneFile.stem().string() : name;
    p.simulate = sceneHasHair(scene) && scene.flag("cache.enabled");
    p.cacheOnly = p.simulate;
    if (sceneHasHair(scene) && !p.simulate)
        scene.fail("cache.enabled", "a farm run shares the simulation through the strand cache; enable it");
    std::vector<StagePtr> stages = makeStages(scene, p.shot, {});
    // Camera auto frames whole cut-free segments of the cached hair: the sim
    // job then writes the clip (follow reads only each task's own frames).
    if (p.simulate && framesOnCachedHair(scene, stages)) {
        const std::vector<int> read = cameraCacheFrames(scene, p.shot.frames);
        p.simulateClip = std::any_of(read.begin(), read.end(), [&](int f) {
            return std::find(p.shot.frames.begin(), p.shot.frames.end(), f) == p.shot.frames.end();
        });
    }
    for (const StagePtr& s : stages) {
        if (s->name() == "sim") continue;
        p.frameStages.push_back(s->name());
        if (s->name() == "compare") p.report = true;
    }
    if (!p.frameStages.empty()) p.chunks = splitFrames(p.shot.frames, farm.chunk);
    if (!p.simulate && p.chunks.empty())
        throw UsageError(cat(scene.name(), ": the scene enables no stage, nothing to submit"));
    if (p.chunks.size() > kMaxArrayTasks)
        throw UsageError(cat(p.shot.frames.size(), " frames in chunks of ", farm.chunk, " make ", p.chunks.size(),
                             " array tasks, more than Slurm's default limit of ", kMaxArrayTasks,
                             "; use a larger --chunk"));
    return p;
}

std::string FarmPlan::describe() const {
    std::ostringstream s;
    s << "farm plan for " << options.sceneFile.string() << ": frames " << formatFrameRange(shot.frames) << " -> "
      << shot.outputDir.string() << "\n";
    if (simulate) s << "  sim      1 job: hairpipe sim (strand cache)\n";
    if (!chunks.empty()) {
        std::string names;
        for (const std::string& n : frameStages) names += (names.empty() ? "" : ", ") + n;
        s << "  frames   array of " << chunks.size() << " task" << (chunks.size() == 1 ? "" : "s") << " of up to "
          << farm.chunk << " frames (" << names << ")" << (simulate ? ", after sim" : "") << "\n";
    }
    if (report) s << "  report   1 job after the array: the compare report over all frames\n";
    s << "  scripts and logs: " << folder().string() << "\n";
    return s.str();
}

void writeFarmScripts(const FarmPlan& p) {
    std::vector<std::string> common = sceneArguments(p.options, p.shot);
    if (p.options.frames) {
        common.push_back("--frames");
        common.push_back(formatFrameRange(p.shot.frames));
    }
    if (p.options.force) common.push_back("--force");
    const std::string exe = shellQuote(p.hairpipe.string());
    // Slurm does not create the folder of --output: a missing one loses the job's log.
    std::error_code ec;
    fs::create_directories(p.folder() / "logs", ec);
    if (ec) throw IoError((p.folder() / "logs").string(), "cannot create folder: " + ec.message());
    // Scripts of an earlier plan that this one does not have.
    if (!p.simulate) fs::remove(p.script("sim"), ec);
    if (p.chunks.empty()) fs::remove(p.script("frames"), ec);
    if (!p.report) fs::remove(p.script("report"), ec);

    if (p.simulate) {
        // Each frame task's camera may frame the cached hair of frames beyond
        // its own (camera auto): the sim job then writes the whole clip.
        std::vector<std::string> sim = common;
        if (p.simulateClip && p.options.frames) sim = sceneArguments(p.options, p.shot);
        if (p.simulateClip && p.options.frames && p.options.force) sim.push_back("--force");
        writeTextAtomically(p.script("sim"), taskScript(p, "sim", "sim", "sim.log", "", exe + " sim " + joinQuoted(sim)), true);
    }
    if (!p.chunks.empty()) {
        std::ostringstream pre;
        pre << "task=\"${SLURM_ARRAY_TASK_ID:-${1:-}}\"\n"
            << "case \"$task\" in\n";
        for (size_t k = 0; k < p.chunks.size(); ++k)
            pre << "  " << k + 1 << ") frames=" << formatFrameRange(p.chunks[k]) << " ;;\n";
        pre << "  *) echo \"hairpipe farm: no chunk '$task' in this plan (tasks 1-" << p.chunks.size()
            << "; give SLURM_ARRAY_TASK_ID or an argument)\" >&2; exit 1 ;;\n"
            << "esac\n";
        std::vector<std::string> args = sceneArguments(p.options, p.shot);
        std::string stages;
        for (const std::string& n : p.frameStages) stages += (stages.empty() ? "" : ",") + n;
        args.insert(args.end(), {"--stages", stages, "--no-report"});
        if (p.cacheOnly) args.push_back("--cache-only");
        if (p.options.force) args.push_back("--force");
        writeTextAtomically(p.script("frames"),
                  taskScript(p, "frames", "frames.$task", "frames.%a.log", pre.str(),
                             exe + " run " + joinQuoted(args) + " --frames \"$frames\""),
                  true);
    }
    if (p.report) {
        std::vector<std::string> args = common;
        args.insert(args.end(), {"--stages", "compare"});
        writeTextAtomically(p.script("report"), taskScript(p, "report", "report", "report.log", "", exe + " run " + joinQuoted(args)),
                  true);
    }
    writeTextAtomically(p.folder() / "submit-slurm.sh", submitScript(p), true);

    std::ostringstream plan;
    plan << "# hairpipe farm plan (read by `hairpipe farm status`)\n"
         << "engine: " << p.engine << "\n"
         << "scene: " << p.options.sceneFile.string() << "\n"
         << "workdir: " << p.workDir.string() << "\n"
         << "frames: " << formatFrameRange(p.shot.frames) << "\n"
         << "sim: " << (p.simulate ? "yes" : "no") << "\n"
         << "report: " << (p.report ? "yes" : "no") << "\n";
    for (size_t k = 0; k < p.chunks.size(); ++k) plan << "task " << k + 1 << ": " << formatFrameRange(p.chunks[k]) << "\n";
    writeTextAtomically(p.folder() / "plan.txt", plan.str(), false);
    // Results of an earlier submission would be mistaken for this one's.
    for (fs::directory_iterator it(p.folder() / "status", ec), end; !ec && it != end; it.increment(ec))
        fs::remove(it->path(), ec);
}

WrittenPlan readFarmPlan(const fs::path& folder) {
    WrittenPlan plan;
    std::ifstream in(folder / "plan.txt");
    std::string line;
    while (std::getline(in, line)) {
        const size_t colon = line.find(": ");
        if (colon == std::string::npos || line[0] == '#') continue;
        const std::string key = line.substr(0, colon), value = line.substr(colon + 2);
        if (key == "engine") plan.engine = value;
        else if (key == "frames") plan.frames = value;
        else if (key == "sim") plan.simulate = value == "yes";
        else if (key == "report") plan.report = value == "yes";
        else if (key.rfind("task ", 0) == 0) plan.chunkFrames.push_back(value);
    }
    return plan;
}

}  // namespace hp
