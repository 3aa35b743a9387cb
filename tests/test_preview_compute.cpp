// The strand vertices shaded in a compute pass (PreviewSettings::shadeInCompute,
// shaders/strand_shade.comp, render/preview/shaded_points.cpp) against the
// tessellation stage shading every tessellated point itself. With one piece
// per segment (tessellation level 1, no pixel target) the tessellated points
// are the strand's vertices, and both paths interpolate the same vertex
// radiance along each piece: the images agree to float rounding. That holds
// only if every vertex is shaded at the curve's own point and read back for
// the right segment: at roots, tips and the chunk boundaries of long strands
// (sorted hair: 4 segments a patch; weighted: at most 29, so a
// strand of 39 is two patches), for the thin strands drawn as lines and the wide ones drawn as
// ribbons, under each light set-up and hair model the programs are compiled
// for.
//
// Set HAIRPIPE_TEST_DUMP=<folder> to write the images as EXR there.
#include "gl_support.h"
#include "render_support.h"
#include "test_support.h"

#include "render/image/image_io.h"
#include "render/preview/preview.h"
#include "render/reference/hair_fit.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace hp {
namespace {

using test::dump;

/// Largest |a - b| over the RGB channels, and the largest RGB value of b.
std::pair<double, double> largestDifference(const Image& a, const Image& b) {
    double diff = 0.0, peak = 0.0;
    for (int y = 0; y < b.height; ++y)
        for (int x = 0; x < b.width; ++x)
            for (int c = 0; c < 3; ++c) {
                diff = std::max(diff, double(std::abs(a.at(x, y, c) - b.at(x, y, c))));
                peak = std::max(peak, double(b.at(x, y, c)));
            }
    return {diff, peak};
}


// Tolerance, relative to the brightest pixel: 1e-4 for the two paths
// evaluating the same expressions in different shader stages (the compiler
// may contract or order them differently: a few ulps a colour), plus the
// stage's tessellation coordinate: a fixed-point value with 16 fraction bits
// (Mesa's tessellator follows Direct3D 11's reference tessellator), so its
// point lies up to n 2^-16 of a segment from the vertex on a patch of n
// segments, where the radiance changes by about its own size per segment
// (twice that, for margin). A vertex read for the wrong segment, or one
// never shaded, differs by far more.
double tolerance(int segmentsPerPatch) { return 1e-4 + 2.0 * segmentsPerPatch * std::ldexp(1.0, -16); }

TEST(PreviewCompute, ComputeShadedVerticesMatchStageShadedOnes) {
    HP_REQUIRE_GL();
    test::HairOnHead h = test::hairOnHead(96, 72);
    h.view.head.ambient = 0.f;
    SyntheticHairSettings hs;  // 39 segments: weighted hair's patches split each strand in two
    hs.strands = 3000;
    hs.vertices = 40;
    h.strands = makeSyntheticHair(hs);
    PreviewSettings s;
    s.tessellationLevel = 1;     // one piece per segment: the tessellated points are the vertices
    s.tessellationPixels = 0.f;
    s.shadow.resolution = 32;
    s.shadow.otherResolution = 16;
    const std::vector<View> views = test::lightSetups(h.view);
    struct Case {
        const char* name;
        HairBlend blend;
        float minPixelWidth;  // 1: thin strands as lines; 0.05: the strands are ribbons
        CurveType curve;
        int segmentsPerPatch;  // render/preview/preview_buffers.cpp StrandBuffers::upload
    };
    const Case cases[] = {{"sorted lines", HairBlend::Sorted, 1.f, CurveType::CatmullRom, 4},
                          {"sorted ribbons", HairBlend::Sorted, 0.05f, CurveType::CatmullRom, 4},
                          {"weighted lines, B-spline", HairBlend::Weighted, 1.f, CurveType::BSpline, 29}};
    for (const Case& c : cases)
        for (size_t i = 0; i < views.size(); ++i) {
            PreviewSettings stage = s;
            stage.blend = c.blend;
            stage.minPixelWidth = c.minPixelWidth;
            stage.curve = c.curve;
            stage.shadeInCompute = false;
            stage.piecesInCompute = 0;  // the tessellation stages' pieces, as the compute shading's (line_pieces.h)
            PreviewSettings compute = stage;
            compute.shadeInCompute = true;
            PreviewStats stats;
            const Image a = test::renderOnce(stage, views[i], h.strands, &h.head);
            const Image b = test::renderOnce(compute, views[i], h.strands, &h.head, &stats);
            dump(std::string("compute_") + std::to_string(i) + "_" + std::to_string(int(&c - cases)), b);
            dump(std::string("stage_") + std::to_string(i) + "_" + std::to_string(int(&c - cases)), a);
            ASSERT_EQ(a.pixels.size(), b.pixels.size());
            const auto [diff, peak] = largestDifference(b, a);
            EXPECT_GT(peak, 0.05) << c.name << ", view " << i << ": the hair is lit";
            EXPECT_LE(diff, tolerance(c.segmentsPerPatch) * peak) << c.name << ", view " << i;
        }
}

// With the default tessellation (pieces of about 20 pixels, not at the
// vertices) the compute path interpolates the vertices' radiance where the
// stage shaded each piece's end: the images differ a little, by less than
// either differs from shading every fragment (the per-vertex shading's own
// error, which both paths share).
TEST(PreviewCompute, DefaultTessellationStaysWithinPerVertexError) {
    HP_REQUIRE_GL();
    test::HairOnHead h = test::hairOnHead(192, 144);
    h.view.head.ambient = 0.f;
    PreviewSettings s;
    s.shadow.resolution = 64;
    View v = test::lightSetups(h.view)[2];  // the rig, fitted hair: the sharpest lobes
    PreviewSettings stage = s, compute = s, fragment = s;
    stage.shadeInCompute = false;
    compute.shadeInCompute = true;
    fragment.shadePerFragment = true;
    const Image a = test::renderOnce(stage, v, h.strands, &h.head);
    const Image b = test::renderOnce(compute, v, h.strands, &h.head);
    const Image f = test::renderOnce(fragment, v, h.strands, &h.head);
    auto rms = [](const Image& x, const Image& y) {
        double sum = 0.0;
        size_t n = 0;
        for (int py = 0; py < y.height; ++py)
            for (int px = 0; px < y.width; ++px) {
                if (x.at(px, py, 3) <= 0.f && y.at(px, py, 3) <= 0.f) continue;  // covered pixels only
                for (int c = 0; c < 3; ++c) sum += std::pow(double(x.at(px, py, c) - y.at(px, py, c)), 2.0), ++n;
            }
        return std::sqrt(sum / double(std::max<size_t>(n, 1)));
    };
    const double between = rms(a, b), stageError = rms(a, f), computeError = rms(b, f);
    EXPECT_GT(between, 0.0) << "the paths shade different points";
    EXPECT_LT(between, stageError) << "compute vs stage against the per-vertex error";
    EXPECT_LT(computeError, 1.5 * stageError) << "compute path's error against shading every fragment";
}

}  // namespace
}  // namespace hp
