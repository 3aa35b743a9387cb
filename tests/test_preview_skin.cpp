// The skin under and behind the hair, seen by the camera: where the camera
// sees the skin behind sorted hair, each fragment lets through its gaps and
// the light the fibre scatters forward, 1 - a (1 - a_f) (shaders/resolve.frag),
// against that law on a slab of strands over a plane and against the
// physical path tracer on the same slab; where it does not (hair beside the
// head), the scalp's bounce lights the hair as in weighted hair, whose bounce
// is a Lambertian plane's (analytic).
//
// Set HAIRPIPE_TEST_DUMP=<folder> to write the images as EXR there.
#include "gl_support.h"
#include "render_support.h"
#include "test_support.h"

#include "render/image/image_io.h"
#include "render/preview/gl_context.h"
#include "render/preview/preview.h"
#include "render/reference/hair_fit.h"
#include "render/reference/reference.h"

#include <cmath>
#include <iostream>

namespace hp {
namespace {

using test::dump;

using test::project;
using test::renderOnce;
using test::strandSlab;

/// The default shot's blond fibre (render.hair.melanin 0.3, pheomelanin 0.1).
HairFiberParams blondFibre() {
    HairFiberParams blond;
    blond.sigmaA = hairAbsorptionFromMelanin(0.3f, 0.1f);
    return blond;
}

/// A `size` x `size` view from (0, 0, 1) with one white light of `intensity`
/// travelling along `lightDirection`, a black environment, a matte skin of
/// the default shot's colour (no ambient, wrap or sheen), and hair fitted to
/// `fibre`.
View skinView(int size, const Vec3f& lightDirection, float intensity, const HairFiberParams& fibre) {
    View v = test::frontView(size, size, lightDirection);
    v.lights[0].intensity = intensity;
    v.lights[0].color = Vec3f::Ones();
    v.environment = Vec3f::Zero();
    v.head.ambient = v.head.wrap = v.head.specular = 0.f;
    v.head.color = Vec3f(0.6f, 0.42f, 0.33f);
    fitHairMaterial(fibre, &v.hair);
    return v;
}

/// `v` with a black skin: a render of `v` less a render of this is the
/// skin's light that reaches the camera.
View withBlackSkin(View v) {
    v.head.color = Vec3f::Zero();
    return v;
}

/// A plane at z = 0 facing the camera, over x0..x1 × -0.2..0.2.
TriangleMesh planeMesh(float x0 = -0.2f, float x1 = 0.2f) {
    TriangleMesh plane;
    plane.positions = {Vec3f(x0, -0.2f, 0.f), Vec3f(x1, -0.2f, 0.f), Vec3f(x1, 0.2f, 0.f), Vec3f(x0, 0.2f, 0.f)};
    plane.triangles = {Tri{0, 1, 2}, Tri{0, 2, 3}};
    plane.computeNormals();
    return plane;
}

// The scalp's bounce (shaders/hair_shading.glsl scalpBounce): a slab of
// straight strands along y (x -0.06..0.06, z 0.02..0.04, C = n 2r L = 1.67
// crossings through it along z) lies over a Lambertian plane at z = 0 (albedo
// rho, no sheen, no wrap), lit straight down (l = +z) and seen from above.
// The skin receives E T_f(C) (T_f(C) = exp(-(1 - a_f) C), the hair's forward
// transmittance) and returns L_s = rho / pi E T_f(C). A fibre at depth c
// (crossings above it, seen by the camera with probability e^-c) meets L_s
// through the C - c crossings below it and sends the viewer a_f of it, times
// the mean of cos(n_s, l) over the half circle of normals across the fibre
// facing the viewer (the preview's stand-in for the unknown skin normal),
// here integrated numerically. Summed over the slab's depth:
//   a_f L_s int_0^C e^-c T_f(C - c) dc = L_s T_f(C) (1 - e^-(a_f C)).
// The plane's albedo is the only difference between the two renders, so
// their difference on the slab's pixels is that bounce plus the skin seen
// between the strands, (1 - alpha_hair) L_s (alpha_hair from a render
// without the plane).
TEST(PreviewSkin, ScalpBounceIsTheSkinsLightThroughTheHair) {
    HP_REQUIRE_GL();
    const float radius = 0.0001f;
    const int columns = 100, rows = 10;
    const float x0 = -0.06f, x1 = 0.06f, z0 = 0.02f, z1 = 0.04f;
    const StrandFrame slab = strandSlab(columns, rows, x0, x1, z0, z1, radius, 7u);
    const double crossings = double(columns * rows) / double((x1 - x0) * (z1 - z0)) * 2.0 * radius * double(z1 - z0);
    const TriangleMesh plane = planeMesh();

    const View skin = skinView(240, Vec3f(0.f, 0.f, -1.f), 2.f, HairFiberParams{});
    const View black = withBlackSkin(skin);
    // The bounce is the weighted hair's approximation of the skin seen
    // through the hair; sorted hair sees that skin where it is drawn
    // (SkinIsSeenThroughTheFibresForwardScattering below).
    PreviewSettings s;
    s.blend = HairBlend::Weighted;
    s.shadow.resolution = 128;
    const Image withSkin = renderOnce(s, skin, slab, &plane), withBlack = renderOnce(s, black, slab, &plane);
    const Image hairAlone = renderOnce(s, skin, slab, nullptr);
    dump("bounce.skin", withSkin);
    dump("bounce.black", withBlack);

    // The mean of max(0, cos(psi - gamma)) over psi in (-pi/2, pi/2), over pi
    // (gamma = 0: the light along the ribbon's normal), by the midpoint rule.
    double halfCircle = 0.0;
    const int steps = 1000;
    for (int i = 0; i < steps; ++i) halfCircle += std::max(0.0, std::cos(-0.5 * M_PI + (i + 0.5) * M_PI / steps));
    halfCircle *= (M_PI / steps) / M_PI;
    const double af = double(skin.hair.dual.forward.y()), rho = double(skin.head.color.y()), e = 2.0;
    const double forwardT = std::exp(-(1.0 - af) * crossings);
    const double skinRadiance = rho / M_PI * e * forwardT;
    const double expected = skinRadiance * halfCircle * forwardT * (1.0 - std::exp(-af * crossings));
    double bounce = 0.0, seen = 0.0;
    int pixels = 0;
    const Vec2f a = project(skin, Vec3f(-0.03f, 0.05f, z1)), b = project(skin, Vec3f(0.03f, -0.05f, z1));
    for (int y = int(std::ceil(a.y())); y < int(b.y()); ++y)
        for (int x = int(std::ceil(a.x())); x < int(b.x()); ++x) {
            const double between = (1.0 - double(hairAlone.at(x, y, 3))) * skinRadiance;
            bounce += double(withSkin.at(x, y, 1)) - double(withBlack.at(x, y, 1)) - between;
            seen += 1.0 - double(hairAlone.at(x, y, 3));
            ++pixels;
        }
    ASSERT_GT(pixels, 100);
    bounce /= pixels;
    seen /= pixels;
    EXPECT_NEAR(seen / std::exp(-crossings), 1.0, 0.15) << "the skin seen between the strands, against e^-C";
    EXPECT_NEAR(bounce / expected, 1.0, 0.15) << "the scalp's bounce on the hair (green): preview " << bounce
                                             << ", slab over a Lambertian plane " << expected;
    std::cout << "C " << crossings << ", skin seen " << seen << " (e^-C " << std::exp(-crossings) << "); bounce "
              << bounce << ", analytic " << expected << "\n";
}

// Sorted hair over skin, seen by the camera: a hair fragment of coverage a
// lets through 1 - a (1 - a_f) of the skin behind it, per channel (a_f: the
// fibre's forward albedo, Zinke et al. 2008), which for fragments thinner
// than a sample multiplies to (1 - A)^(1 - a_f), A the hair's coverage
// (shaders/resolve.frag skinThrough). The same slab over the same Lambertian
// plane, lit from the camera with no shadows (the skin's radiance is
// rho E / pi everywhere); only the plane's albedo differs between two
// renders, so their difference on the slab's pixels is the skin that reaches
// the camera, over rho E / pi: against (1 - alpha_hair)^(1 - a_f) per pixel,
// alpha_hair from a render of the hair alone. With Kajiya-Kay hair (no
// forward scattering) the skin shows through the gaps alone, 1 - alpha_hair.
TEST(PreviewSkin, SkinIsSeenThroughTheFibresForwardScattering) {
    HP_REQUIRE_GL();
    const float radius = 0.0001f;
    const float x0 = -0.06f, x1 = 0.06f, z0 = 0.02f, z1 = 0.04f;
    const StrandFrame slab = strandSlab(100, 10, x0, x1, z0, z1, radius, 7u);
    const TriangleMesh plane = planeMesh();
    const View skin = skinView(240, Vec3f(0.f, 0.f, -1.f), 2.f, blondFibre());
    PreviewSettings s;  // sorted hair, the default
    ASSERT_EQ(s.blend, HairBlend::Sorted);
    s.shadow.voxels = false;
    s.shadow.shadowMap = false;
    const Vec3f af = skin.hair.dual.forward;
    ASSERT_GT(af.minCoeff(), 0.2f);  // (1 - alpha)^(1 - a_f) differs from the gaps by e^(a_f C) > 1.3 here
    const Vec2f a = project(skin, Vec3f(-0.03f, 0.05f, z1)), b = project(skin, Vec3f(0.03f, -0.05f, z1));
    // Mean over the slab's pixels of the skin passed, over rho E / pi, and
    // of (1 - alpha_hair)^(1 - a) per channel.
    auto passed = [&](const View& lit, const Vec3f& forward, Eigen::Vector3d& expected) {
        const Image withSkin = renderOnce(s, lit, slab, &plane);
        const Image withBlack = renderOnce(s, withBlackSkin(lit), slab, &plane);
        const Image hairAlone = renderOnce(s, lit, slab, nullptr);
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        expected = Eigen::Vector3d::Zero();
        int pixels = 0;
        for (int y = int(std::ceil(a.y())); y < int(b.y()); ++y)
            for (int x = int(std::ceil(a.x())); x < int(b.x()); ++x) {
                const double gaps = 1.0 - double(hairAlone.at(x, y, 3));
                for (int c = 0; c < 3; ++c) {
                    const double skinRadiance = double(lit.head.color[c]) / M_PI * 2.0;
                    sum[c] += (double(withSkin.at(x, y, c)) - double(withBlack.at(x, y, c))) / skinRadiance;
                    expected[c] += std::pow(std::max(gaps, 1e-9), 1.0 - double(forward[c]));
                }
                ++pixels;
            }
        EXPECT_GT(pixels, 100);
        expected /= double(std::max(pixels, 1));
        return Eigen::Vector3d(sum / double(std::max(pixels, 1)));
    };
    Eigen::Vector3d expected;
    const Eigen::Vector3d fitted = passed(skin, af, expected);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(fitted[c] / expected[c], 1.0, 0.08)
            << "channel " << c << ": skin passed " << fitted[c] << ", (1 - alpha)^(1 - a_f) " << expected[c];
    View plain = skin;
    plain.hair.shading = HairShading::KajiyaKay;
    Eigen::Vector3d gapsOnly;
    const Eigen::Vector3d kajiyaKay = passed(plain, Vec3f::Zero(), gapsOnly);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(kajiyaKay[c] / gapsOnly[c], 1.0, 0.03) << "channel " << c << ": Kajiya-Kay hair passes its gaps";
    std::cout << "skin through the slab (R G B): fitted " << fitted.transpose() << " against "
              << expected.transpose() << " (a_f " << af.transpose() << "); Kajiya-Kay " << kajiyaKay.transpose()
              << " against its gaps " << gapsOnly.transpose() << "\n";
}

// The same slab over the same plane, now lit from the camera with the hair's
// shadows on, against the physical path tracer (Chiang et al. 2016's fibre
// over a Lambertian plane, render/reference): the skin's light that reaches
// the camera through the slab (the difference between the plane's albedo and
// a black plane) crosses the slab twice, to the skin and back, and the
// preview keeps about exp(-(1 - a_f) C) each way (the skin's lighting,
// shaders/shadow.glsl hairOnlyVisibility, and resolve.frag skinThrough). Letting
// the skin through the gaps alone, as before, kept 0.10 / 0.06 / 0.03 of
// rho E / pi (R / G / B), 0.10 / 0.08 / 0.06 against the physical render's
// 0.30 / 0.19 / 0.10; adding the scalp's bounce where the camera sees the skin
// too (the same path twice) 0.43 / 0.28 / 0.13.
TEST(PreviewSkin, SkinThroughTheHairMatchesThePhysicalSlab) {
    HP_REQUIRE_GL();
    const float radius = 0.0001f;
    const float x0 = -0.06f, x1 = 0.06f, z0 = 0.02f, z1 = 0.04f;
    const StrandFrame slab = strandSlab(100, 10, x0, x1, z0, z1, radius, 7u);
    const TriangleMesh plane = planeMesh();
    const HairFiberParams blond = blondFibre();
    const View skin = skinView(160, Vec3f(0.f, 0.f, -1.f), 2.f, blond);
    const View black = withBlackSkin(skin);
    PreviewSettings s;
    s.shadow.resolution = 128;
    ReferenceSettings rs;
    rs.mode = ReferenceMode::Physical;
    rs.fiber = blond;
    rs.samplesPerPixel = 64;
    rs.bounces = 16;
    ReferenceRenderer reference;
    const Image pSkin = renderOnce(s, skin, slab, &plane), pBlack = renderOnce(s, black, slab, &plane);
    const Image rSkin = reference.render(skin, &slab, &plane, rs), rBlack = reference.render(black, &slab, &plane, rs);
    dump("slab.preview", pSkin);
    dump("slab.physical", rSkin);
    const Vec2f a = project(skin, Vec3f(-0.03f, 0.05f, z1)), b = project(skin, Vec3f(0.03f, -0.05f, z1));
    Eigen::Vector3d preview = Eigen::Vector3d::Zero(), physical = Eigen::Vector3d::Zero();
    int pixels = 0;
    for (int y = int(std::ceil(a.y())); y < int(b.y()); ++y)
        for (int x = int(std::ceil(a.x())); x < int(b.x()); ++x) {
            for (int c = 0; c < 3; ++c) {
                const double lit = double(skin.head.color[c]) / M_PI * 2.0;  // rho E / pi
                preview[c] += (double(pSkin.at(x, y, c)) - double(pBlack.at(x, y, c))) / lit;
                physical[c] += (double(rSkin.at(x, y, c)) - double(rBlack.at(x, y, c))) / lit;
            }
            ++pixels;
        }
    ASSERT_GT(pixels, 100);
    preview /= pixels;
    physical /= pixels;
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(preview[c] / physical[c], 1.0, 0.15)
            << "channel " << c << ": the skin through the slab, preview " << preview[c] << ", physical " << physical[c];
    std::cout << "skin through the slab and back, over rho E / pi (R G B): preview " << preview.transpose()
              << ", physical " << physical.transpose() << "\n";
}

// Hair beside the head: the slab (x 0.02..0.08) lies right of a plane that
// ends at x = -0.005, so the camera at (0, 0, 1) sees no skin behind it, but
// the light, travelling along (-3, 0, -1), crosses the slab and goes on to the
// plane. There only the scalp's bounce brings the skin's light to the hair,
// in sorted hair as in weighted hair (the same term, scalpBounce); sorted hair
// leaves the bounce out only where the camera sees the skin behind the fibre
// and composites it instead (with the bounce left out everywhere this
// difference is 0).
TEST(PreviewSkin, BounceLightsHairBesideTheHead) {
    HP_REQUIRE_GL();
    const float z0 = 0.02f, z1 = 0.04f;
    const StrandFrame slab = strandSlab(50, 10, 0.02f, 0.08f, z0, z1, 0.0001f, 11u);
    const TriangleMesh plane = planeMesh(-0.2f, -0.005f);
    const View skin = skinView(200, Vec3f(-3.f, 0.f, -1.f), 4.f, blondFibre());
    const View black = withBlackSkin(skin);
    const Vec2f a = project(skin, Vec3f(0.035f, 0.05f, z1)), b = project(skin, Vec3f(0.065f, -0.05f, z1));
    auto bounce = [&](HairBlend blend) {
        PreviewSettings s;
        s.blend = blend;
        s.shadow.resolution = 128;
        const Image withSkin = renderOnce(s, skin, slab, &plane), withBlack = renderOnce(s, black, slab, &plane);
        dump(blend == HairBlend::Sorted ? "beside.sorted" : "beside.weighted", withSkin);
        double sum = 0.0;
        int pixels = 0;
        for (int y = int(std::ceil(a.y())); y < int(b.y()); ++y)
            for (int x = int(std::ceil(a.x())); x < int(b.x()); ++x, ++pixels)
                sum += double(withSkin.at(x, y, 1)) - double(withBlack.at(x, y, 1));
        EXPECT_GT(pixels, 100);
        return sum / std::max(pixels, 1);
    };
    const double sorted = bounce(HairBlend::Sorted), weighted = bounce(HairBlend::Weighted);
    EXPECT_GT(weighted, 0.0);
    EXPECT_NEAR(sorted / weighted, 1.0, 0.2) << "the bounce on hair beside the head (green): sorted " << sorted
                                             << ", weighted " << weighted;
    std::cout << "bounce beside the head (green, mean over the slab): sorted " << sorted << ", weighted " << weighted
              << "\n";
}

}  // namespace
}  // namespace hp
