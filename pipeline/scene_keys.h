// Registration of the scene schema, one function per section, each in its own
// pipeline/scene_keys_<section>.cpp. addSceneKeys (schema.cpp) calls them all.
#pragma once

#include "pipeline/schema.h"

namespace hp {

void addSceneKeys(SchemaBuilder& b);

void addShotKeys(SchemaBuilder& b);    // top level: name, frames, fps, seed
void addOutputKeys(SchemaBuilder& b);  // output: directory, templates
void addRenderKeys(SchemaBuilder& b);  // render: camera, lights, materials (scene_keys_render.cpp)
void addCompareKeys(SchemaBuilder& b);  // compare: sequences, thresholds, report (scene_keys_compare.cpp)
void addCurlyKeys(SchemaBuilder& b);   // hair.model, hair.curly, hair.wet: the curly/wet model (scene_keys_curly.cpp)

}  // namespace hp
