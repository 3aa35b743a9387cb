// Constructors of the frame sources and stages, one per stage file. Each
// returns null when the scene disables that stage. makeStages (stages.cpp)
// lists them in the order they run within a frame.
#pragma once

#include "pipeline/stages/shot.h"

namespace hp {

/// compare.*: preview vs reference metrics, difference images and report (stage_compare.cpp).
/// "sim": the strand cache, statistics and USD export of each frame (stage_sim.cpp).
StagePtr makeSimStage(const Scene& scene, const ShotSettings& shot);
StagePtr makeCompareStage(const Scene& scene, const ShotSettings& shot);
/// The GL preview (stage_preview.cpp); null unless preview.enabled.
StagePtr makePreviewStage(const Scene& scene, const ShotSettings& shot);
/// The Embree reference renderer (stage_reference.cpp); null unless reference.enabled.
StagePtr makeReferenceStage(const Scene& scene, const ShotSettings& shot);
/// OpenVDB density caches (stage_vdb.cpp); null unless vdb.enabled.
StagePtr makeVdbStage(const Scene& scene, const ShotSettings& shot);

/// Every stage name makeStages knows, in run order ("sim", "preview", ...).
const std::vector<std::string>& stageNames();

}  // namespace hp
