// Load-time resource budgets (the budget.* keys, pipeline/scene/keys/budget.yaml).
//
// Each key's own range stops a single absurd value (10^9 strands), but a
// product of in-range keys can still ask for terabytes: a million guides of
// 200 segments, or a 16384² reference at 4096 samples and scale 4. These
// checks run when the scene is loaded — before any stage allocates — and fail
// with a SceneError at the key that most likely needs to change, naming the
// product, the budget and the budget key that raises it.
#pragma once

#include "pipeline/scene/scene.h"

namespace hp {

/// @brief Throws SceneError when the scene's strand vertices, simulated guide
/// vertices, image pixels or reference samples exceed the budget.* keys.
void checkSceneBudget(const Scene& scene);

}  // namespace hp
