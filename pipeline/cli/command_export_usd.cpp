// `hairpipe export-usd`: the whole shot's strands from the strand cache as one
// USD BasisCurves file with a time sample per frame — what DCCs that do not
// read per-frame file sequences (Blender's USD import) need.
#include "core/log.h"
#include "pipeline/cli/commands.h"
#include "pipeline/batch/frame_range.h"
#include "pipeline/stages/hair_source.h"
#include "pipeline/batch/output.h"
#include "pipeline/stages/cached_strands.h"
#include "pipeline/stages/usd_export.h"

#include <iostream>

namespace fs = std::filesystem;

namespace hp {

CommandSpec exportUsdCommandSpec() {
    CommandSpec c{"export-usd", "[--output FILE] [options] scene.yaml",
                  "write the shot's strands from the cache as one animated USD BasisCurves file"};
    c.details =
        "Reads the strand cache (run `hairpipe sim` first) of the shot's frames (or --frames)\n"
        "and writes one .usda: curveVertexCounts once, points, velocities and widths as time\n"
        "samples at the frame numbers (timeCodesPerSecond = fps). Memory holds one frame at a\n"
        "time. For one file per frame, set cache.usd (e.g. usd/hair.####.usda) instead.";
    c.options = {{"--output", "FILE", "the .usda to write (default: usd/hair.usda in the output folder)"}};
    c.run = [](const CommandLine& cl) {
        CommandContext ctx(cl);
        if (!sceneHasHair(ctx.scene))
            throw UsageError("hairpipe export-usd: the scene grows no hair (it needs head.file and hair.guides.count > 0)");
        const ShotSettings shot = resolveShot(ctx.scene, ctx.options);
        const fs::path output =
            cl.has("--output") ? fs::absolute(cl.value("--output")) : shot.outputDir / "usd" / "hair.usda";
        if (output.extension() != ".usda")
            throw UsageError("hairpipe export-usd: --output must end in .usda (the text form written), got '" +
                             output.string() + "'");
        // Check every frame is cached before writing anything.
        for (int frame : shot.frames) {
            const fs::path cache = cachePath(ctx.scene, shot, "cache.strands", frame);
            if (!fs::is_regular_file(cache))
                throw AssetError(cache.string(), cat("no strand cache for frame ", frame, " (run `hairpipe sim ",
                                                     ctx.options.sceneFile.string(), "` first)"));
        }
        UsdExportSettings usd;
        usd.fps = shot.fps;
        CachedStrands cached(ctx.scene, shot);  // rebuilds followers from cached guides (version 2)
        writeAtomically(output, [&](const fs::path& tmp) {
            writeUsdCurves(tmp, shot.frames, [&](int frame) { return cached.read(frame); }, usd);
        });
        std::cout << output.string() << ": frames " << formatFrameRange(shot.frames) << " as time samples\n";
        return int(kExitOk);
    };
    return c;
}

}  // namespace hp
