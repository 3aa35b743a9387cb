// Registration of the scene schema, one function per section, each in its own
// pipeline/scene_keys_<section>.cpp. addSceneKeys (schema.cpp) calls them all.
#pragma once

#include "pipeline/scene/schema.h"

namespace hp {

void addSceneKeys(SchemaBuilder& b);

void addShotKeys(SchemaBuilder& b);    // top level: name, frames, fps, seed
void addOutputKeys(SchemaBuilder& b);  // output: directory, templates
void addRenderKeys(SchemaBuilder& b);  // render: camera, lights, materials (scene_keys_render.cpp)
void addCompareKeys(SchemaBuilder& b);  // compare: sequences, thresholds, report (scene_keys_compare.cpp)
void addFollowerKeys(SchemaBuilder& b);  // hair.followers: follower modes (scene_keys_followers.cpp)
void addPreviewKeys(SchemaBuilder& b); // preview: the GL preview pass (scene_keys_preview.cpp)
void addHeadKeys(SchemaBuilder& b);    // head: import, clip, scalp, collider (scene_keys_head.cpp)
void addHairKeys(SchemaBuilder& b);    // hair: root counts and placement (scene_keys_hair.cpp)
void addReferenceKeys(SchemaBuilder& b);  // reference: Embree reference renderer (scene_keys_reference.cpp)
void addGroomKeys(SchemaBuilder& b);   // hair.groom: rest shape (scene_keys_sim.cpp)
void addCacheKeys(SchemaBuilder& b);
void addStageFrameKeys(SchemaBuilder& b);  // <stage>.frames subsets (scene_keys_cache.cpp)   // cache: strand cache, checkpoints, USD (scene_keys_cache.cpp)
void addVdbKeys(SchemaBuilder& b);     // vdb: OpenVDB density caches (scene_keys_vdb.cpp)
void addCurlyKeys(SchemaBuilder& b);   // hair.model, hair.curly, hair.wet: the curly/wet model (scene_keys_curly.cpp)
void addSimKeys(SchemaBuilder& b);     // simulation.*, hair.guides shape, hair.radius (scene_keys_sim.cpp)
void addBudgetKeys(SchemaBuilder& b);  // budget: resource budgets across keys (scene_keys_budget.cpp)

}  // namespace hp
