// Maps the scene's preview.* keys onto render/preview/preview.h's PreviewSettings
// (shared by the preview stage and the viewer).
#pragma once

#include "pipeline/scene/scene.h"
#include "render/preview/preview.h"

namespace hp {

/// The preview settings of the scene. Throws SceneError for combinations a
/// single key cannot check (trilinear binary splatting, a region naming a
/// missing hair type).
PreviewSettings makePreviewSettings(const Scene& scene);

}  // namespace hp
