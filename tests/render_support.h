// The small view the renderer tests (test_preview.cpp, test_reference.cpp)
// draw their strands in, and the jittered slab of strands the shadow and
// skin tests (test_preview_shadows.cpp, test_preview_skin.cpp) put in it.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "render/image/image_io.h"
#include "render/reference/hair_fit.h"
#include "render/view/simple_view.h"
#include "sim/strands/head.h"
#include "sim/strands/synthetic.h"

namespace hp::test {

/// Writes `img` as <HAIRPIPE_TEST_DUMP>/<name>.exr when that variable names a
/// folder (to look at a renderer test's images); does nothing otherwise.
inline void dump(const std::string& name, const Image& img) {
    if (const char* dir = std::getenv("HAIRPIPE_TEST_DUMP")) writeImage(std::string(dir) + "/" + name + ".exr", img);
}

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

/// A slab of straight vertical strands (y from -0.12 to 0.12 m, 8 vertices)
/// of one radius, jittered on a columns × rows lattice over x0..x1 × z0..z1
/// by a deterministic generator seeded with `seed`.
inline StrandFrame strandSlab(int columns, int rows, float x0, float x1, float z0, float z1, float radius, uint32_t seed) {
    StrandFrame slab;
    auto random = [&seed] {  // deterministic, in [0, 1)
        seed = seed * 1664525u + 1013904223u;
        return float(seed >> 8) / float(1u << 24);
    };
    for (int i = 0; i < columns; ++i)
        for (int k = 0; k < rows; ++k) {
            const float x = x0 + (x1 - x0) * (float(i) + random()) / float(columns);
            const float z = z0 + (z1 - z0) * (float(k) + random()) / float(rows);
            std::vector<Vec3f> p;
            for (int j = 0; j < 8; ++j) p.push_back(Vec3f(x, -0.12f + 0.24f * float(j) / 7.f, z));
            const std::vector<float> r(p.size(), radius);
            slab.addStrand(uint32_t(slab.strandCount()), p.data(), r.data(), p.size());
        }
    return slab;
}

/// Image position of a world point (pixels, y down).
inline Vec2f project(const View& v, const Vec3f& p) {
    const Vec4f c = v.camera.projection() * v.camera.view() * p.homogeneous();
    return Vec2f((c.x() / c.w() * 0.5f + 0.5f) * v.camera.width, (0.5f - c.y() / c.w() * 0.5f) * v.camera.height);
}

}  // namespace hp::test
