// Maps the scene's render.* keys onto render/view/view.h's View and the display transform.
#pragma once

#include "pipeline/scene/scene.h"
#include "render/image/display_transform.h"
#include "render/reference/hair_bsdf.h"
#include "render/view/view.h"

namespace hp {

/// The camera, lights and materials of the scene. Throws SceneError for
/// combinations single keys cannot check (camera target at its position,
/// zero light direction).
View makeView(const Scene& scene);

/// The physical hair fibre, the one source of truth for hair optics: the
/// physical reference renders it, and render.hair.shading: fitted derives
/// the preview's (and the Kajiya-Kay reference's) material from it.
/// Absorption from hairAbsorption(); roughness, tilt and index from
/// reference.physical.*.
HairFiberParams hairFiber(const Scene& scene);

/// Absorption σa of the physical hair: render.hair.melanin when set (the one
/// key that drives both renderers), else reference.physical.*.
Vec3f hairAbsorption(const Scene& scene);
/// β_n of the physical hair (reference.physical.azimuthal_roughness), which
/// the colour fit between σa and Kajiya-Kay colour depends on.
float hairRoughness(const Scene& scene);

/// The display transform of PNG / JPEG outputs (render.ocio.*,
/// render.exposure, render.background). Throws SceneError naming the key
/// when the config cannot be loaded or names no such display or view.
DisplaySettings makeDisplaySettings(const Scene& scene);

}  // namespace hp
