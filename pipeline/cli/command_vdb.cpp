// `hairpipe vdb`: only the OpenVDB density caches of a shot.
#include "pipeline/cli/commands.h"

namespace hp {

CommandSpec vdbCommandSpec() {
    CommandSpec c{"vdb", "[options] scene.yaml", "write the OpenVDB density caches (one .vdb per frame)"};
    c.details =
        "Voxelizes each frame's strands into a fog-volume grid named 'density' (hair volume\n"
        "fraction, m^3 of hair per m^3) at vdb.voxel_size, optionally with a 'velocity' grid,\n"
        "and writes vdb.output (default vdb/hair.####.vdb) under the output folder. Frames\n"
        "whose file exists are skipped unless --force. The scene must set vdb.enabled: true\n"
        "(or pass --set vdb.enabled=true).";
    c.options = jobOptions("write N frames at once in child processes (simulating missing cache frames first)");
    c.run = runStages([](const CommandContext& ctx, const CommandLine&) {
        if (!ctx.scene.flag("vdb.enabled"))
            throw UsageError(cat("hairpipe vdb: ", ctx.scene.name(),
                                 " has vdb.enabled: false; enable it in the scene or pass --set vdb.enabled=true"));
        return std::set<std::string>{"vdb"};
    });
    return c;
}

}  // namespace hp
