// Maps the scene's render.* keys onto render/view.h's View.
#pragma once

#include "pipeline/scene.h"
#include "render/view.h"

namespace hp {

/// The camera, lights and materials of the scene. Throws SceneError for
/// combinations single keys cannot check (camera target at its position,
/// zero light direction).
View makeView(const Scene& scene);

}  // namespace hp
