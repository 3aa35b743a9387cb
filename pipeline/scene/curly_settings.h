// Maps the scene's hair.model, hair.curly.* and hair.wet.* keys onto the
// curly/wet solver's plain settings (sim/curly/curly_wet.h), and evaluates the
// animated saturation for the driver that steps the solver.
#pragma once

#include "pipeline/scene/scene.h"
#include "sim/curly/curly_wet.h"

namespace hp {

/// True when the scene's guides use the curly/wet model (hair.model: curly-wet).
bool usesCurlyWetModel(const Scene& scene);

/// The solver settings of the scene. `threads` is left at 0 (the ambient TBB
/// limit, which --threads sets). Throws SceneError for combinations single
/// keys cannot check (an adhesion shell inside the collision clearance).
CurlyWetSettings curlyWetSettings(const Scene& scene);

/// The scene's saturation σ at `time` seconds: hair.wet.saturation (a curve
/// over frames) at frame time·fps, clamped to [0, 1]. Pass it to
/// CurlyWetSolver::setSaturation before each step.
float sceneSaturation(const Scene& scene, double time);

}  // namespace hp
