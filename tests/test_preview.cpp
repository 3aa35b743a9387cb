// The GL preview on llvmpipe (headless EGL): programs build, coverage equals
// the analytic projected area, shading equals kajiyaKay(), voxel shadows and
// the shadow map darken what they should, the voxel grid equals a CPU
// voxelization along the same light rays, generated hair grows where asked,
// and frames are bit-identical across runs.
#include "gl_support.h"
#include "kajiya_kay_oracle.h"
#include "render_support.h"
#include "test_support.h"

#include "core/errors.h"
#include "render/preview/gl_context.h"
#include "render/preview/preview.h"
#include "sim/strands/synthetic.h"

#include <cmath>
#include <cstdlib>
#include <map>

namespace hp {
namespace {

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

using test::renderOnce;

/// The shadow voxels a fresh renderer with settings `s` fills for one draw of `strands`.
VoxelSnapshot voxelsOf(const PreviewSettings& s, const View& v, const StrandFrame& strands) {
    PreviewRenderer renderer(s);
    PreviewFrame frame;
    frame.strands = &strands;
    renderer.draw(v, frame);
    return renderer.readVoxels();
}

/// Mean green over the 6 x 3 pixels around the image of segment ab's midpoint.
double brightnessAt(const Image& img, const View& v, const Vec3f& a, const Vec3f& b) {
    const Vec2f p = project(v, (a + b) * 0.5f);
    return meanIn(img, 1, int(p.x()) - 3, int(p.y()) - 1, int(p.x()) + 3, int(p.y()) + 2);
}

TEST(Preview, ShadersCompileAndLink) {
    HP_REQUIRE_GL();
    // Every program (per-vertex shading) is built by the constructor; per-fragment
    // shading and a second strand patch size are built on first use.
    // Each program must not only link but draw: a strand across the middle
    // of the frame covers the centre pixel and leaves the corners empty.
    PreviewSettings s;
    PreviewRenderer renderer(s);
    StrandFrame f;
    addLine(f, Vec3f(-0.1f, 0.f, 0.f), Vec3f(0.1f, 0.f, 0.f), 0.001f, 5);
    const View v = test::frontView(64, 48);
    PreviewFrame frame;
    frame.strands = &f;
    for (bool perFragment : {false, true}) {
        s.shadePerFragment = perFragment;
        renderer.setSettings(s);
        const Image img = renderer.render(v, frame);
        const Vec2f centre = project(v, Vec3f::Zero());
        // Sub-pixel hair: its alpha is its true width in pixels (about 0.07 here).
        EXPECT_GT(img.at(int(centre.x()), int(centre.y()), 3), 0.02f) << (perFragment ? "per fragment" : "per vertex");
        EXPECT_GT(img.at(int(centre.x()), int(centre.y()), 0), 0.f) << "the strand is lit";
        EXPECT_EQ(img.at(0, 0, 3), 0.f);
        EXPECT_EQ(img.at(63, 47, 3), 0.f);
    }
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
    test::glContext(&glWhy)->makeCurrent();
}

/// Hair coverage (sum of alpha) against the analytic projected area of
/// separated straight strands facing the camera: wide ones (MSAA edges) and
/// sub-pixel ones (minimum width + alpha), with both curve types.
TEST(Preview, CoverageMatchesProjectedArea) {
    HP_REQUIRE_GL();
    const View v = test::frontView(320, 240);
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
            const Image img = renderOnce(s, v, strands);
            const double coverage = channelSum(img, 3);
            EXPECT_NEAR(coverage / area, 1.0, 0.03) << "width " << widthPx << " px, curve " << int(curve);
        }
    }
}

/// Single-strand shading equals the CPU kajiyaKay() at fully covered pixels,
/// per vertex and per fragment, one and two lobes.
TEST(Preview, KajiyaKayMatchesCpuReference) {
    HP_REQUIRE_GL();
    View v = test::frontView(320, 240);
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
            const Image img = renderOnce(s, v, strands);
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
                const Vec3f expected = test::seedKajiyaKay(v.hair, tangent, n, l, view).cwiseProduct(radiance);
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(img.at(x, y, c), expected[c], 0.01f * expected[c] + 1e-4f)
                        << "channel " << c << " at t=" << t << (perFragment ? " per fragment" : " per vertex")
                        << (twoLobes ? ", two lobes" : "");
            }
        }
    }
}

/// A dense slab of hair between the light and a strand: the strand is darker
/// with voxel shadows on; a strand beside the slab is not. Directional lights
/// use an orthographic light box, point lights a perspective frustum.
TEST(Preview, VoxelShadowsDarkenStrandBehindSlab) {
    HP_REQUIRE_GL();
    View v = test::frontView(320, 240);
    v.camera.position = Vec3f(0.f, 0.f, -1.f);  // looks at the lit strand from behind the slab's shadow side
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
    Light directional;
    directional.direction = Vec3f(0.f, -0.3f, -1.f);  // travels toward -z: the slab (z = +0.05) shadows z = -0.05
    Light point;
    point.type = LightType::Point;
    point.position = Vec3f(0.f, 0.1f, 0.6f);
    point.intensity = 1.f;
    for (const Light& light : {directional, point}) {
        v.lights = {light};
        auto brightness = [&](bool voxels, const Vec3f& a, const Vec3f& b) {
            PreviewSettings s;
            s.shadow.voxels = voxels;
            s.shadow.shadowMap = false;
            PreviewStats stats;
            const Image img = renderOnce(s, v, strands, nullptr, &stats);
            EXPECT_EQ(stats.shadowed, voxels);
            return brightnessAt(img, v, a, b);
        };
        const char* kind = light.type == LightType::Point ? "point light" : "directional light";
        const double off = brightness(false, shadowedA, shadowedB), on = brightness(true, shadowedA, shadowedB);
        EXPECT_GT(off, 0.01) << kind;
        EXPECT_LT(on, 0.6 * off) << kind << ", behind the slab: off " << off << ", on " << on;
        const double litOff = brightness(false, litA, litB), litOn = brightness(true, litA, litB);
        EXPECT_NEAR(litOn / litOff, 1.0, 0.02) << kind << ", beside the slab";
    }
}

/// The head's shadow map darkens hair in the head's shadow.
TEST(Preview, ShadowMapDarkensHairBehindHead) {
    HP_REQUIRE_GL();
    View v = test::frontView(320, 240);
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
        return brightnessAt(renderOnce(s, v, strands, &head), v, a, b);
    };
    const double off = brightness(false), on = brightness(true);
    EXPECT_GT(off, 0.01);
    EXPECT_LT(on, 0.1 * off) << "off " << off << ", on " << on;
}

/// CPU voxelization of straight strands with the GPU's rules: a strand is a
/// line in the light's raster at the grid's resolution; it gives one fragment
/// per pixel by GL's diamond-exit rule (x-major lines: one per column), with
/// the line's attributes at the
/// pixel centre's projection onto the line (GL spec 14.5.1); that fragment
/// updates the grid like shaders/voxelize.frag (fixed point, 256 = 1).
std::vector<float> cpuVoxelize(const std::vector<std::pair<Vec3f, Vec3f>>& lines, const LightGrid& grid, int res,
                               VoxelMode mode, VoxelSplat splat) {
    std::vector<uint32_t> v(size_t(res) * res * res, 0);
    auto at = [&](int x, int y, int z) -> uint32_t* {
        if (x < 0 || y < 0 || z < 0 || x >= res || y >= res || z >= res) return nullptr;
        return &v[(size_t(z) * res + y) * res + x];
    };
    for (const auto& [a, b] : lines) {
        const Vec3f ga = grid.toGrid(a) * float(res), gb = grid.toGrid(b) * float(res);
        const Vec2f pa = ga.head<2>(), pb = gb.head<2>(), d = pb - pa;
        auto l1 = [](const Vec2f& p, const Vec2f& c) { return std::abs(p.x() - c.x()) + std::abs(p.y() - c.y()); };
        const int x0 = int(std::floor(std::min(pa.x(), pb.x()))) - 1, x1 = int(std::ceil(std::max(pa.x(), pb.x()))) + 1;
        for (int x = x0; x <= x1; ++x) {
            // Diamond-exit rule: pixel (x, r) is produced when the segment passes
            // through its diamond |dx| + |dy| < 1/2 and does not end inside it.
            const float xc = float(x) + 0.5f;
            const float tc = std::clamp((xc - pa.x()) / d.x(), 0.f, 1.f);
            const Vec2f centre(xc, std::floor(pa.y() + d.y() * tc) + 0.5f);
            float nearest = std::min(l1(pa, centre), l1(pb, centre));
            for (float t : {(centre.x() - pa.x()) / d.x(), (centre.y() - pa.y()) / d.y()})
                if (t > 0.f && t < 1.f) nearest = std::min(nearest, l1(pa + d * t, centre));
            if (nearest >= 0.5f || l1(pb, centre) < 0.5f) continue;
            // Attributes at the pixel centre's projection onto the line (GL spec 14.5.1).
            const float t = std::clamp((centre - pa).dot(d) / d.squaredNorm(), 0.f, 1.f);
            const Vec3f g = ga + (gb - ga) * t;
            if (splat == VoxelSplat::Nearest) {
                uint32_t* cell = at(x, int(std::floor(g.y())), int(std::floor(g.z())));
                if (cell) *cell = mode == VoxelMode::Binary ? 256u : *cell + 256u;
                continue;
            }
            const Vec3f c = g - Vec3f::Constant(0.5f);
            const Eigen::Vector3i base(int(std::floor(c.x())), int(std::floor(c.y())), int(std::floor(c.z())));
            const Vec3f f = c - base.cast<float>();
            for (int k = 0; k < 8; ++k) {
                const Eigen::Vector3i o(k & 1, (k >> 1) & 1, (k >> 2) & 1);
                float w = 1.f;
                for (int axis = 0; axis < 3; ++axis) w *= o[axis] ? f[axis] : 1.f - f[axis];
                if (uint32_t* cell = at(base.x() + o.x(), base.y() + o.y(), base.z() + o.z()))
                    *cell += uint32_t(std::lround(w * 256.f));
            }
        }
    }
    std::vector<float> out(v.size());
    for (size_t i = 0; i < v.size(); ++i) out[i] = float(v[i]) / 256.f;
    return out;
}

/// The summed voxel grid the GPU shades with equals a CPU voxelization summed
/// along the same light rays: transmittance alpha^C per voxel, for Dehlin and Styngberg 2017's
/// three voxelization modes.
// With preview.shadow.weight: crossings (the default) the additive grid holds
// expected strand crossings of a light ray: summed over the grid and times a
// voxel column's cross-section it is the hair's projected area seen from the
// light, sum of 2 r |segment| sin(theta) (theta between strand and light).
TEST(Preview, VoxelCrossingsAddUpToProjectedArea) {
    HP_REQUIRE_GL();
    View v = test::frontView(64, 48);
    v.lights[0].direction = Vec3f(0.f, 0.f, -1.f);
    StrandFrame strands;
    uint32_t seed = 777;
    auto random = [&seed] {
        seed = seed * 1664525u + 1013904223u;
        return float(seed >> 8) / float(1u << 24);
    };
    const float radius = 0.0001f;
    double projected = 0.0;
    for (int i = 0; i < 200; ++i) {
        // Strands at up to ~60 degrees to the light and in every direction across it.
        const Vec3f a(-0.04f + 0.02f * random(), -0.04f + 0.08f * random(), -0.04f + 0.02f * random());
        const Vec3f b(0.04f - 0.02f * random(), -0.04f + 0.08f * random(), 0.04f - 0.02f * random());
        addLine(strands, a, b, radius);
        projected += 2.0 * radius * double((b - a).head<2>().norm());
    }
    for (VoxelSplat splat : {VoxelSplat::Nearest, VoxelSplat::Trilinear}) {
        PreviewSettings s;
        s.shadow.resolution = 64;
        s.shadow.mode = VoxelMode::Additive;
        s.shadow.splat = splat;
        const VoxelSnapshot snap = voxelsOf(s, v, strands);
        ASSERT_EQ(snap.resolution, 64);
        ASSERT_FALSE(snap.grid.perspective);
        double crossings = 0.0;
        for (float c : snap.raw) crossings += c;
        const double column = 1.0 / (double(snap.grid.scale.x()) * 64.0 * double(snap.grid.scale.y()) * 64.0);
        EXPECT_NEAR(crossings * column / projected, 1.0, 0.05)
            << (splat == VoxelSplat::Nearest ? "nearest" : "trilinear") << ": grid " << crossings * column
            << " m^2, strands " << projected << " m^2";
        std::cout << (splat == VoxelSplat::Nearest ? "nearest" : "trilinear") << ": grid / projected area "
                  << crossings * column / projected << "\n";
    }
}

TEST(Preview, VoxelTransmittanceMatchesCpuVoxelization) {
    HP_REQUIRE_GL();
    View v = test::frontView(64, 48);
    v.lights[0].direction = Vec3f(0.f, 0.f, -1.f);  // the grid's u, v follow world x, y
    StrandFrame strands;
    std::vector<std::pair<Vec3f, Vec3f>> lines;
    uint32_t seed = 12345;
    auto random = [&seed] {  // deterministic, in [0, 1)
        seed = seed * 1664525u + 1013904223u;
        return float(seed >> 8) / float(1u << 24);
    };
    for (int i = 0; i < 300; ++i) {
        // x-major in the light's raster: along x with gentle slopes in y and z.
        const Vec3f a(-0.05f + 0.01f * random(), -0.04f + 0.08f * random(), -0.04f + 0.08f * random());
        const Vec3f b(0.04f + 0.01f * random(), a.y() + 0.03f * (random() - 0.5f), a.z() + 0.04f * (random() - 0.5f));
        addLine(strands, a, b, 0.0001f);
        lines.push_back({a, b});
    }
    const int res = 64;
    const float alpha = 0.85f;
    // One renderer for the three set-ups: its voxelization programs are
    // compiled for the voxel mode and splat (render/preview/voxel_programs.h)
    // and must follow each change of the settings.
    PreviewRenderer renderer{PreviewSettings{}};
    PreviewFrame frame;
    frame.strands = &strands;
    for (auto [mode, splat] : {std::pair{VoxelMode::Binary, VoxelSplat::Nearest},
                               std::pair{VoxelMode::Additive, VoxelSplat::Nearest},
                               std::pair{VoxelMode::Additive, VoxelSplat::Trilinear}}) {
        PreviewSettings s;
        s.shadow.resolution = res;
        s.shadow.weight = VoxelWeight::Fragments;  // Dehlin and Styngberg 2017's count, which cpuVoxelize mirrors
        s.shadow.alpha = alpha;
        s.shadow.mode = mode;
        s.shadow.splat = splat;
        renderer.setSettings(s);
        renderer.draw(v, frame);
        const VoxelSnapshot snap = renderer.readVoxels();
        ASSERT_EQ(snap.resolution, res);
        const std::vector<float> cpu = cpuVoxelize(lines, snap.grid, res, mode, splat);
        double gpuTotal = 0.0, cpuTotal = 0.0, error = 0.0;
        size_t compared = 0, apart = 0;
        for (int y = 0; y < res; ++y)
            for (int x = 0; x < res; ++x) {
                float sum = 0.f;  // CPU sum along the light ray, strictly in front of each voxel
                for (int z = 0; z < res; ++z) {
                    const float gpuT = std::pow(alpha, snap.summedAt(x, y, z)), cpuT = std::pow(alpha, sum);
                    if (sum > 0.f || snap.summedAt(x, y, z) > 0.f) {
                        error += std::abs(gpuT - cpuT);
                        apart += std::abs(gpuT - cpuT) > 1.f - alpha + 0.01f;  // more than one fragment
                        ++compared;
                    }
                    const float c = cpu[(size_t(z) * res + y) * res + x];
                    sum += c;
                    cpuTotal += c;
                    gpuTotal += snap.rawAt(x, y, z);
                }
            }
        const std::string what = cat(mode == VoxelMode::Binary ? "binary" : "additive", " ",
                                     splat == VoxelSplat::Nearest ? "nearest" : "trilinear");
        ASSERT_GT(cpuTotal, 1000.0) << what;
        EXPECT_NEAR(gpuTotal / cpuTotal, 1.0, 0.01) << what;
        EXPECT_LT(error / double(compared), 0.004) << what << ": mean |T_gpu - T_cpu| over " << compared << " voxels";
        EXPECT_LT(double(apart) / double(compared), 0.001) << what << ": voxels more than one fragment apart";
        std::cout << what << ": fragments gpu/cpu " << gpuTotal / cpuTotal << ", mean |dT| "
                  << error / double(compared) << ", >1 fragment apart " << apart << " of " << compared << "\n";
    }
}

/// Sorted hair is voxelized from whole-strand patches (render/preview/
/// preview.cpp lightStrands), cut into at least a piece per 4 segments, as
/// many as the camera's sorted 4-segment patches give. A zigzag of 24
/// segments, its peaks at vertices 4, 12 and 20 and its zeros at 0, 8, 16
/// and 24, spans ~45 raster pixels of the light pass: by length alone it
/// would be 3 pieces, chords through the zeros, and no hair at the peaks.
TEST(Preview, LightPassKeepsAPiecePerFourSegments) {
    HP_REQUIRE_GL();
    View v = test::frontView(64, 48);
    v.lights[0].direction = Vec3f(0.f, 0.f, -1.f);  // the grid's u, v follow world x, y
    StrandFrame strands;
    addLine(strands, Vec3f(-0.1f, -0.1f, -0.01f), Vec3f(0.1f, 0.1f, 0.01f), 0.0001f);  // widens the grid: 0.8 mm voxels
    const float amplitude = 0.005f;
    std::vector<Vec3f> zigzag(25);
    std::vector<float> radii(25, 0.0001f);
    for (int i = 0; i < 25; ++i)
        zigzag[size_t(i)] = Vec3f(-0.005f + 0.01f * float(i) / 24.f, 0.05f + amplitude * (1.f - std::abs(float(i % 8) - 4.f) / 4.f), 0.f);
    strands.addStrand(1, zigzag.data(), radii.data(), zigzag.size());
    PreviewSettings s;
    s.shadow.resolution = 256;
    ASSERT_EQ(s.blend, HairBlend::Sorted);
    const VoxelSnapshot snap = voxelsOf(s, v, strands);
    ASSERT_EQ(snap.resolution, 256);
    for (int peak : {4, 12, 20}) {
        const Vec3f g = snap.grid.toGrid(zigzag[size_t(peak)]) * 256.f;
        const Vec3f zero = snap.grid.toGrid(zigzag[size_t(peak - 4)]) * 256.f;
        ASSERT_GT(std::abs(g.y() - zero.y()), 4.f) << "the peak lies several voxels off the zeros' line";
        float mass = 0.f;  // raw hair within a voxel of the peak
        for (int z = 0; z < 256; ++z)
            for (int y = int(g.y()) - 1; y <= int(g.y()) + 1; ++y)
                for (int x = int(g.x()) - 1; x <= int(g.x()) + 1; ++x) mass += snap.rawAt(x, y, z);
        EXPECT_GT(mass, 0.f) << "no hair voxelized at the zigzag's peak at vertex " << peak;
    }
}

/// Generated hair grows on the region only, one strand per tessellated
/// triangle, and bends with the force.
TEST(Preview, GeneratedHairGrowsOnRegionAndBends) {
    HP_REQUIRE_GL();
    View v = test::frontView(240, 180);
    v.camera.position = Vec3f(0.f, 0.f, 0.6f);
    const TriangleMesh head = makeSphereMesh(Vec3f::Zero(), 0.1f, 12, 24);
    PreviewSettings s = noShadows();
    s.drawHead = true;
    s.generated.enabled = true;
    HairType fur;
    fur.segments = 6;
    fur.segmentLength = 0.006f;
    fur.rootRadius = fur.tipRadius = 0.0005f;
    s.generated.types = {fur};
    HairRegion cap;
    cap.axis = Vec3f::UnitY();
    cap.angle = 50.f;
    s.generated.regions = {cap};
    s.generated.wind = Vec3f::Zero();
    PreviewFrame frame;
    frame.head = &head;
    const std::vector<uint8_t> types = assignHairTypes(head, s.generated, Eigen::Isometry3f::Identity(), nullptr);
    const size_t inRegion = size_t(std::count_if(types.begin(), types.end(), [](uint8_t t) { return t != 0; }));
    ASSERT_GT(inRegion, 10u);
    ASSERT_LT(inRegion, head.triangleCount() / 2);

    // Coverage outside the sphere's disc: (pixels, centroid x, centroid y) above and below its centre.
    const Vec2f centre = project(v, Vec3f::Zero());
    const float discRadius = project(v, Vec3f(0.1f, 0.f, 0.f)).x() - centre.x();
    struct Outside {
        double above = 0, below = 0, sumX = 0, sumY = 0;
    };
    auto outside = [&](const Image& img) {
        Outside o;
        for (int y = 0; y < img.height; ++y)
            for (int x = 0; x < img.width; ++x) {
                const float a = img.at(x, y, 3);
                if (a < 0.01f || (Vec2f(float(x) + 0.5f, float(y) + 0.5f) - centre).norm() < discRadius + 1.5f) continue;
                (float(y) < centre.y() ? o.above : o.below) += a;
                o.sumX += a * (float(x) - centre.x());
                o.sumY += a * (centre.y() - float(y));
            }
        return o;
    };
    for (int level : {1, 3}) {
        s.generated.innerLevel = s.generated.outerLevel = level;
        PreviewRenderer renderer(s);
        const Image img = renderer.render(v, frame);
        EXPECT_EQ(renderer.stats().furTriangles, inRegion);
        if (renderer.stats().generatedStrands > 0 || level == 1) {  // needs ARB_pipeline_statistics_query
            if (level == 1) EXPECT_EQ(renderer.stats().generatedStrands, inRegion) << "level 1: one strand per triangle";
            else EXPECT_GT(renderer.stats().generatedStrands, inRegion * 6) << "level 3 tessellates each triangle";
        }
        const Outside o = outside(img);
        EXPECT_GT(o.above, 20.0) << "fur sticks out above the head (level " << level << ")";
        EXPECT_LT(o.below, 0.05 * o.above) << "nothing grows outside the cap";
    }
    // A sideways force bends the fur toward it; gravity pulls the top fur down.
    s.generated.innerLevel = s.generated.outerLevel = 2;
    s.generated.gravity = Vec3f::Zero();
    PreviewRenderer still(s);
    const Outside straight = outside(still.render(v, frame));
    s.generated.wind = Vec3f(0.6f, 0.f, 0.f);
    s.generated.gust = 0.f;
    PreviewRenderer windy(s);
    const Outside blown = outside(windy.render(v, frame));
    EXPECT_GT(blown.sumX / blown.above, straight.sumX / straight.above + 2.0) << "wind toward +x moves fur right";
    s.generated.wind = Vec3f::Zero();
    s.generated.gravity = Vec3f(0.f, -1.5f, 0.f);
    PreviewRenderer heavy(s);
    const Outside drooping = outside(heavy.render(v, frame));
    EXPECT_LT(drooping.sumY / drooping.above, straight.sumY / straight.above - 2.0) << "gravity pulls fur down";
}

TEST(Preview, IdenticalImagesAcrossRuns) {
    HP_REQUIRE_GL();
    SyntheticHairSettings hs;
    hs.strands = 3000;
    const StrandFrame strands = makeSyntheticHair(hs);
    const TriangleMesh head = makeSphereMesh(Vec3f::Zero(), 0.1f, 16, 32);
    View v = test::frontView(240, 180);
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
