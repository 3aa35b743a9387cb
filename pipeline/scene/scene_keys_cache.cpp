// cache.*: the strand cache and simulation checkpoints that split a shot into
// its sequential part (simulation) and its frame-parallel part (everything
// after), plus the USD export of the strands.
#include "pipeline/scene/scene_keys.h"

namespace hp {

void addCacheKeys(SchemaBuilder& b) {
    b.section("cache",
              "The simulation's outputs: one strand cache file per frame (versioned, checksummed), "
              "per-frame statistics and solver checkpoints. Later stages and other machines read the "
              "cache instead of simulating; a stopped simulation resumes from its last checkpoint with "
              "results identical to an uninterrupted run.")
        .flag("cache.enabled", true, "Write the strand cache (the 'sim' stage).")
        .text("cache.strands", "cache/strands.####.hpc", "Strand cache files, relative to the output folder.")
        .text("cache.stats", "cache/stats.####.json",
              "Simulation statistics per frame (JSON): length error, penetration, energy, ms per step.")
        .flag("cache.checkpoints", true, "Write solver checkpoints next to the cache so a simulation can resume.")
        .text("cache.checkpoint", "cache/checkpoint.####.bin", "Checkpoint files, relative to the output folder.")
        .text("cache.settled_groom", "cache/settled_groom.bin",
              "The settled groom (hair.groom.settle), relative to the output folder: reruns and frame chunks "
              "reuse it when the inputs that determine it (groom, first pose, solver settings) are unchanged.")
        .text("cache.usd", "",
              "Also export each frame's strands as USD BasisCurves (.usda), e.g. usd/hair.####.usda; "
              "empty: no USD.");
}

void addStageFrameKeys(SchemaBuilder& b) {
    for (const char* stage : {"preview", "reference", "vdb", "compare"})
        b.frames(std::string(stage) + ".frames", "",
                 std::string("Frames on which the ") + stage +
                     " stage runs (a subset of the shot, e.g. 1-84x12); default: every frame.");
}

}  // namespace hp
