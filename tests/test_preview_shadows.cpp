// The preview shadows every light that casts shadows (up to
// PreviewShadowSettings::maxLights), each through its own light grid, voxel
// density and head shadow map: a second light's shadow through a slab of hair
// is Beer-Lambert's, computed here from the slab's strand density (the skin
// under and behind the hair: test_preview_skin.cpp); shadowing the rig's fill
// darkens the hair; the cap and the slot order hold.
//
// Set HAIRPIPE_TEST_DUMP=<folder> to write the images as EXR there.
#include "gl_support.h"
#include "render_support.h"
#include "test_support.h"

#include "render/image/image_io.h"
#include "render/preview/gl_context.h"
#include "render/preview/preview.h"
#include "render/reference/hair_fit.h"
#include "sim/strands/synthetic.h"

#include <cmath>
#include <iostream>

namespace hp {
namespace {

using test::dump;

using test::project;
using test::renderOnce;
using test::strandSlab;

/// Sum of the green channel over the image of the plane rectangle x0..x1 × y0..y1 (z = 0).
double greenOver(const Image& img, const View& v, float x0, float x1, float y0, float y1) {
    const Vec2f a = project(v, Vec3f(x0, y1, 0.f)), b = project(v, Vec3f(x1, y0, 0.f));
    double sum = 0.0;
    for (int y = int(std::ceil(a.y())); y < int(b.y()); ++y)
        for (int x = int(std::ceil(a.x())); x < int(b.x()); ++x) sum += img.at(x, y, 1);
    return sum;
}

// A flat "head" at z = 0 facing the camera, a slab of straight strands along
// y in front of it (x 0.04..0.16, z 0.04..0.08, jittered on a 100 x 20
// lattice: n per m² across the strands, uniform to within a lattice cell),
// and two directional lights: light 0 from the upper left, which reaches the
// probe region (x 0.005..0.03) past the slab, and light 1 from the right,
// whose rays from the probe region cross the slab's whole thickness at 45°,
// a path of L = 0.04 √2 m. Hair of radius r perpendicular to a ray blocks it
// where a strand's centre lies within r of it, so the expected crossings are
// C = n · 2r · L (Beer-Lambert with the slab's cross-section density), and
// the preview keeps exp(-(1 - T) C) of light 1 there (T: per-crossing
// transmittance, render.hair.transmittance). The camera sees the probe region
// in front of the slab, so its pixels are the plane's shading alone.
TEST(PreviewShadows, SecondLightThroughHairIsBeerLambert) {
    HP_REQUIRE_GL();
    const float radius = 0.0001f;
    const int columns = 100, rows = 20;
    const float x0 = 0.04f, x1 = 0.16f, z0 = 0.04f, z1 = 0.08f;
    const StrandFrame slab = strandSlab(columns, rows, x0, x1, z0, z1, radius, 2024u);
    const double density = double(columns * rows) / double((x1 - x0) * (z1 - z0));
    const double path = double(z1 - z0) * std::sqrt(2.0);
    const double crossings = density * 2.0 * radius * path;

    TriangleMesh plane;
    plane.positions = {Vec3f(-0.15f, -0.15f, 0.f), Vec3f(0.17f, -0.15f, 0.f), Vec3f(0.17f, 0.15f, 0.f),
                       Vec3f(-0.15f, 0.15f, 0.f)};
    plane.triangles = {Tri{0, 1, 2}, Tri{0, 2, 3}};
    plane.computeNormals();

    View v = test::frontView(320, 240);
    v.environment = Vec3f::Zero();
    v.head.ambient = 0.f;
    Light left, right;
    left.direction = Vec3f(1.f, 0.f, -1.f);
    right.direction = Vec3f(-1.f, 0.f, -1.f);
    left.intensity = right.intensity = 2.f;
    v.lights = {left, right};
    const double transmittance = std::exp(-(1.0 - double(v.hair.transmittance)) * crossings);

    PreviewSettings s;
    s.shadow.resolution = 128;
    s.shadow.otherResolution = 96;  // slot 1 on a grid of its own resolution
    PreviewStats stats;
    VoxelSnapshot grid;
    const Image both = renderOnce(s, v, slab, &plane, &stats, &grid);
    EXPECT_EQ(stats.shadowedLights, 2);
    View unshadowed = v;
    unshadowed.lights[1].castsShadows = false;
    const Image open = renderOnce(s, unshadowed, slab, &plane);
    View dark = v;
    dark.lights[1].intensity = 0.f;
    const Image none = renderOnce(s, dark, slab, &plane);
    dump("slab.both", both);
    dump("slab.open", open);

    // The slot's grid: C at probe points on the plane, against n 2r L.
    ASSERT_EQ(grid.resolution, 96);
    ASSERT_FALSE(grid.summed.empty());
    double gridC = 0.0;
    int probes = 0;
    for (float x = 0.006f; x < 0.03f; x += 0.002f)
        for (float y = -0.05f; y <= 0.05f; y += 0.01f) {
            const Vec3f g = grid.grid.toGrid(Vec3f(x, y, 0.f)) * float(grid.resolution);
            gridC += grid.summedAt(int(g.x()), int(g.y()), std::min(int(g.z()), grid.resolution - 1));
            ++probes;
        }
    gridC /= probes;
    EXPECT_NEAR(gridC / crossings, 1.0, 0.1) << "slot 1's C " << gridC << ", analytic n 2r L = " << crossings;

    // The image: light 1's share of the probe region, shadowed over unshadowed.
    const double lit = greenOver(both, v, 0.005f, 0.03f, -0.05f, 0.05f) - greenOver(none, v, 0.005f, 0.03f, -0.05f, 0.05f);
    const double full = greenOver(open, v, 0.005f, 0.03f, -0.05f, 0.05f) - greenOver(none, v, 0.005f, 0.03f, -0.05f, 0.05f);
    ASSERT_GT(full, 1.0) << "light 1 lights the probe region";
    EXPECT_NEAR(lit / full / transmittance, 1.0, 0.1)
        << "light 1 through the slab: preview keeps " << lit / full << ", Beer-Lambert exp(-(1 - T) n 2r L) = "
        << transmittance;
    // Light 0 does not cross the slab: unshadowing light 1 leaves its share alone.
    View onlyLeft = v;
    onlyLeft.lights[1].intensity = 0.f;
    onlyLeft.lights[1].castsShadows = false;
    const double leftShare = greenOver(renderOnce(s, onlyLeft, slab, &plane), v, 0.005f, 0.03f, -0.05f, 0.05f);
    EXPECT_NEAR(leftShare / greenOver(none, v, 0.005f, 0.03f, -0.05f, 0.05f), 1.0, 1e-4);
    std::cout << "C grid " << gridC << " analytic " << crossings << "; light 1 kept " << lit / full
              << " Beer-Lambert " << transmittance << "\n";
}

/// Luminance sum over pixels where both images have hair coverage above 0.2.
double hairLight(const Image& img, const Image& mask) {
    double sum = 0.0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            if (mask.at(x, y, 3) > 0.2f)
                sum += 0.2126 * img.at(x, y, 0) + 0.7152 * img.at(x, y, 1) + 0.0722 * img.at(x, y, 2);
    return sum;
}

// Hair on a head under the three-point rig, every light shadowed: the fill's
// light on the hair, with the fill shadowed, is what reaches it through the
// hair in front, less than unshadowed (in Kajiya-Kay shading, visibility only
// multiplies: no pixel gets brighter), by a measurable share, but not all of
// it (the hair facing the fill is lit).
TEST(PreviewShadows, ShadowingTheFillDarkensTheHair) {
    HP_REQUIRE_GL();
    test::HairOnHead h = test::hairOnHead(240, 180);
    h.view.lights = threePointRig();
    h.view.head.ambient = 0.f;
    PreviewSettings s;
    s.shadow.resolution = 96;
    s.shadow.otherResolution = 64;
    PreviewStats stats;
    const Image shadowed = renderOnce(s, h.view, h.strands, &h.head, &stats);
    EXPECT_EQ(stats.shadowedLights, 3);
    View open = h.view;
    open.lights[1].castsShadows = false;
    const Image unshadowed = renderOnce(s, open, h.strands, &h.head);
    View noFill = h.view;
    noFill.lights[1].intensity = 0.f;
    const Image without = renderOnce(s, noFill, h.strands, &h.head);
    dump("rig.shadowed", shadowed);
    dump("rig.unshadowed", unshadowed);
    size_t brighter = 0;
    for (int y = 0; y < shadowed.height; ++y)
        for (int x = 0; x < shadowed.width; ++x)
            for (int c = 0; c < 3; ++c)
                brighter += shadowed.at(x, y, c) > unshadowed.at(x, y, c) * 1.0001f + 1e-6f;
    EXPECT_EQ(brighter, 0u) << "shadowing a light never brightens Kajiya-Kay hair";
    const double kept = (hairLight(shadowed, shadowed) - hairLight(without, shadowed)) /
                        (hairLight(unshadowed, shadowed) - hairLight(without, shadowed));
    // Measured 0.94 on llvmpipe: the synthetic head's 3000 strands are a thin
    // layer, and the fill lights the side of it that faces the fill.
    EXPECT_LT(kept, 0.97) << "the hair in front of the hair hides a measurable part of the fill";
    EXPECT_GT(kept, 0.2) << "the front hair, lit by the fill, is not in shadow";
    std::cout << "fill kept on the hair: " << kept << "\n";

    // Fitted hair: the fill and rim through the hair in front (coloured
    // forward scattering) instead of the forward chain of unshadowed lights.
    fitHairMaterial(HairFiberParams{}, &h.view.hair);
    View fittedOpen = h.view;
    fittedOpen.lights[1].castsShadows = fittedOpen.lights[2].castsShadows = false;
    const double fittedRatio = hairLight(renderOnce(s, h.view, h.strands, &h.head), shadowed) /
                               hairLight(renderOnce(s, fittedOpen, h.strands, &h.head), shadowed);
    EXPECT_LT(fittedRatio, 0.97) << "fitted hair: shadowing fill and rim darkens the hair";
    std::cout << "fitted hair, fill and rim shadowed / unshadowed: " << fittedRatio << "\n";
}

// The preview shadows the first maxLights lights with castsShadows, in order,
// slot k being the k-th of them (its grid is fitted to that light).
TEST(PreviewShadows, CapAndOrderOfShadowedLights) {
    HP_REQUIRE_GL();
    test::HairOnHead h = test::hairOnHead(64, 48);
    h.view.lights.clear();
    for (int i = 0; i < 6; ++i) {
        Light l;
        l.direction = Vec3f(std::cos(float(i)), -1.f, std::sin(float(i)));
        l.castsShadows = i != 1;
        h.view.lights.push_back(l);
    }
    PreviewSettings s;
    s.shadow.resolution = s.shadow.otherResolution = 16;
    for (int cap : {0, 2, 4}) {
        s.shadow.maxLights = cap;
        PreviewRenderer renderer(s);
        PreviewFrame frame;
        frame.strands = &h.strands;
        frame.head = &h.head;
        renderer.draw(h.view, frame);
        EXPECT_EQ(renderer.stats().shadowedLights, cap);
        const int expected[] = {0, 2, 3, 4};  // light 1 casts no shadows
        for (int k = 0; k < cap; ++k) {
            const VoxelSnapshot snap = renderer.readVoxels(k);
            ASSERT_EQ(snap.resolution, 16) << k;
            const Vec3f beam = -snap.grid.view.block<1, 3>(2, 0).transpose();  // the light view's -Z
            EXPECT_GT(beam.dot(h.view.lights[size_t(expected[k])].direction.normalized()), 0.9999f) << "slot " << k;
        }
        EXPECT_EQ(renderer.readVoxels(cap).resolution, 0) << "no slot past the cap";
    }
}

// The strands are tessellated once, from the first shadowed light, and the
// captured pieces voxelized into every light's grid
// (PreviewShadowSettings::shareTessellation). Each grid, summed and times a
// voxel column's cross-section, is the hair's projected area seen from its
// light, sum of 2 r |segment| sin(theta) with theta between strand and that
// light, computed here from straight strands (whose pieces are exact
// whatever the tessellation); the first light's grid is the same with and
// without sharing.
TEST(PreviewShadows, SharedTessellationFillsEveryLightsGrid) {
    HP_REQUIRE_GL();
    View v = test::frontView(64, 48);
    const Vec3f directions[] = {Vec3f(0.f, 0.f, -1.f), Vec3f(1.f, -0.3f, -0.6f), Vec3f(-0.4f, -1.f, 0.5f)};
    v.lights.assign(3, v.lights[0]);
    for (int k = 0; k < 3; ++k) v.lights[size_t(k)].direction = directions[k].normalized();
    StrandFrame strands;
    uint32_t seed = 4242;
    auto random = [&seed] {
        seed = seed * 1664525u + 1013904223u;
        return float(seed >> 8) / float(1u << 24);
    };
    const float radius = 0.0001f;
    std::vector<std::pair<Vec3f, Vec3f>> lines;
    for (int i = 0; i < 200; ++i) {
        const Vec3f a(-0.04f + 0.02f * random(), -0.04f + 0.08f * random(), -0.04f + 0.08f * random());
        const Vec3f b(0.04f - 0.02f * random(), -0.04f + 0.08f * random(), -0.04f + 0.08f * random());
        std::vector<Vec3f> p(9);
        for (int j = 0; j < 9; ++j) p[size_t(j)] = a + (b - a) * (float(j) / 8.f);
        const std::vector<float> r(9, radius);
        strands.addStrand(uint32_t(i), p.data(), r.data(), 9);  // two sorted patches of 4 segments
        lines.push_back({a, b});
    }
    auto grids = [&](bool share) {
        PreviewSettings s;
        s.shadow.resolution = 64;
        s.shadow.otherResolution = 48;
        s.shadow.shareTessellation = share;
        PreviewRenderer renderer(s);
        PreviewFrame frame;
        frame.strands = &strands;
        renderer.draw(v, frame);
        EXPECT_EQ(renderer.stats().shadowedLights, 3);
        std::vector<VoxelSnapshot> out;
        for (int k = 0; k < 3; ++k) out.push_back(renderer.readVoxels(k));
        return out;
    };
    const std::vector<VoxelSnapshot> shared = grids(true), own = grids(false);
    for (int k = 0; k < 3; ++k) {
        const VoxelSnapshot& snap = shared[size_t(k)];
        ASSERT_EQ(snap.resolution, k == 0 ? 64 : 48);
        ASSERT_FALSE(snap.grid.perspective);
        const Vec3f d = v.lights[size_t(k)].direction.normalized();
        double projected = 0.0;
        for (const auto& [a, b] : lines) projected += 2.0 * radius * double((b - a).cross(d).norm());
        double crossings = 0.0;
        for (float c : snap.raw) crossings += c;
        const double res = snap.resolution;
        const double column = 1.0 / (double(snap.grid.scale.x()) * res * double(snap.grid.scale.y()) * res);
        EXPECT_NEAR(crossings * column / projected, 1.0, 0.05)
            << "light " << k << ": grid " << crossings * column << " m^2, strands " << projected << " m^2";
        std::cout << "light " << k << " (shared tessellation): grid / projected area " << crossings * column / projected
                  << "\n";
    }
    EXPECT_EQ(shared[0].raw, own[0].raw) << "the first light's grid does not depend on sharing";
    EXPECT_EQ(shared[0].summed, own[0].summed);
}

// The hair programs are compiled for the lights, flags and hair model they
// shade (render/preview/preview_uniforms.cpp hairShadingDefines). They give
// the bytes of the one program that reads all of these from uniforms
// (PreviewSettings::specializeShading false), for views that differ in each;
// and one renderer drawing these views one after the other gives each view
// the bytes a renderer made for that view alone gives it (a program kept
// from the view before would shade with its lights).
TEST(PreviewShadows, EachViewIsShadedWithItsOwnLights) {
    HP_REQUIRE_GL();
    test::HairOnHead h = test::hairOnHead(96, 72);
    h.view.head.ambient = 0.f;
    const std::vector<View> views = test::lightSetups(h.view);
    PreviewSettings s;
    s.shadow.resolution = 32;
    s.shadow.otherResolution = 16;
    PreviewRenderer renderer(s);
    PreviewFrame frame;
    frame.strands = &h.strands;
    frame.head = &h.head;
    auto differing = [](const Image& a, const Image& b) {
        size_t n = 0;
        for (size_t p = 0; p < a.pixels.size() && p < b.pixels.size(); ++p) n += a.pixels[p] != b.pixels[p];
        return n;
    };
    std::vector<Image> alone;
    for (const View& v : views) alone.push_back(renderOnce(s, v, h.strands, &h.head));
    for (size_t i = 1; i < views.size(); ++i)
        ASSERT_GT(differing(alone[i], alone[i - 1]), 100u) << "views " << i - 1 << " and " << i << " look different";
    PreviewSettings generic = s;
    generic.specializeShading = false;
    for (size_t i = 0; i < views.size(); ++i)
        EXPECT_EQ(differing(renderOnce(generic, views[i], h.strands, &h.head), alone[i]), 0u) << "view " << i;
    int previous = -1;
    for (int i : {0, 1, 2, 3, 2, 1, 0, 3, 0}) {  // each change both ways
        const Image shared = renderer.render(views[size_t(i)], frame);
        ASSERT_EQ(shared.pixels.size(), alone[size_t(i)].pixels.size());
        EXPECT_EQ(differing(shared, alone[size_t(i)]), 0u) << "view " << i << " drawn after view " << previous;
        previous = i;
    }
}

}  // namespace
}  // namespace hp
