#include "pipeline/scene/scene_keys.h"

namespace hp {

// Section order here is the order of docs/scene-reference.md.
void addSceneKeys(SchemaBuilder& b) {
    addShotKeys(b);
    addOutputKeys(b);
    addHeadKeys(b);
    addHairKeys(b);
    addFollowerKeys(b);
    addSimKeys(b);
    addGroomKeys(b);
    addCurlyKeys(b);
    addCacheKeys(b);
    addRenderKeys(b);
    addPreviewKeys(b);
    addReferenceKeys(b);
    addVdbKeys(b);
    addCompareKeys(b);
    addStageFrameKeys(b);
    addBudgetKeys(b);
}

void addShotKeys(SchemaBuilder& b) {
    b.section("", "The shot: which frames, at what rate, with which random seed.")
        .text("name", "", "Name of the scene, written into output metadata (default: the file name).")
        .frames("frames", "1-24", "Frames of the shot. Simulation always starts at the first frame.")
        .number("fps", 24, 1, 1000, "1/s", "Frames per second; frame f is at time f / fps.")
        .integer("seed", 1, 0, 2147483647, "", "Seed of every random choice (roots, follower variation).");
}

void addOutputKeys(SchemaBuilder& b) {
    b.section("output", "Where a run writes. Per-stage file templates are in each stage's section.")
        .text("output.directory", "",
              "Output folder, relative to the scene file (default: out/<scene file name> in the "
              "current folder). --out overrides it.");
}

}  // namespace hp
