// The thin strands' line pieces made by compute passes
// (PreviewSettings::piecesInCompute, shaders/strand_pieces.comp,
// render/preview/line_pieces.h) against the tessellation stages that made
// them before: the same pieces, points and shading, so the pictures agree
// but for the stages' tessellation coordinate, a fixed-point value with 16
// fraction bits in Mesa (Direct3D 11's reference tessellator), where the
// compute pass divides k / n in floats: the pieces' ends move by up to
// 2^-16 of a patch. The bound is mean FLIP over the hair's pixels (as
// `hairpipe compare --mask hair`): sorted hair (4-segment patches, back to
// front; the default) measures 2e-6 to 8e-6, bound 1e-4; weighted hair
// (patches of up to 29 segments, whose ends the 2^-16 moves 7 times as far;
// more than 64 pieces a patch: several isolines) 5e-4 to 9e-4, bound 0.002;
// both under the 0.005 a change of the picture may move it by. A piece lost
// (0.09-0.27) or shaded at its control point instead of the curve's
// (0.002-0.0035) fails every case. Catmull-Rom and B-spline, under each
// light set-up and hair model.
//
// Set HAIRPIPE_TEST_DUMP=<folder> to write the images as EXR there.
#include "gl_support.h"
#include "render_support.h"
#include "test_support.h"

#include "render/compare/flip.h"
#include "render/preview/preview.h"

#include <algorithm>
#include <string>

namespace hp {
namespace {

using test::dump;

/// Mean FLIP of `b` against `a` over the pixels either covers with hair (alpha > 0).
double hairFlip(const Image& a, const Image& b) {
    RgbPlanes pa{ImagePlane(a.width, a.height), ImagePlane(a.width, a.height), ImagePlane(a.width, a.height)};
    RgbPlanes pb = pa;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            const size_t i = size_t(y) * size_t(a.width) + size_t(x);
            pa.r.data[i] = std::clamp(a.at(x, y, 0), 0.f, 1.f), pb.r.data[i] = std::clamp(b.at(x, y, 0), 0.f, 1.f);
            pa.g.data[i] = std::clamp(a.at(x, y, 1), 0.f, 1.f), pb.g.data[i] = std::clamp(b.at(x, y, 1), 0.f, 1.f);
            pa.b.data[i] = std::clamp(a.at(x, y, 2), 0.f, 1.f), pb.b.data[i] = std::clamp(b.at(x, y, 2), 0.f, 1.f);
        }
    const ImagePlane e = flipErrorMap(pa, pb);
    double sum = 0.0;
    size_t n = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            if (a.at(x, y, 3) > 0.f || b.at(x, y, 3) > 0.f) sum += e.data[size_t(y) * size_t(a.width) + size_t(x)], ++n;
    return n ? sum / double(n) : 0.0;
}

bool ranComputePieces(const PreviewStats& stats) {
    for (const auto& p : stats.passes)
        if (p.name == "strand pieces (compute)") return true;
    return false;
}

TEST(PreviewLinePieces, ComputePiecesMatchTheTessellationStages) {
    HP_REQUIRE_GL();
    test::HairOnHead h = test::hairOnHead(192, 144);
    SyntheticHairSettings hs;  // 39 segments: weighted hair's patches split each strand in two
    hs.strands = 3000;
    hs.vertices = 40;
    h.strands = makeSyntheticHair(hs);
    PreviewSettings s;
    s.shadow.resolution = 64;
    s.shadow.otherResolution = 32;
    s.profile = true;  // its passes say which path drew the lines
    s.tessellationPixels = 4.f;  // more pieces than segments: points between the vertices, up to 232 a patch
    const std::vector<View> views = test::lightSetups(h.view);
    struct Case {
        const char* name;
        HairBlend blend;
        CurveType curve;
        double bound;  // mean FLIP over the hair
    };
    const Case cases[] = {{"sorted", HairBlend::Sorted, CurveType::CatmullRom, 1e-4},
                          {"weighted, B-spline", HairBlend::Weighted, CurveType::BSpline, 0.002}};
    for (const Case& c : cases)
        for (size_t i = 0; i < views.size(); ++i) {
            PreviewSettings stages = s;
            stages.blend = c.blend;
            stages.curve = c.curve;
            stages.piecesInCompute = 0;
            PreviewSettings compute = stages;
            compute.piecesInCompute = 1;
            PreviewStats before, after;
            const Image a = test::renderOnce(stages, views[i], h.strands, &h.head, &before);
            const Image b = test::renderOnce(compute, views[i], h.strands, &h.head, &after);
            const std::string tag = std::to_string(i) + "_" + std::to_string(int(&c - cases));
            dump("pieces_stages_" + tag, a);
            dump("pieces_compute_" + tag, b);
            ASSERT_FALSE(ranComputePieces(before)) << c.name;
            ASSERT_TRUE(ranComputePieces(after)) << c.name << ": the line path ran";
            size_t hair = 0;
            for (int y = 0; y < a.height; ++y)
                for (int x = 0; x < a.width; ++x) hair += a.at(x, y, 3) > 0.f;
            EXPECT_GT(hair, size_t(a.width * a.height / 10)) << c.name << ", view " << i << ": hair in view";
            EXPECT_LT(hairFlip(a, b), c.bound) << c.name << ", view " << i;
        }
}

}  // namespace
}  // namespace hp
