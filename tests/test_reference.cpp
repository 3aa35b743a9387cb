// The Embree reference renderer (render/reference/reference.h, render/reference/embree_scene.h)
// and its pipeline stage: Kajiya-Kay pixels against the formula, coverage
// against projected width, shadow transmittance, determinism across thread
// counts, no memory growth across frames, clear errors.
#include "kajiya_kay_oracle.h"
#include "render_support.h"
#include "test_support.h"

#include "core/errors.h"
#include "pipeline/scene/scene.h"
#include "pipeline/stages/stages.h"
#include "render/reference/embree_scene.h"
#include "render/reference/reference.h"
#include "sim/strands/synthetic.h"

#include <tbb/task_arena.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <tuple>

using namespace hp;
using namespace hp::test;

namespace {

/// One straight strand from a to b with n vertices of constant radius.
void addLine(StrandFrame& f, uint32_t id, const Vec3f& a, const Vec3f& b, int n, float radius) {
    std::vector<Vec3f> p(n);
    std::vector<float> r(n, radius);
    for (int i = 0; i < n; ++i) p[i] = a + (b - a) * (float(i) / float(n - 1));
    f.addStrand(id, p.data(), r.data(), size_t(n));
}

float pixelsPerUnitAtDepthOne(const Camera& c) { return float(c.height) / (2.f * std::tan(c.fovY * float(M_PI) / 360.f)); }

}  // namespace

TEST(Reference, KajiyaKayPixelsMatchTheFormula) {
    // A thick straight strand along x fills the middle rows; every covered
    // pixel must be kajiyaKay(tangent, light, view) times the light.
    const Vec3f lightDir = -Vec3f(0.3f, 0.6f, 0.8f).normalized();  // light from up-front-right
    View view = testView(96, 64, lightDir);
    StrandFrame strands;
    addLine(strands, 7, Vec3f(-1.f, 0.f, 0.f), Vec3f(1.f, 0.f, 0.f), 9, 0.02f);
    ReferenceSettings s;
    s.samplesPerPixel = 16;
    s.filter = {PixelFilterType::Box, 0.5f, 0.f};  // every sample inside its pixel: rows 31, 32 stay covered
    for (bool twoLobes : {false, true}) {
        view.hair.twoLobes = twoLobes;
        view.hair.primaryShift = twoLobes ? 0.05f : 0.f;
        ReferenceRenderer renderer;
        const Image img = renderer.render(view, &strands, nullptr, s);
        const Vec3f t = Vec3f::UnitX(), l = -lightDir;
        const Vec3f radiance = view.lights[0].color * view.lights[0].intensity;
        int compared = 0;
        float maxSpecular = 0.f, minSpecular = 1e9f;
        for (int y : {31, 32}) {
            for (int x = 2; x < 94; x += 3) {
                ASSERT_FLOAT_EQ(img.at(x, y, 3), 1.f) << "pixel " << x << "," << y << " not fully covered";
                const Vec3f v = -view.camera.rayDirection(x + 0.5f, y + 0.5f);
                const Vec3f n = (v - v.dot(t) * t).normalized();  // the renderer's view-facing normal
                const Vec3f expected = seedKajiyaKay(view.hair, t, n, l, v).cwiseProduct(radiance);
                const float spec = expected.x() - view.hair.kd * t.cross(l).norm() * view.hair.color.x() * radiance.x();
                maxSpecular = std::max(maxSpecular, spec), minSpecular = std::min(minSpecular, spec);
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(img.at(x, y, c), expected[c], 0.01f * expected[c] + 1e-4f)
                        << "pixel " << x << "," << y << " channel " << c << " two lobes " << twoLobes;
                ++compared;
            }
        }
        EXPECT_EQ(compared, 62);
        // The highlight moves across the strand with the view: the test
        // really exercises the view dependence.
        EXPECT_GT(maxSpecular, 4.f * minSpecular);
        // Depth of the strand's front at the image centre: 1 − radius.
        EXPECT_NEAR(img.at(48, 32, 4), 0.98f, 2e-3f);
        EXPECT_FLOAT_EQ(img.at(48, 2, 3), 0.f);                    // background: no coverage
        EXPECT_FLOAT_EQ(img.at(48, 2, 4), view.camera.farClip);    // ... and far depth
    }
}

TEST(Reference, AlphaCoverageMatchesProjectedWidth) {
    // A strand narrower than a pixel: the alpha summed down a column is its
    // projected width in pixels (box filter), 2 r · f / depth.
    View view = testView(128, 96, Vec3f(0.f, -1.f, 0.f));
    for (float radius : {0.0015f, 0.003f}) {
        StrandFrame strands;
        addLine(strands, 0, Vec3f(-1.f, 0.01f, 0.f), Vec3f(1.f, 0.01f, 0.f), 12, radius);
        ReferenceSettings s;
        s.samplesPerPixel = 64;
        s.shadows = false;
        const Image img = ReferenceRenderer().render(view, &strands, nullptr, s);
        const double expected = 2.0 * radius * pixelsPerUnitAtDepthOne(view.camera);
        double sum = 0.0;
        int columns = 0;
        for (int x = 8; x < 120; ++x, ++columns)
            for (int y = 0; y < img.height; ++y) sum += img.at(x, y, 3);
        EXPECT_NEAR(sum / columns, expected, 0.02 * expected) << "radius " << radius;
    }
}

TEST(Reference, ShadowRaysCountEachStrandCrossingOnce) {
    // Entry and exit of a tube, and the overlapping ends of two segments at a
    // vertex, are one crossing of that strand.
    EmbreeDevice device;
    StrandFrame strands;
    addLine(strands, 0, Vec3f(-0.5f, 0.f, 0.f), Vec3f(0.5f, 0.f, 0.f), 11, 0.01f);   // vertex every 0.1
    addLine(strands, 1, Vec3f(-0.5f, 0.1f, 0.f), Vec3f(0.5f, 0.1f, 0.f), 11, 0.01f);
    const TriangleMesh head = makeSphereMesh(Vec3f(0.f, 1.f, 0.f), 0.6f, 16, 32);  // above both
    const EmbreeScene scene(device, &strands, &head);
    const Vec3f up = Vec3f::UnitY();
    const float inf = std::numeric_limits<float>::infinity();
    for (float x : {0.05f, 0.1f, 0.2001f, -0.3f}) {  // mid-segment and exactly at vertices
        const Vec3f o(x, -0.5f, 0.f);
        EXPECT_FLOAT_EQ(scene.transmittance(o, up, 0.f, 0.05f + 0.5f, 0.5f), 0.5f) << "x " << x;  // first strand only
        EXPECT_FLOAT_EQ(scene.transmittance(o, up, 0.f, 0.7f, 0.5f), 0.25f) << "x " << x;         // both strands
        EXPECT_FLOAT_EQ(scene.transmittance(o, up, 0.f, inf, 0.5f), 0.f) << "x " << x;            // the head
        EXPECT_FLOAT_EQ(scene.transmittance(o, up, 0.f, 0.7f, 0.f), 0.f) << "x " << x;            // opaque hair
        EXPECT_FLOAT_EQ(scene.transmittance(o, up, 0.f, 0.7f, 1.f), 1.f) << "x " << x;            // no hair shadow
    }
    // A ray leaving strand 0's surface through its own tube skips it.
    const SceneHit h = scene.intersect(Vec3f(0.05f, -0.5f, 0.f), up, 0.f, inf);
    ASSERT_EQ(h.kind, SceneHit::Kind::Hair);
    EXPECT_EQ(h.strand, 0u);
    EXPECT_NEAR(h.t, 0.49f, 1e-4f);
    const Vec3f p = Vec3f(0.05f, -0.5f, 0.f) + h.t * up;
    EXPECT_FLOAT_EQ(scene.transmittance(p, up, 0.f, 0.05f, 0.5f, RayStart{h.strand, h.segment}), 1.f);
    const SceneHit next = scene.intersect(p, up, 0.f, inf, RayStart{h.strand, h.segment});
    EXPECT_EQ(next.strand, 1u);
}

TEST(Reference, SameBitsForOneAndTwoThreads) {
    HairOnHead shot = hairOnHead(80, 60);
    shot.view.environment = Vec3f(0.1f, 0.1f, 0.12f);
    // Physical three times more: with the ZSobol layout (one sequence for the
    // image), with split bounces and with efficiency-aware rates (trained
    // between passes).
    struct Case {
        ReferenceMode mode;
        sampling::SamplerType sampler;
        int splits;
        bool efficiency;
    };
    for (const Case& c : {Case{ReferenceMode::KajiyaKay, sampling::SamplerType::Independent, 1, false},
                          Case{ReferenceMode::Physical, sampling::SamplerType::Independent, 1, false},
                          Case{ReferenceMode::Physical, sampling::SamplerType::ZSobol, 1, false},
                          Case{ReferenceMode::Physical, sampling::SamplerType::Independent, 3, false},
                          Case{ReferenceMode::Physical, sampling::SamplerType::Independent, 1, true}}) {
        const ReferenceMode mode = c.mode;
        ReferenceSettings s;
        s.mode = mode;
        s.sampler = c.sampler;
        s.bounceSplits = c.splits;
        s.efficiencySplitting = c.efficiency;
        s.samplesPerPixel = 4;
        s.bounces = 3;
        s.tileSize = 8;
        s.diffuseSpecularLayers = true;
        s.strandIdLayer = true;
        Image one, two;
        tbb::task_arena(1).execute([&] { one = ReferenceRenderer().render(shot.view, &shot.strands, &shot.head, s); });
        tbb::task_arena(2).execute([&] { two = ReferenceRenderer().render(shot.view, &shot.strands, &shot.head, s); });
        ASSERT_EQ(one.pixels.size(), two.pixels.size());
        EXPECT_EQ(0, std::memcmp(one.pixels.data(), two.pixels.data(), one.pixels.size() * sizeof(float)))
            << referenceModeName(mode) << " " << sampling::samplerName(c.sampler) << " splits " << c.splits
            << " efficiency " << c.efficiency;
        double coverage = 0.0;
        for (int y = 0; y < one.height; ++y)
            for (int x = 0; x < one.width; ++x) coverage += one.at(x, y, 3);
        EXPECT_GT(coverage, 0.05 * one.width * one.height);  // hair and head are in the picture
        // A different frame draws different samples.
        s.frame = 2;
        const Image other = ReferenceRenderer().render(shot.view, &shot.strands, &shot.head, s);
        EXPECT_NE(0, std::memcmp(one.pixels.data(), other.pixels.data(), one.pixels.size() * sizeof(float)));
    }
}

TEST(Reference, OneBuiltSceneRendersBothModesBitForBit) {
    // The stage builds a frame's scene once for the physical reference and
    // its Kajiya-Kay companion: each render from the shared scene must be the
    // image a render that builds its own scene gives, in either order.
    HairOnHead shot = hairOnHead(48, 36);
    ReferenceSettings physical;
    physical.mode = ReferenceMode::Physical;
    physical.samplesPerPixel = 4;
    physical.bounces = 2;
    ReferenceSettings kk = physical;
    kk.mode = ReferenceMode::KajiyaKay;
    ReferenceRenderer renderer;
    const auto geometry = renderer.build(&shot.strands, &shot.head);
    ReferenceStats shared;
    const Image p1 = renderer.render(shot.view, *geometry, physical, &shared);
    const Image k1 = renderer.render(shot.view, *geometry, kk);
    const Image p2 = renderer.render(shot.view, *geometry, physical);
    EXPECT_GT(shared.segments, size_t(0));
    EXPECT_GT(shared.sceneBytes, 0);
    for (const auto& [image, s] : {std::pair{&p1, physical}, std::pair{&k1, kk}, std::pair{&p2, physical}}) {
        const Image own = ReferenceRenderer().render(shot.view, &shot.strands, &shot.head, s);
        ASSERT_EQ(own.pixels.size(), image->pixels.size());
        EXPECT_EQ(0, std::memcmp(own.pixels.data(), image->pixels.data(), own.pixels.size() * sizeof(float)))
            << referenceModeName(s.mode);
    }
}

TEST(Reference, ShadowRouletteKeepsTheMeanAndSavesRays) {
    // Dark hair: most light samples are small, so roulette skips most of
    // their shadow rays; weighting the traced ones by 1/q keeps the mean.
    const HairOnHead shot = hairOnHead(64, 48);
    ReferenceSettings s;
    s.mode = ReferenceMode::Physical;
    s.samplesPerPixel = 64;
    s.bounces = 2;
    auto render = [&](float threshold, ReferenceStats* stats) {
        s.shadowRouletteThreshold = threshold;
        const Image img = ReferenceRenderer().render(shot.view, &shot.strands, &shot.head, s, stats);
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (int y = 0; y < img.height; ++y)
            for (int x = 0; x < img.width; ++x)
                for (int c = 0; c < 3; ++c) sum[c] += img.at(x, y, c);
        return sum;
    };
    ReferenceStats all, roulette;
    const Eigen::Vector3d exact = render(0.f, &all);
    const Eigen::Vector3d skipped = render(0.25f, &roulette);
    const double camera = double(shot.view.camera.width) * shot.view.camera.height * s.samplesPerPixel;
    EXPECT_LT(double(roulette.rays) - camera, 0.75 * (double(all.rays) - camera));  // shadow + bounce rays
    for (int c = 0; c < 3; ++c) {
        ASSERT_GT(exact[c], 1.0) << "channel " << c;  // the hair is lit
        EXPECT_NEAR(skipped[c] / exact[c], 1.0, 0.03) << "channel " << c;
    }
}

TEST(Reference, NoEmbreeMemoryGrowthAcrossFrames) {
    ReferenceRenderer renderer;
    const int64_t idle = renderer.embreeBytesInUse();
    const TriangleMesh head = makeSphereMesh(Vec3f::Zero(), 0.1f, 16, 32);
    View view = testView(32, 24, Vec3f(-1.f, -1.f, -1.f));
    ReferenceSettings s;
    s.samplesPerPixel = 1;
    int64_t firstScene = -1;
    for (int frame = 0; frame < 5; ++frame) {
        SyntheticHairSettings hs;
        hs.strands = 2000;
        hs.droop = 0.2f * frame;  // the hair moves from frame to frame
        const StrandFrame strands = makeSyntheticHair(hs);
        ReferenceStats stats;
        s.frame = frame;
        renderer.render(view, &strands, &head, s, &stats);
        EXPECT_GT(stats.sceneBytes, int64_t(2000 * 23 * 4));  // the monitor sees at least the index buffer
        if (firstScene < 0) firstScene = stats.sceneBytes;
        EXPECT_EQ(stats.sceneBytes, firstScene) << "frame " << frame;
        EXPECT_EQ(renderer.embreeBytesInUse(), idle) << "frame " << frame << " left Embree memory behind";
    }
}

TEST(Reference, PhysicalWhiteFibreUnderWhiteSkyIsWhite) {
    // The furnace through the whole integrator: a non-absorbing fibre in a
    // uniform environment neither gains nor loses light.
    View view = testView(64, 48, Vec3f(0.f, -1.f, 0.f));
    view.lights.clear();
    view.environment = Vec3f::Ones();
    StrandFrame strands;
    addLine(strands, 0, Vec3f(-1.f, 0.f, 0.f), Vec3f(1.f, 0.f, 0.f), 9, 0.03f);
    ReferenceSettings s;
    s.mode = ReferenceMode::Physical;
    s.samplesPerPixel = 32;
    s.fiber.sigmaA = Vec3f::Zero();
    // Also with split bounces (each of the N continuations counts 1/N) and
    // with the ZSobol layout.
    for (const auto& [bounces, splits, zsobol] :
         {std::tuple{0, 1, false}, {2, 1, false}, {2, 3, false}, {2, 1, true}}) {
        s.bounces = bounces;
        s.bounceSplits = splits;
        s.sampler = zsobol ? sampling::SamplerType::ZSobol : sampling::SamplerType::Independent;
        const Image img = ReferenceRenderer().render(view, &strands, nullptr, s);
        double sum = 0.0;
        int n = 0;
        for (int y = 21; y <= 26; ++y)
            for (int x = 4; x < 60; ++x)
                if (img.at(x, y, 3) == 1.f) sum += img.at(x, y, 1), ++n;
        ASSERT_GT(n, 100);
        EXPECT_NEAR(sum / n, 1.0, 0.03) << "bounces " << bounces << " splits " << splits << " zsobol " << zsobol;
    }
}

TEST(Reference, NanVertexIsAClearFrameError) {
    SyntheticHairSettings hs;
    hs.strands = 10;
    StrandFrame strands = makeSyntheticHair(hs);
    strands.positions[strands.first(2) + 5].y() = std::numeric_limits<float>::quiet_NaN();
    try {
        ReferenceRenderer().render(testView(16, 16, Vec3f(0.f, -1.f, 0.f)), &strands, nullptr, ReferenceSettings{});
        FAIL() << "no error";
    } catch (const FrameError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("strand 2 (id 2) vertex 5"), std::string::npos) << m;
        EXPECT_NE(m.find("not finite"), std::string::npos) << m;
    }
    strands = makeSyntheticHair(hs);
    strands.radii[3] = -1.f;
    EXPECT_THROW(ReferenceRenderer().render(testView(16, 16, Vec3f(0.f, -1.f, 0.f)), &strands, nullptr, {}),
                 FrameError);
}

// ------------------------------------------------------------------ stage --

namespace {

Scene referenceScene(const std::string& extra = "") {
    return Scene::parse("frames: 1-2\n"
                        "render:\n  camera: {width: 64, height: 48}\n"
                        "reference:\n  enabled: true\n  samples: 2\n"
                        "  layers: {diffuse_specular: true, strand_id: true}\n" +
                            extra,
                        "test.yaml", std::filesystem::current_path());
}

/// Frame 1 of a shot whose only content is the head `pose` (no strands).
FrameData headOnlyFrame(const HeadPose& pose) {
    FrameData data;
    data.frame = 1;
    data.head = &pose;
    return data;
}

/// The head of the stage tests: a sphere of radius 0.1 m at the origin.
HeadPose sphereHead() {
    HeadPose pose;
    pose.mesh = makeSphereMesh(Vec3f::Zero(), 0.1f, 16, 32);
    return pose;
}

}  // namespace

TEST(ReferenceStage, WritesExrWithLayersAndPng) {
    TempDir dir;
    const Scene scene = referenceScene();
    ShotSettings shot;
    shot.outputDir = dir.path();
    shot.frames = {1, 2};
    const StagePtr stage = makeReferenceStage(scene, shot);
    ASSERT_TRUE(stage);
    EXPECT_EQ(stage->name(), "reference");
    const auto outputs = stage->outputs(2);
    ASSERT_EQ(outputs.size(), 2u);
    EXPECT_EQ(outputs[0], dir / "reference/reference.0002.exr");
    EXPECT_EQ(outputs[1], dir / "reference/reference.0002.png");

    SyntheticHairSettings hs;
    hs.strands = 500;
    const StrandFrame strands = makeSyntheticHair(hs);
    HeadPose pose;
    pose.mesh = makeSphereMesh(Vec3f::Zero(), 0.1f, 16, 32);
    FrameData data;
    data.frame = 2;
    data.head = &pose;
    data.strands = &strands;
    stage->run(data);

    const Image exr = readImage(outputs[0].string());
    EXPECT_EQ(exr.width, 64);
    for (const char* c : {"R", "G", "B", "A", "Z", "diffuse.R", "specular.B", "strand_id"})
        EXPECT_GE(exr.channelIndex(c), 0) << c;
    // The layers add up to the colour (half-float precision), and the head
    // in the middle has a depth and no strand id where hair does not cover it.
    const int r = exr.channelIndex("R"), d = exr.channelIndex("diffuse.R"), s = exr.channelIndex("specular.R");
    double worst = 0.0, idMax = -1.0;
    for (int y = 0; y < exr.height; ++y)
        for (int x = 0; x < exr.width; ++x) {
            const float sum = exr.at(x, y, d) + exr.at(x, y, s);
            worst = std::max(worst, double(std::abs(sum - exr.at(x, y, r))) / (1e-2 + exr.at(x, y, r)));
            idMax = std::max(idMax, double(exr.at(x, y, exr.channelIndex("strand_id"))));
        }
    EXPECT_LT(worst, 0.01);
    EXPECT_GE(idMax, 0.0);
    EXPECT_LT(idMax, 500.0);
    EXPECT_NEAR(exr.at(32, 24, exr.channelIndex("Z")), 0.8f, 0.05f);  // sphere front at 0.9 − 0.1, or hair just in front
    const Image png = readImage(outputs[1].string());
    EXPECT_EQ(png.channelCount(), 4);
}

TEST(ReferenceStage, HeadAloneWithoutStrandsAndNothingIsAnError) {
    TempDir dir;
    ShotSettings shot;
    shot.outputDir = dir.path();
    const StagePtr stage = makeReferenceStage(referenceScene("  png: \"\"\n"), shot);
    ASSERT_EQ(stage->outputs(1).size(), 1u);  // empty png template writes no PNG
    const HeadPose pose = sphereHead();
    FrameData data = headOnlyFrame(pose);
    stage->run(data);
    const Image img = readImage(stage->outputs(1)[0].string());
    EXPECT_FLOAT_EQ(img.at(32, 24, img.channelIndex("A")), 1.f);

    data.head = nullptr;
    try {
        stage->run(data);
        FAIL() << "no error";
    } catch (const FrameError& e) {
        EXPECT_NE(std::string(e.what()).find("neither strands nor a head"), std::string::npos) << e.what();
    }
}

TEST(ReferenceStage, DisabledOrBadTemplates) {
    ShotSettings shot;
    shot.outputDir = std::filesystem::temp_directory_path();
    EXPECT_FALSE(makeReferenceStage(Scene::parse("frames: 1\n", "t.yaml", "."), shot));
    try {
        makeReferenceStage(referenceScene("  exr: reference.exr\n"), shot);
        FAIL() << "no error";
    } catch (const SceneError& e) {
        EXPECT_EQ(e.key(), "reference.exr");
        EXPECT_NE(std::string(e.what()).find("frame token"), std::string::npos) << e.what();
    }
}

TEST(ReferenceStage, KajiyaKayCompanionBesidePhysical) {
    TempDir dir;
    ShotSettings shot;
    shot.outputDir = dir.path();
    const StagePtr stage =
        makeReferenceStage(
        referenceScene("  mode: physical\n  png: \"\"\n  kajiya_kay: {enabled: true, png: \"\", samples: 2}\n"), shot);
    ASSERT_EQ(stage->outputs(1), (std::vector<std::filesystem::path>{dir.path() / "reference/reference.0001.exr",
                                                                     dir.path() / "reference/kajiya-kay.0001.exr"}));
    const HeadPose pose = sphereHead();
    FrameData data = headOnlyFrame(pose);
    stage->run(data);
    const Image physical = readImage(stage->outputs(1)[0].string());
    const Image kk = readImage(stage->outputs(1)[1].string());
    ASSERT_EQ(physical.width, kk.width);
    // Same camera, samples (2, given to both) and seed: the same coverage, pixel for pixel. The
    // skin is one model with one albedo in both modes (no ambient by
    // default), so the two differ only by what the physical mode adds: the
    // light its bounces bring and its sampling noise (summed |ΔR| measured
    // 0.53 on this frame); a copy of the physical image would differ by 0.
    double alphaDiff = 0.0, colourDiff = 0.0;
    const int a = physical.channelIndex("A");
    for (int y = 0; y < kk.height; ++y)
        for (int x = 0; x < kk.width; ++x) {
            alphaDiff += std::abs(physical.at(x, y, a) - kk.at(x, y, a));
            colourDiff += std::abs(physical.at(x, y, 0) - kk.at(x, y, 0));
        }
    EXPECT_EQ(alphaDiff, 0.0);
    EXPECT_GT(colourDiff, 0.05);

    try {
        makeReferenceStage(referenceScene("  kajiya_kay: {enabled: true}\n"), shot);
        FAIL() << "a Kajiya-Kay companion of a Kajiya-Kay reference must be refused";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("reference.kajiya_kay.enabled"), std::string::npos) << e.what();
    }
}

TEST(ReferenceStage, KajiyaKayCompanionHasItsOwnBudget) {
    // reference.kajiya_kay.samples: the companion takes exactly that many
    // samples in every pixel, while the physical reference beside it keeps
    // its adaptive settings, bit for bit what it is without the companion.
    const HeadPose pose = sphereHead();
    const FrameData data = headOnlyFrame(pose);
    auto render = [&](const std::string& companion) {
        TempDir dir;
        ShotSettings shot;
        shot.outputDir = dir.path();
        const StagePtr stage = makeReferenceStage(
            Scene::parse("frames: 1\nrender:\n  camera: {width: 48, height: 40}\n"
                         "reference:\n  enabled: true\n  mode: physical\n  png: \"\"\n"
                         "  noise_threshold: 0.05\n  min_samples: 2\n  max_samples: 32\n" + companion,
                         "test.yaml", std::filesystem::current_path()),
            shot);
        stage->run(data);
        std::vector<Image> images;
        for (const std::filesystem::path& p : stage->outputs(1)) images.push_back(readImage(p.string()));
        return images;
    };
    auto samples = [](const Image& image, int x, int y) { return image.at(x, y, image.channelIndex("samples")); };

    const std::vector<Image> alone = render("");
    const std::vector<Image> budget = render("  kajiya_kay: {enabled: true, png: \"\", samples: 4}\n");
    const std::vector<Image> same = render("  kajiya_kay: {enabled: true, png: \"\", samples: 0}\n");
    ASSERT_EQ(alone.size(), 1u);
    ASSERT_EQ(budget.size(), 2u);
    ASSERT_EQ(same.size(), 2u);
    const Image& physical = alone[0];
    ASSERT_EQ(budget[0].channels, physical.channels);
    EXPECT_TRUE(budget[0].pixels == physical.pixels) << "the companion's budget changed the physical reference";
    int adaptive = 0, fixedFour = 0;
    float fewest = 1e9f, most = 0.f;
    for (int y = 0; y < physical.height; ++y)
        for (int x = 0; x < physical.width; ++x) {
            fixedFour += samples(budget[1], x, y) == 4.f;
            adaptive += samples(physical, x, y) != 4.f;
            // samples: 0 samples the companion as the physical reference is
            // sampled: adaptively, from min_samples up to max_samples.
            fewest = std::min(fewest, samples(same[1], x, y));
            most = std::max(most, samples(same[1], x, y));
        }
    EXPECT_EQ(fixedFour, physical.width * physical.height);
    // The physical reference's own counts (2 to 32, adaptive) are not the
    // companion's, or the test could not tell the budgets apart.
    EXPECT_GT(adaptive, 0);
    EXPECT_EQ(fewest, 2.f);
    EXPECT_GT(most, 4.f);
    EXPECT_LE(most, 32.f);
}
