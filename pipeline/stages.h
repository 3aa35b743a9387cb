// Constructors of the frame sources and stages, one per stage file. Each
// returns null when the scene disables that stage. makeStages (stages.cpp)
// lists them in the order they run within a frame.
#pragma once

#include "pipeline/shot.h"

namespace hp {

/// OpenVDB density caches (stage_vdb.cpp); null unless vdb.enabled.
StagePtr makeVdbStage(const Scene& scene, const ShotSettings& shot);

}  // namespace hp
