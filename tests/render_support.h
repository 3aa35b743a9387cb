// The small view the renderer tests (test_preview.cpp, test_reference.cpp)
// draw their strands in.
#pragma once

#include "render/reference/hair_fit.h"
#include "render/view/simple_view.h"
#include "sim/strands/head.h"
#include "sim/strands/synthetic.h"

namespace hp::test {

/// @brief A camera at (0, 0, 1) looking at the origin with a 40° vertical
/// field of view, `width` × `height` pixels, and one directional light (View's
/// default intensity and colour) travelling along `lightDirection`.
inline View frontView(int width, int height, const Vec3f& lightDirection = Vec3f(-1.f, -1.f, -1.f)) {
    return simpleView(Vec3f(0.f, 0.f, 1.f), Vec3f::Zero(), 40.f, width, height, lightDirection);
}

/// frontView (camera at (0, 0, 1) looking at the origin) with a warm light
/// of intensity 2 and a black environment.
inline View testView(int width, int height, const Vec3f& lightDirection) {
    View v = frontView(width, height, lightDirection);
    v.lights[0].intensity = 2.f;
    v.lights[0].color = Vec3f(1.f, 0.9f, 0.8f);
    v.environment = Vec3f::Zero();
    return v;
}

/// 3000 synthetic strands on their 0.1 m sphere head (16 x 32 facets), seen
/// from (0, 0.05, 0.9) in testView's light from (-1, -1, -1).
struct HairOnHead {
    StrandFrame strands;
    TriangleMesh head;
    View view;
};

inline HairOnHead hairOnHead(int width, int height) {
    SyntheticHairSettings hs;
    hs.strands = 3000;
    HairOnHead h{makeSyntheticHair(hs), makeSphereMesh(Vec3f::Zero(), 0.1f, 16, 32),
                 testView(width, height, Vec3f(-1.f, -1.f, -1.f))};
    h.view.camera.position = Vec3f(0.f, 0.05f, 0.9f);
    return h;
}

/// @brief Four light set-ups of `base` that exercise every shading path
/// of the preview's hair programs (test_preview_shadows.cpp,
/// test_preview_compute.cpp): 0 one light, shadowed, Kajiya-Kay; 1 the rig with
/// the rim unshadowed; 2 the same with fitted hair and an unshadowed point
/// light; 3 no light shadowed.
inline std::vector<View> lightSetups(const View& base) {
    std::vector<View> views(4, base);
    views[1].lights = threePointRig();
    views[1].lights[2].castsShadows = false;
    views[2] = views[1];
    fitHairMaterial(HairFiberParams{}, &views[2].hair);
    Light point;
    point.type = LightType::Point;
    point.position = Vec3f(0.4f, 0.3f, 0.6f);
    point.intensity = 0.2f;
    point.castsShadows = false;
    views[2].lights.push_back(point);
    views[3] = views[2];
    for (Light& l : views[3].lights) l.castsShadows = false;
    return views;
}

}  // namespace hp::test
