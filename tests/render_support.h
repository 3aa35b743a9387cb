// The small view the renderer tests (test_preview.cpp, test_reference.cpp)
// draw their strands in.
#pragma once

#include "render/view/simple_view.h"

namespace hp::test {

/// @brief A camera at (0, 0, 1) looking at the origin with a 40° vertical
/// field of view, `width` × `height` pixels, and one directional light (View's
/// default intensity and colour) travelling along `lightDirection`.
inline View frontView(int width, int height, const Vec3f& lightDirection = Vec3f(-1.f, -1.f, -1.f)) {
    return simpleView(Vec3f(0.f, 0.f, 1.f), Vec3f::Zero(), 40.f, width, height, lightDirection);
}

}  // namespace hp::test
