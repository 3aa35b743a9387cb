// The frame source of a shot with a head and no simulation yet: each frame's
// head pose (deformed mesh, rigid transform, collider) for the stages.
#pragma once

#include "pipeline/stages/stage.h"

#include <memory>

namespace hp {

/// @brief Samples `head` at frame / fps for each requested frame. The pose
/// stays valid until the next get(). Later sources (the simulation) take the
/// same HeadMotion and sample it themselves.
std::unique_ptr<FrameSource> makeHeadFrameSource(std::shared_ptr<const HeadMotion> head, double fps);

}  // namespace hp
