// Maps the scene's simulation.* and guide shape keys onto sim/guides/guides.h's
// GuideSettings (keys: pipeline/scene/keys/simulation.yaml).
#pragma once

#include "pipeline/scene/scene.h"
#include "sim/guides/guides.h"

namespace hp {

/// The guide solver's settings of `scene`. Throws SceneError for
/// combinations single keys cannot check (a collision radius that does not
/// fit a segment, a tip radius above the root radius). `threads` is left at 0:
/// the solver then uses the CLI's --threads limit (tbb::global_control).
GuideSettings guideSettings(const Scene& scene);

}  // namespace hp
