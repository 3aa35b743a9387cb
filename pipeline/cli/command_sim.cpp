// `hairpipe sim`: the sequential part of a shot alone. Writes the strand
// cache, statistics and checkpoints, then prints a summary of the statistics.
#include "core/log.h"
#include "pipeline/cli/commands.h"
#include "pipeline/stages/hair_source.h"

#include <cmath>
#include <fstream>
#include <iostream>
#include <sstream>

namespace fs = std::filesystem;

namespace hp {

namespace {

/// The number after "key": in one line of our own statistics JSON.
bool jsonNumber(const std::string& line, const std::string& key, double& value) {
    const size_t at = line.find("\"" + key + "\": ");
    if (at == std::string::npos) return false;
    value = std::strtod(line.c_str() + at + key.size() + 4, nullptr);
    return true;
}

void printSummary(const Scene& scene, const ShotSettings& shot) {
    double maxLength = 0, maxPenetration = 0, energy = 0, stepMs = 0, frameMs = 0, steps = 0, nans = 0,
           penetrations = 0;
    size_t frames = 0;
    for (int frame : shot.frames) {
        std::ifstream in(cachePath(scene, shot, "cache.stats", frame));
        std::string line;
        if (!std::getline(in, line)) continue;
        double v = 0, n = 0;
        if (!jsonNumber(line, "steps", n)) continue;  // a frame read back from the cache
        ++frames;
        if (jsonNumber(line, "max_length_error", v)) maxLength = std::max(maxLength, v);
        if (jsonNumber(line, "max_penetration", v)) maxPenetration = std::max(maxPenetration, v);
        if (jsonNumber(line, "penetration_count", v)) penetrations += v;
        if (jsonNumber(line, "kinetic_energy", v)) energy = std::max(energy, v);
        if (jsonNumber(line, "nan_count", v)) nans += v;
        if (jsonNumber(line, "ms_per_step", v)) stepMs += v * n, steps += n;
        if (jsonNumber(line, "frame_ms", v)) frameMs += v;
    }
    if (frames == 0) return;
    std::ostringstream out;
    out.precision(4);
    out << "simulation summary (" << frames << " simulated frames, " << steps << " guide steps):\n"
        << "  max segment length error  " << maxLength * 100 << " %\n"
        << "  deepest penetration       " << maxPenetration * 1000 << " mm (" << penetrations
        << " vertex-steps inside the head)\n"
        << "  max kinetic energy        " << energy << " J\n"
        << "  non-finite values         " << nans << "\n"
        << "  guide step                " << (steps ? stepMs / steps : 0) << " ms (" << (stepMs > 0 ? 1000 * steps / stepMs : 0)
        << " steps/s)\n"
        << "  frame (head, guides, followers)  " << frameMs / frames << " ms\n"
        << "  statistics per frame: " << cachePath(scene, shot, "cache.stats", shot.frames.front()).parent_path().string()
        << "\n";
    std::cout << out.str();
}

}  // namespace

CommandSpec simCommandSpec() {
    CommandSpec c{"sim", "[options] scene.yaml",
                  "simulate the shot and write the strand cache, statistics and checkpoints"};
    c.details =
        "The simulation is sequential from the scene's first frame. Frames already in the\n"
        "cache are skipped; a stopped simulation resumes from its latest checkpoint with\n"
        "results identical to an uninterrupted run (--force starts over). Later stages\n"
        "(render, vdb, compare) read the cache for any subset of frames.";
    c.run = [](const CommandLine& cl) {
        CommandContext ctx(cl);
        if (!sceneHasHair(ctx.scene))
            throw UsageError("hairpipe sim: the scene grows no hair (it needs head.file and hair.guides.count > 0)");
        if (!ctx.scene.flag("cache.enabled"))
            ctx.scene.fail("cache.enabled", "hairpipe sim writes the strand cache; it is disabled in this scene");
        const int code = runShotCommand(ctx, {"sim"});
        printSummary(ctx.scene, resolveShot(ctx.scene, ctx.options));
        return code;
    };
    return c;
}

}  // namespace hp
