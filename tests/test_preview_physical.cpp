// The preview's fitted hair (render/reference/hair_fit.h, Zinke et al.
// 2008's dual scattering on the voxel grid) against the physical reference
// (Embree path tracing Chiang et al. 2016's fibre) converged on a small scene:
// the preview must predict the physical render, not only the Kajiya-Kay one.
// One shadowed light, so both renderers see the same light paths blocked.
//
// Set HAIRPIPE_TEST_DUMP=<folder> to write the images as EXR there.
#include "gl_support.h"
#include "render_support.h"
#include "test_support.h"

#include "render/compare/compare.h"
#include "render/image/image_io.h"
#include "render/preview/gl_context.h"
#include "render/preview/preview.h"
#include "render/reference/hair_fit.h"
#include "render/reference/reference.h"
#include "render/view/simple_view.h"
#include "sim/strands/synthetic.h"

#include <iostream>

namespace hp {
namespace {

using test::dump;

/// Mean luminance of the hair pixels' colour (premultiplied colour over
/// alpha-weighted coverage), over pixels covered in both images.
double hairLuminance(const Image& img, const Image& mask) {
    double sum = 0.0, alpha = 0.0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            if (img.at(x, y, 3) <= 0.f || mask.at(x, y, 3) <= 0.f) continue;
            sum += 0.2126 * img.at(x, y, 0) + 0.7152 * img.at(x, y, 1) + 0.0722 * img.at(x, y, 2);
            alpha += img.at(x, y, 3);
        }
    return alpha > 0.0 ? sum / alpha : 0.0;
}

struct Measured {
    double flip, luminanceRatio;
};

Measured measure(const Image& physical, const Image& preview) {
    CompareSettings cs;
    cs.mask = MaskMode::Hair;
    const FrameMetrics m = compareImages(physical, preview, cs).metrics;
    return {m.flip, hairLuminance(preview, physical) / hairLuminance(physical, preview)};
}

// Drooping hair grown on a sphere, the sphere not drawn (hair against black:
// what the hair looks like, not the skin model, which another change owns), lit by one shadowed directional
// light from the upper right front. Bounds: measured values (printed) with
// a margin; the plain Kajiya-Kay preview misses them by far. (The scene's
// 2000 strands are sparse: dual scattering changes little here; the default
// scene's numbers are in scenes/default.yaml and README.md.)
TEST(PreviewPhysical, FittedPreviewPredictsThePhysicalRender) {
    HP_REQUIRE_GL();
    SyntheticHairSettings hs;
    hs.strands = 2000;
    hs.vertices = 12;
    hs.length = 0.2f;
    hs.rootRadius = 0.00006f;
    hs.tipRadius = 0.00002f;
    hs.droop = 0.9f;
    const StrandFrame hair = makeSyntheticHair(hs);
    View view = simpleView(Vec3f(0.46f, 0.09f, 0.68f), Vec3f(0.f, -0.04f, -0.02f), 38.f, 160, 90,
                           Vec3f(-0.6f, -0.7f, -0.4f));
    view.lights[0].intensity = 3.f;
    HairFiberParams fibre;
    fibre.sigmaA = hairAbsorptionFromMelanin(0.3f, 0.1f);  // the default scene's blond

    ReferenceSettings rs;
    rs.mode = ReferenceMode::Physical;
    rs.fiber = fibre;
    rs.samplesPerPixel = 128;
    rs.bounces = 8;
    ReferenceRenderer reference;
    const Image physical = reference.render(view, &hair, nullptr, rs);
    dump("physical.reference", physical);

    PreviewSettings ps;
    ps.tessellationPixels = 8.f;
    PreviewRenderer renderer(ps);
    PreviewFrame frame;
    frame.strands = &hair;
    View plain = view;
    plain.hair.color = hairColorFromAbsorption(fibre.sigmaA, fibre.azimuthalRoughness);
    View fitted = view;
    fitHairMaterial(fibre, &fitted.hair);
    View single = fitted;  // without dual scattering: no forward transmittance, no back-scatter
    single.hair.dual.back.setStrength(Vec3f::Zero());
    single.hair.dual.forward = Vec3f::Constant(view.hair.transmittance);
    single.hair.dual.forwardVariance = 0.f;
    const Image pPlain = renderer.render(plain, frame), pFitted = renderer.render(fitted, frame),
                pSingle = renderer.render(single, frame);
    dump("physical.preview_kajiya_kay", pPlain);
    dump("physical.preview_fitted", pFitted);
    dump("physical.preview_single", pSingle);
    const Measured mPlain = measure(physical, pPlain), mFitted = measure(physical, pFitted),
                   mSingle = measure(physical, pSingle);
    std::cout << "FLIP / hair luminance preview over physical: kajiya-kay " << mPlain.flip << " / "
              << mPlain.luminanceRatio << ", fitted single scattering " << mSingle.flip << " / "
              << mSingle.luminanceRatio << ", fitted dual scattering " << mFitted.flip << " / "
              << mFitted.luminanceRatio << "\n";
    // Measured: fitted with dual scattering FLIP 0.038, hair luminance 0.93 of
    // the physical (0.041 / 0.98 with one azimuthal N for every θo, which
    // made the default shot's hair 17% too bright); without dual scattering
    // (Kajiya-Kay's grey shadows) 0.039 / 0.92; the plain Kajiya-Kay preview
    // 0.42 / 9.5 (its hand-set specular and the old convention, several
    // times too bright).
    EXPECT_LT(mFitted.flip, 0.06);
    EXPECT_NEAR(mFitted.luminanceRatio, 1.0, 0.1);
    EXPECT_LT(mFitted.flip, 0.5 * mPlain.flip);
}

}  // namespace
}  // namespace hp
