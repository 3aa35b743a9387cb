// Constructors of the frame sources and stages, one per stage file. Each
// returns null when the scene disables that stage. makeStages (stages.cpp)
// lists them in the order they run within a frame.
#pragma once

#include "pipeline/shot.h"

namespace hp {

/// The Embree reference renderer (stage_reference.cpp); null unless reference.enabled.
StagePtr makeReferenceStage(const Scene& scene, const ShotSettings& shot);

}  // namespace hp
