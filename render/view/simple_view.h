// @brief A view of one camera and one directional light, everything else
// View's defaults: what the renderer tests and the B-render benchmarks draw
// their synthetic strands with (a shot's view comes from the scene's render
// keys instead, pipeline/scene/view_settings.h).
#pragma once

#include "render/view/view.h"

namespace hp {

/// @brief A camera at `eye` looking at `target` with a vertical field of
/// view of `fovY` degrees, `width` × `height` pixels, and one directional
/// light (View's default intensity and colour) travelling along
/// `lightDirection`.
inline View simpleView(const Vec3f& eye, const Vec3f& target, float fovY, int width, int height,
                       const Vec3f& lightDirection) {
    View v;
    v.camera.position = eye;
    v.camera.target = target;
    v.camera.fovY = fovY;
    v.camera.width = width;
    v.camera.height = height;
    v.lights = {Light{}};
    v.lights[0].type = LightType::Directional;
    v.lights[0].direction = lightDirection;
    return v;
}

}  // namespace hp
