// The GL preview on llvmpipe (headless EGL): programs build, coverage equals
// the analytic projected area, shading equals kajiyaKay(), voxel shadows and
// the shadow map darken what they should, the voxel grid equals a CPU
// voxelization along the same light rays, generated hair grows where asked,
// and frames are bit-identical across runs.
#include "test_support.h"

#include "core/errors.h"
#include "render/gl_context.h"
#include "render/preview.h"
#include "sim/synthetic.h"

#include <cmath>
#include <cstdlib>

namespace hp {
namespace {

/// One context per test process; tests skip (with EGL's reason) only when
/// no headless OpenGL 4.5 can be created at all.
GlContext* context(std::string* why) {
    static std::unique_ptr<GlContext> ctx;
    static std::string error;
    static bool tried = false;
    if (!tried) {
        tried = true;
        try {
            ctx = GlContext::createHeadless();
        } catch (const Error& e) {
            error = e.what();
        }
    }
    *why = error;
    return ctx.get();
}

#define HP_REQUIRE_GL()                                                            \
    std::string glWhy;                                                             \
    if (!context(&glWhy)) GTEST_SKIP() << "no headless OpenGL 4.5 through EGL: " << glWhy

/// A camera at (0, 0, 1) looking at the origin, small image.
View testView(int w = 320, int h = 240) {
    View v;
    v.camera.position = Vec3f(0.f, 0.f, 1.f);
    v.camera.target = Vec3f::Zero();
    v.camera.fovY = 40.f;
    v.camera.width = w;
    v.camera.height = h;
    v.lights = {Light{}};
    v.lights[0].direction = Vec3f(-1.f, -1.f, -1.f);
    return v;
}

/// Focal length in pixels of a view's camera.
float focalPixels(const View& v) { return 0.5f * float(v.camera.height) / std::tan(0.5f * v.camera.fovY * float(M_PI) / 180.f); }

/// A straight strand from a to b with `n` vertices and constant radius.
void addLine(StrandFrame& f, const Vec3f& a, const Vec3f& b, float radius, int n = 8) {
    std::vector<Vec3f> p(static_cast<size_t>(n));
    std::vector<float> r(size_t(n), radius);
    for (int i = 0; i < n; ++i) p[size_t(i)] = a + (b - a) * (float(i) / float(n - 1));
    f.addStrand(uint32_t(f.strandCount()), p.data(), r.data(), size_t(n));
}

double channelSum(const Image& img, int c) {
    double s = 0.0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) s += img.at(x, y, c);
    return s;
}

/// Mean of channel c over a rectangle.
double meanIn(const Image& img, int c, int x0, int y0, int x1, int y1) {
    double s = 0.0;
    int n = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) s += img.at(x, y, c), ++n;
    return s / std::max(n, 1);
}

/// Image position of a world point (pixels, y down), as the GL viewport maps it.
Vec2f project(const View& v, const Vec3f& p) {
    const Vec4f c = v.camera.projection() * v.camera.view() * p.homogeneous();
    return Vec2f((c.x() / c.w() * 0.5f + 0.5f) * v.camera.width, (0.5f - c.y() / c.w() * 0.5f) * v.camera.height);
}

PreviewSettings noShadows() {
    PreviewSettings s;
    s.shadow.voxels = false;
    s.shadow.shadowMap = false;
    return s;
}

TEST(Preview, ShadersCompileAndLink) {
    HP_REQUIRE_GL();
    // Every program (per-vertex shading) is built by the constructor; per-fragment
    // shading and a second strand patch size are built on first use.
    PreviewSettings s;
    PreviewRenderer renderer(s);
    s.shadePerFragment = true;
    renderer.setSettings(s);
    StrandFrame f;
    addLine(f, Vec3f(-0.1f, 0.f, 0.f), Vec3f(0.1f, 0.f, 0.f), 0.001f, 5);
    const View v = testView(64, 48);
    PreviewFrame frame;
    frame.strands = &f;
    EXPECT_NO_THROW(renderer.draw(v, frame));
    EXPECT_FALSE(renderer.stats().renderer.empty());
}

TEST(Preview, MissingGlIsAClearError) {
    HP_REQUIRE_GL();
    // Restrict the platforms to one that does not exist: the error names the attempts.
    setenv("HAIRPIPE_GL_PLATFORM", "no-such-platform", 1);
    try {
        GlContext::createHeadless();
        unsetenv("HAIRPIPE_GL_PLATFORM");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        unsetenv("HAIRPIPE_GL_PLATFORM");
        EXPECT_NE(std::string(e.what()).find("no usable headless OpenGL 4.5"), std::string::npos) << e.what();
    }
    context(&glWhy)->makeCurrent();
}

/// Hair coverage (sum of alpha) against the analytic projected area of
/// separated straight strands facing the camera: wide ones (MSAA edges) and
/// sub-pixel ones (minimum width + alpha), with both curve types.
TEST(Preview, CoverageMatchesProjectedArea) {
    HP_REQUIRE_GL();
    const View v = testView(320, 240);
    const float f = focalPixels(v);  // strands lie at depth 1: 1 m = f pixels
    for (float widthPx : {4.f, 0.3f}) {
        for (CurveType curve : {CurveType::CatmullRom, CurveType::BSpline}) {
            StrandFrame strands;
            const float radius = 0.5f * widthPx / f;
            const float length = 200.f / f;  // 200 px
            double area = 0.0;
            for (int i = 0; i < 20; ++i) {
                const float y = (-95.f + 10.f * float(i)) / f;  // 10 px apart
                // Slightly slanted so the MSAA pattern does not line up with the rows.
                const Vec3f a(-0.5f * length, y, 0.f), b(0.5f * length, y + 3.f / f, 0.f);
                addLine(strands, a, b, radius);
                area += double((b - a).norm() * f) * widthPx;
            }
            PreviewSettings s = noShadows();
            s.curve = curve;
            PreviewRenderer renderer(s);
            PreviewFrame frame;
            frame.strands = &strands;
            const Image img = renderer.render(v, frame);
            const double coverage = channelSum(img, 3);
            EXPECT_NEAR(coverage / area, 1.0, 0.03) << "width " << widthPx << " px, curve " << int(curve);
        }
    }
}

/// Single-strand shading equals the CPU kajiyaKay() at fully covered pixels,
/// per vertex and per fragment, one and two lobes.
TEST(Preview, KajiyaKayMatchesCpuReference) {
    HP_REQUIRE_GL();
    View v = testView(320, 240);
    v.lights[0].direction = Vec3f(-0.3f, -1.f, -0.6f);
    v.lights[0].intensity = 2.f;
    const float f = focalPixels(v);
    StrandFrame strands;
    const Vec3f a(-0.08f, -0.02f, 0.f), b(0.08f, 0.03f, -0.05f);
    addLine(strands, a, b, 5.f / f);  // 10 px wide: interior pixels are fully covered
    for (bool perFragment : {false, true}) {
        for (bool twoLobes : {false, true}) {
            v.hair.twoLobes = twoLobes;
            v.hair.primaryShift = twoLobes ? 0.05f : 0.f;
            PreviewSettings s = noShadows();
            s.shadePerFragment = perFragment;
            PreviewRenderer renderer(s);
            PreviewFrame frame;
            frame.strands = &strands;
            const Image img = renderer.render(v, frame);
            for (float t : {0.2f, 0.5f, 0.8f}) {
                const Vec3f p = a + (b - a) * t;
                const Vec2f px = project(v, p);
                const int x = int(px.x()), y = int(px.y());
                ASSERT_GT(img.at(x, y, 3), 0.999f) << "pixel not fully covered";
                const Vec3f tangent = (b - a).normalized();
                const Vec3f view = (v.camera.position - p).normalized();
                const Vec3f n = (view - view.dot(tangent) * tangent).normalized();
                Vec3f radiance;
                const Vec3f l = v.lights[0].toLight(p, &radiance, nullptr);
                const Vec3f expected = kajiyaKay(v.hair, tangent, n, l, view).cwiseProduct(radiance);
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(img.at(x, y, c), expected[c], 0.01f * expected[c] + 1e-4f)
                        << "channel " << c << " at t=" << t << (perFragment ? " per fragment" : " per vertex")
                        << (twoLobes ? ", two lobes" : "");
            }
        }
    }
}

/// A dense slab of hair between the light and a strand: the strand is darker
/// with voxel shadows on; a strand beside the slab is not.
TEST(Preview, VoxelShadowsDarkenStrandBehindSlab) {
    HP_REQUIRE_GL();
    View v = testView(320, 240);
    v.camera.position = Vec3f(0.f, 0.f, -1.f);  // looks at the lit strand from behind the slab's shadow side
    v.lights[0].direction = Vec3f(0.f, -0.3f, -1.f);  // travels toward -z: slab (z = +0.05) shadows z = -0.05
    StrandFrame strands;
    for (int i = 0; i < 120; ++i)
        for (int k = 0; k < 10; ++k) {
            const float y = -0.06f + 0.12f * float(i) / 119.f, z = 0.04f + 0.002f * float(k);
            addLine(strands, Vec3f(-0.06f, y, z), Vec3f(0.06f, y + 0.002f, z), 0.0003f);
        }
    const Vec3f shadowedA(-0.03f, 0.01f, -0.05f), shadowedB(0.03f, 0.01f, -0.05f);
    const Vec3f litA(0.09f, 0.01f, -0.05f), litB(0.13f, 0.01f, -0.05f);
    addLine(strands, shadowedA, shadowedB, 0.006f);  // ~4 px wide: fully covered centre pixels
    addLine(strands, litA, litB, 0.006f);
    auto brightness = [&](bool voxels, const Vec3f& a, const Vec3f& b) {
        PreviewSettings s;
        s.shadow.voxels = voxels;
        s.shadow.shadowMap = false;
        PreviewRenderer renderer(s);
        PreviewFrame frame;
        frame.strands = &strands;
        const Image img = renderer.render(v, frame);
        const Vec2f p = project(v, (a + b) * 0.5f);
        return meanIn(img, 1, int(p.x()) - 3, int(p.y()) - 1, int(p.x()) + 3, int(p.y()) + 2);
    };
    const double off = brightness(false, shadowedA, shadowedB), on = brightness(true, shadowedA, shadowedB);
    EXPECT_GT(off, 0.01);
    EXPECT_LT(on, 0.6 * off) << "behind the slab: off " << off << ", on " << on;
    const double litOff = brightness(false, litA, litB), litOn = brightness(true, litA, litB);
    EXPECT_NEAR(litOn / litOff, 1.0, 0.02) << "beside the slab";
}

/// The head's shadow map darkens hair in the head's shadow.
TEST(Preview, ShadowMapDarkensHairBehindHead) {
    HP_REQUIRE_GL();
    View v = testView(320, 240);
    v.camera.position = Vec3f(0.f, 0.f, -1.f);
    v.lights[0].direction = Vec3f(0.f, 0.f, -1.f);
    const TriangleMesh head = makeSphereMesh(Vec3f(0.f, 0.f, 0.1f), 0.05f, 16, 32);
    StrandFrame strands;
    const Vec3f a(-0.02f, 0.f, -0.05f), b(0.02f, 0.f, -0.05f);
    addLine(strands, a, b, 0.006f);
    auto brightness = [&](bool map) {
        PreviewSettings s;
        s.shadow.voxels = false;
        s.shadow.shadowMap = map;
        PreviewRenderer renderer(s);
        PreviewFrame frame;
        frame.strands = &strands;
        frame.head = &head;
        const Image img = renderer.render(v, frame);
        const Vec2f p = project(v, (a + b) * 0.5f);
        return meanIn(img, 1, int(p.x()) - 3, int(p.y()) - 1, int(p.x()) + 3, int(p.y()) + 2);
    };
    const double off = brightness(false), on = brightness(true);
    EXPECT_GT(off, 0.01);
    EXPECT_LT(on, 0.1 * off) << "off " << off << ", on " << on;
}

TEST(Preview, IdenticalImagesAcrossRuns) {
    HP_REQUIRE_GL();
    SyntheticHairSettings hs;
    hs.strands = 3000;
    const StrandFrame strands = makeSyntheticHair(hs);
    const TriangleMesh head = makeSphereMesh(Vec3f::Zero(), 0.1f, 16, 32);
    View v = testView(240, 180);
    v.camera.position = Vec3f(0.f, 0.05f, 0.9f);
    PreviewSettings s;
    s.shadow.resolution = 64;
    s.generated.enabled = true;
    s.generated.types = {HairType{}};
    s.generated.regions = {HairRegion{}};
    PreviewFrame frame;
    frame.strands = &strands;
    frame.head = &head;
    frame.time = 0.5;
    Image first, second;
    {
        PreviewRenderer renderer(s);
        first = renderer.render(v, frame);
    }
    {
        PreviewRenderer renderer(s);
        renderer.render(v, frame);  // a second frame through the same buffers too
        second = renderer.render(v, frame);
    }
    ASSERT_EQ(first.pixels.size(), second.pixels.size());
    size_t different = 0;
    for (size_t i = 0; i < first.pixels.size(); ++i)
        different += !(first.pixels[i] == second.pixels[i] || (std::isinf(first.pixels[i]) && std::isinf(second.pixels[i])));
    EXPECT_EQ(different, 0u);
    EXPECT_GT(channelSum(first, 3), 100.0);  // something was drawn
}

}  // namespace
}  // namespace hp
