#include "pipeline/cli/commands.h"

#include "core/log.h"
#include "pipeline/stages/camera_track.h"
#include "pipeline/stages/cached_strands.h"
#include "pipeline/head/clip_cuts.h"
#include "pipeline/scene/curly_settings.h"
#include "pipeline/batch/frame_jobs.h"
#include "pipeline/batch/frame_range.h"
#include "pipeline/groom/groom_import.h"
#include "pipeline/stages/hair_source.h"
#include "pipeline/head/head_setup.h"
#include "pipeline/batch/output.h"
#include "pipeline/stages/shot_outputs.h"
#include "pipeline/stages/shot_simulation.h"
#include "pipeline/stages/stages.h"
#include "pipeline/batch/progress.h"
#include "pipeline/scene/schema.h"
#include "pipeline/scene/view_settings.h"

#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>
#include <iostream>

namespace hp {

const std::vector<CommandSpec>& commands() {
    static const std::vector<CommandSpec> list = {
        runCommandSpec(),
        simCommandSpec(),
        renderCommandSpec(),
        compareCommandSpec(),
        viewCommandSpec(),
        vdbCommandSpec(),
        exportUsdCommandSpec(),
        farmCommandSpec(),
        validateCommandSpec(),
        infoCommandSpec(),
        helpCommandSpec(),
    };
    return list;
}

namespace {

std::string sceneArgument(const CommandLine& cl) {
    if (cl.positional.empty()) throw UsageError("hairpipe " + cl.command + ": no scene file given (see --help)");
    if (cl.positional.size() > 1)
        throw UsageError("hairpipe " + cl.command + ": unexpected argument '" + cl.positional[1] + "'");
    return cl.positional[0];
}

/// --jobs, --chunk (run, render, vdb) and --stages, --cache-only,
/// --no-report, --no-overlap (run); a command that does not list one never sees it.
void parseBatchOptions(const CommandLine& cl, RunOptions& options) {
    if (cl.has("--jobs")) options.jobs = int(integerOption(cl, "--jobs", 1, 256));
    if (cl.has("--chunk")) options.chunk = int(integerOption(cl, "--chunk", 1, 1000000));
    options.cacheOnly = cl.has("--cache-only");
    options.noReport = cl.has("--no-report");
    options.noOverlap = cl.has("--no-overlap");
    if (cl.has("--stages")) {
        const std::string list = cl.value("--stages");
        size_t start = 0;
        while (start <= list.size()) {
            const size_t end = std::min(list.find(',', start), list.size());
            const std::string name = list.substr(start, end - start);
            const std::vector<std::string>& known = stageNames();
            if (std::find(known.begin(), known.end(), name) == known.end()) {
                std::string all;
                for (const std::string& k : known) all += (all.empty() ? "" : ", ") + k;
                throw UsageError("option --stages: unknown stage '" + name + "' (stages: " + all + ")");
            }
            options.only.insert(name);
            start = end + 1;
        }
    }
}

}  // namespace

long integerOption(const CommandLine& cl, const std::string& option, long lo, long hi) {
    const std::string text = cl.value(option);
    char* end = nullptr;
    const long n = std::strtol(text.c_str(), &end, 10);
    if (text.empty() || *end != '\0' || n < lo || n > hi)
        throw UsageError(cat("option ", option, " expects an integer in [", lo, ", ", hi, "], got '", text, "'"));
    return n;
}

CommandContext::CommandContext(const CommandLine& cl) {
    std::vector<std::string> sets;
    if (cl.has("--set")) sets = cl.values.at("--set");
    if (cl.has("--seed")) {
        const std::string seed = cl.value("--seed");
        char* end = nullptr;
        std::strtoll(seed.c_str(), &end, 10);
        if (seed.empty() || *end != '\0') throw UsageError("option --seed expects an integer, got '" + seed + "'");
        sets.push_back("seed=" + seed);
    }
    if (cl.has("--threads")) {
        const long n = integerOption(cl, "--threads", 1, 1024);
        threads_ = std::make_shared<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(n));
        options.threads = int(n);
    }
    options.sceneFile = sceneArgument(cl);
    scene = Scene::load(sceneArgument(cl), sets);
    options.sets = sets;
    if (cl.has("--frames")) options.frames = parseFrameRange(cl.value("--frames"));
    if (cl.has("--out")) options.outputDir = cl.value("--out");
    options.force = cl.has("--force");
    parseBatchOptions(cl, options);
}

CommandContext::~CommandContext() = default;

int runShotCommand(const CommandContext& ctx, const std::set<std::string>& only) {
    const auto start = std::chrono::steady_clock::now();
    ShotSettings shot = resolveShot(ctx.scene, ctx.options);
    std::vector<StagePtr> stages = makeStages(ctx.scene, shot, only);
    for (const StagePtr& s : stages) shot.writesCache |= s->name() == "sim";
    std::string names;
    for (const StagePtr& s : stages) names += (names.empty() ? "" : ", ") + s->name();
    logInfo("hairpipe: ", ctx.scene.name(), ": frames ", formatFrameRange(shot.frames), " -> ",
            shot.outputDir.string(), " (stages: ", names.empty() ? "none" : names, ")");
    if (!stages.empty()) checkOutputDirectory(shot.outputDir);  // exit 1 now, not a failure per frame
    // A killed run leaves temporaries beside its outputs; drop those of dead writers.
    std::set<std::filesystem::path> cacheFolders;
    if (sceneHasHair(ctx.scene) && !shot.frames.empty())
        cacheFolders.insert(cachePath(ctx.scene, shot, "cache.checkpoint", shot.frames.front()).parent_path());
    cleanStaleTemporaries(stages, shot.frames, cacheFolders);
    RunReport report;
    if (ctx.options.jobs > 1) {
        stages.clear();
        report = runShotInJobs(ctx.scene, ctx.options, only);
    } else {
        RunReport simulation;
        if (framesOnCachedHair(ctx.scene, stages)) simulateFirst(ctx.scene, shot, stages, simulation);
        std::unique_ptr<FrameSource> source = makeFrameSource(ctx.scene, shot);
        report = runFrames(*source, stages, shot);
        lendToCachedStrands(ctx.scene, shot, nullptr);  // free the simulation the frame stages rebuilt on
        report.outputsSkipped += simulation.outputsSkipped;
        report.failures.insert(report.failures.begin(), simulation.failures.begin(), simulation.failures.end());
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    logInfo("hairpipe: ", report.framesDone, " frames in ", formatDuration(seconds), ", ", report.outputsSkipped,
            " stage outputs already present (skipped)", report.failures.empty() ? "" : ", FAILURES:");
    for (const std::string& f : report.failures) logError(f);
    return report.failures.empty() ? kExitOk : kExitFrameFailed;
}

std::function<int(const CommandLine&)> runStages(StageChoice choose) {
    return [choose](const CommandLine& cl) {
        CommandContext ctx(cl);
        return runShotCommand(ctx, choose(ctx, cl));
    };
}

std::vector<OptionSpec> jobOptions(const std::string& jobs, const std::string& chunk) {
    return {{"--jobs", "N", jobs}, {"--chunk", "N", chunk}};
}

CommandSpec runCommandSpec() {
    CommandSpec c{"run", "[options] scene.yaml", "run every stage the scene enables, frame by frame"};
    c.details =
        "Frames whose outputs all exist are skipped (use --force to redo them), so an\n"
        "interrupted batch resumes where it stopped. Each file is written under a\n"
        "temporary name and renamed when complete.\n\n"
        "With --jobs N the simulation runs first (writing the strand cache), then the\n"
        "frame stages run in N child processes at a time, each a chunk of frames read\n"
        "from the cache; outputs are identical to --jobs 1. --stages, --cache-only and\n"
        "--no-report run one chunk of a larger run (what --jobs and farm tasks run).";
    c.options = jobOptions("run the frame stages in N processes at once (after the simulation)",
                           "--jobs: frames per child process (default: about 4 chunks per job)");
    c.options.insert(c.options.end(), {
        {"--stages", "LIST", "run only these stages, e.g. preview,vdb (sim, preview, reference, vdb, compare)"},
        {"--cache-only", "", "read strands only from the strand cache; a frame without one fails"},
        {"--no-report", "", "skip whole-run outputs (the compare report): for one chunk of a larger run"},
        {"--no-overlap", "", "run each frame's stages one after another (the VDB and compare of a frame otherwise "
                             "run beside the next frame's preview); same outputs, stage timings in -v of their own"},
    });
    c.run = runStages([](const CommandContext& ctx, const CommandLine&) { return ctx.options.only; });
    return c;
}

CommandSpec renderCommandSpec() {
    CommandSpec c{"render", "[--preview] [--reference] [options] scene.yaml",
                  "render preview (GL) and/or reference (Embree) frames"};
    c.details = "Without --preview or --reference, renders whichever of the two the scene enables;\n"
                "--preview and --reference render theirs even where the scene leaves it disabled.";
    c.options = {{"--preview", "", "render the GL preview"}, {"--reference", "", "render the Embree reference"}};
    for (const OptionSpec& o : jobOptions("render N frames at once in child processes (simulating missing cache frames first)"))
        c.options.push_back(o);
    const auto run = runStages([](const CommandContext&, const CommandLine& cl) {
        std::set<std::string> only;
        if (cl.has("--preview")) only.insert("preview");
        if (cl.has("--reference")) only.insert("reference");
        if (only.empty()) only = {"preview", "reference"};
        return only;
    });
    c.run = [run](const CommandLine& given) {
        // As an override, so --jobs children (which get the run's --set list) see it too.
        CommandLine cl = given;
        for (const std::string stage : {"preview", "reference"})
            if (cl.has("--" + stage)) cl.values["--set"].push_back(stage + ".enabled=true");
        return run(cl);
    };
    return c;
}

CommandSpec validateCommandSpec() {
    CommandSpec c{"validate", "[options] scene.yaml", "check a scene file (types, ranges, files) without running it"};
    c.run = [](const CommandLine& cl) {
        CommandContext ctx(cl);
        resolveShot(ctx.scene, ctx.options);
        makeView(ctx.scene);             // checks across render keys
        makeDisplaySettings(ctx.scene);  // the OCIO config loads; its display and view exist
        checkCameraKeys(ctx.scene);
        if (sceneHasHead(ctx.scene)) {
            const HeadSetup head = loadHead(ctx.scene);  // mesh, clip and scalp selections
            if (sceneHasGroomFile(ctx.scene))  // the groom file read, bound and resampled
                importGroom(ctx.scene, head, int(ctx.scene.integer("hair.guides.segments")) + 1);
        }
        if (usesCurlyWetModel(ctx.scene)) curlyWetSettings(ctx.scene).validate();  // across hair.curly/wet keys
        std::cout << ctx.scene.name() << ": ok\n";
        return int(kExitOk);
    };
    return c;
}

namespace {

/// The scene cuts of the shot's clip (simulation.cut_*), as `info` prints them.
void printClipCuts(const Scene& scene, const ShotSettings& shot) {
    if (shot.frames.empty()) return;
    const double start = shot.frames.front() / shot.fps, end = shot.frames.back() / shot.fps;
    const double step = frameAlignedStep(shot.fps, scene.number("simulation.time_step"));
    const std::vector<ClipCut> cuts = findClipCuts(scene, loadHead(scene), start, end, step);
    std::cout << "cuts:    " << cuts.size() << " (simulation.cut_distance " << scene.number("simulation.cut_distance")
              << " m, cut_angle " << scene.number("simulation.cut_angle") << " deg per step)\n";
    for (const ClipCut& c : cuts) {
        char line[200];
        std::snprintf(line, sizeof line,
                      "  t = %.4f s (frame %.2f): head moved %.3f m, turned %.1f deg, a root moved %.3f m%s\n", c.time,
                      c.time * shot.fps, c.jump.headMove, c.jump.headTurn, c.jump.rootMove,
                      c.steps > 1 ? cat(" over ", c.steps, " steps from t = ", c.start - step, " s").c_str() : "");
        std::cout << line;
    }
}

}  // namespace

CommandSpec infoCommandSpec() {
    CommandSpec c{"info", "[options] scene.yaml",
                  "print what a scene resolves to (frames, assets, strand counts, every key)"};
    c.run = [](const CommandLine& cl) {
        CommandContext ctx(cl);
        const ShotSettings shot = resolveShot(ctx.scene, ctx.options);
        std::cout << "scene:   " << ctx.scene.name() << "\n"
                  << "frames:  " << formatFrameRange(shot.frames) << " (" << shot.frames.size() << " frames at "
                  << shot.fps << " fps)\n"
                  << "output:  " << shot.outputDir.string() << "\n"
                  << "seed:    " << shot.seed << "\n";
        if (sceneHasHead(ctx.scene)) {
            try {
                std::cout << "head:\n" << importHead(headImportSettings(ctx.scene)).summary();
            } catch (const RigSelectionError& e) {
                ctx.scene.fail("head.meshes", e.what());
            }
            printClipCuts(ctx.scene, shot);
        }
        std::cout << "\nresolved keys:\n" << ctx.scene.dump();
        return int(kExitOk);
    };
    return c;
}

CommandSpec helpCommandSpec() {
    CommandSpec c{"help", "[command | scene]", "show help for a command, or 'help scene' for the scene file reference"};
    c.sceneOptions = false;
    c.run = [](const CommandLine& cl) {
        if (cl.positional.empty()) {
            std::cout << generalHelp();
        } else if (cl.positional[0] == "scene") {
            std::cout << Schema::scene().markdown();
        } else {
            for (const CommandSpec& cmd : commands())
                if (cmd.name == cl.positional[0]) {
                    std::cout << commandHelp(cmd);
                    return int(kExitOk);
                }
            throw UsageError("hairpipe help: unknown command '" + cl.positional[0] + "'");
        }
        return int(kExitOk);
    };
    return c;
}

}  // namespace hp
