// Registration of the scene schema, one function per section, each in its own
// pipeline/scene_keys_<section>.cpp. addSceneKeys (schema.cpp) calls them all.
#pragma once

#include "pipeline/schema.h"

namespace hp {

void addSceneKeys(SchemaBuilder& b);

void addShotKeys(SchemaBuilder& b);    // top level: name, frames, fps, seed
void addOutputKeys(SchemaBuilder& b);  // output: directory, templates
void addRenderKeys(SchemaBuilder& b);  // render: camera, lights, materials (scene_keys_render.cpp)
void addSimKeys(SchemaBuilder& b);     // simulation.*, hair.guides shape, hair.radius (scene_keys_sim.cpp)

}  // namespace hp
