// @brief The view of the B-render benchmarks (docs/benchmarks.md), which
// bench_preview and bench_reference both render: spelled out here rather than
// taken from View's defaults, so that a change of the defaults does not move
// the benchmark.
#pragma once

#include "render/view/simple_view.h"

namespace hp::bench {

/// @brief B-render's camera and light: an eye at (0, 0.05, 0.9) looking at
/// the origin with a 40° vertical field of view, `width` × `height` pixels;
/// one directional light travelling along (-1, -1, -1) with intensity 3;
/// black background.
inline View bRenderView(int width, int height) {
    View view = simpleView(Vec3f(0.f, 0.05f, 0.9f), Vec3f::Zero(), 40.f, width, height, Vec3f(-1.f, -1.f, -1.f));
    view.lights[0].intensity = 3.f;
    view.environment = Vec3f::Zero();
    return view;
}

}  // namespace hp::bench
