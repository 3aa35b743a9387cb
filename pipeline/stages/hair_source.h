// The frame source of a shot with hair: strands come from the strand cache
// when it holds the frame, otherwise from the simulation, which resumes from
// the latest usable checkpoint instead of starting over.
#pragma once

#include "pipeline/scene/scene.h"
#include "pipeline/stages/stage.h"

#include <memory>

namespace hp {

/// True when the scene grows hair (a head and at least one guide).
bool sceneHasHair(const Scene& scene);

/// @brief The shot's hair: cached frames are read (a corrupt cache file fails
/// that frame, naming the file), missing ones simulated. With
/// `shot.writesCache` the simulation writes a checkpoint per frame
/// (cache.checkpoint) so a later run can resume; `shot.force` ignores both
/// cache and checkpoints and simulates from the first frame.
std::unique_ptr<FrameSource> makeHairFrameSource(const Scene& scene, const ShotSettings& shot);

/// Output paths of the cache keys for a frame (absolute).
std::filesystem::path cachePath(const Scene& scene, const ShotSettings& shot, const std::string& key, int frame);

}  // namespace hp
