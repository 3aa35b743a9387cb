// Preview (GL) against reference (Embree) on the same StrandFrame, head and
// View: hair coverage, hair colour without shadows, a small hair scene with
// shadows (FLIP), and the head alone.
//
// Set HAIRPIPE_TEST_DUMP=<folder> to write every rendered pair as EXR there.
#include "test_support.h"

#include "core/errors.h"
#include "render/compare.h"
#include "render/gl_context.h"
#include "render/preview.h"
#include "render/reference.h"
#include "sim/synthetic.h"

#include <cmath>
#include <cstdlib>
#include <iostream>

namespace hp {
namespace {

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

void dump(const std::string& name, const Image& img) {
    const char* dir = std::getenv("HAIRPIPE_TEST_DUMP");
    if (!dir) return;
    writeImage(std::string(dir) + "/" + name + ".exr", img);
}

struct Pair {
    Image preview, reference;
};

Pair renderBoth(const std::string& name, const View& view, const StrandFrame* strands, const TriangleMesh* head,
                const PreviewSettings& ps, const ReferenceSettings& rs) {
    Pair p;
    {
        PreviewRenderer renderer(ps);
        PreviewFrame frame;
        frame.strands = strands;
        frame.head = head;
        p.preview = renderer.render(view, frame);
    }
    ReferenceRenderer reference;
    p.reference = reference.render(view, strands, head, rs);
    dump(name + ".preview", p.preview);
    dump(name + ".reference", p.reference);
    return p;
}

/// The default scene's look, scaled down: a sphere head of radius 0.1 m with
/// synthetic drooping hair, seen from the front-right and lit from the upper right.
View smallView(int w = 160, int h = 90) {
    View v;
    v.camera.position = Vec3f(0.42f, 0.08f, 0.62f) * 1.1f;
    v.camera.target = Vec3f(0.f, -0.04f, -0.02f);
    v.camera.fovY = 38.f;
    v.camera.width = w;
    v.camera.height = h;
    v.lights = {Light{}};
    v.lights[0].direction = Vec3f(-1.f, -1.f, -1.f);
    v.lights[0].intensity = 3.f;
    return v;
}

void printStats(const std::string& what, const Pair& p) {
    double ap = 0, ar = 0;
    Eigen::Vector3d cp = Eigen::Vector3d::Zero(), cr = cp;
    long full = 0;
    for (int y = 0; y < p.preview.height; ++y)
        for (int x = 0; x < p.preview.width; ++x) {
            ap += p.preview.at(x, y, 3), ar += p.reference.at(x, y, 3);
            if (p.preview.at(x, y, 3) > 0.99f && p.reference.at(x, y, 3) > 0.99f) {
                ++full;
                for (int c = 0; c < 3; ++c) cp[c] += p.preview.at(x, y, c), cr[c] += p.reference.at(x, y, c);
            }
        }
    CompareSettings cs;
    cs.mask = MaskMode::Hair;
    const Comparison c = compareImages(p.reference, p.preview, cs);
    std::cout << what << ": alpha sum preview/reference " << ap / ar << " (" << ap << " / " << ar << "), full px "
              << full << ", mean colour preview " << (cp / std::max(full, 1L)).transpose() << " reference "
              << (cr / std::max(full, 1L)).transpose() << ", FLIP " << c.metrics.flip << " SSIM " << c.metrics.ssim
              << "\n";
}

TEST(Parity, ExploreDense) {
    HP_REQUIRE_GL();
    SyntheticHairSettings hs;
    hs.strands = 30000;
    hs.vertices = 16;
    hs.length = 0.22f;
    hs.capMinCosine = -0.2f;
    hs.rootRadius = 0.00006f;
    hs.tipRadius = 0.00002f;
    hs.droop = 0.9f;
    const StrandFrame hair = makeSyntheticHair(hs);
    const TriangleMesh head = makeSphereMesh(Vec3f::Zero(), 0.1f, 24, 48);
    View v = smallView(320, 180);
    ReferenceSettings rs;
    rs.samplesPerPixel = 32;
    PreviewSettings ps;
    PreviewSettings p = ps;
    p.shadow.voxels = false;
    p.shadow.shadowMap = false;
    ReferenceSettings r = rs;
    r.shadows = false;
    printStats("dense hair+head, no shadows", renderBoth("dense_noshadow", v, &hair, &head, p, r));
    printStats("dense hair+head, shadows", renderBoth("dense_shadow", v, &hair, &head, ps, rs));
}

TEST(Parity, Explore) {
    HP_REQUIRE_GL();
    SyntheticHairSettings hs;
    hs.strands = 3000;
    hs.vertices = 16;
    hs.length = 0.22f;
    hs.capMinCosine = -0.2f;
    hs.rootRadius = 0.00006f;
    hs.tipRadius = 0.00002f;
    hs.droop = 0.9f;
    const StrandFrame hair = makeSyntheticHair(hs);
    const TriangleMesh head = makeSphereMesh(Vec3f::Zero(), 0.1f, 24, 48);
    View v = smallView(320, 180);
    ReferenceSettings rs;
    rs.samplesPerPixel = 64;
    PreviewSettings ps;
    {
        PreviewSettings p = ps;
        p.shadow.voxels = false;
        p.shadow.shadowMap = false;
        ReferenceSettings r = rs;
        r.shadows = false;
        printStats("hair+head, no shadows", renderBoth("noshadow", v, &hair, &head, p, r));
        printStats("hair only, no shadows", renderBoth("hair_noshadow", v, &hair, nullptr, p, r));
        printStats("head only, no shadows", renderBoth("head_noshadow", v, nullptr, &head, p, r));
    }
    printStats("hair+head, shadows", renderBoth("shadow", v, &hair, &head, ps, rs));
    printStats("head only, shadows", renderBoth("head_shadow", v, nullptr, &head, ps, rs));
    printStats("hair only, shadows", renderBoth("hair_shadow", v, &hair, nullptr, ps, rs));
}

}  // namespace
}  // namespace hp
