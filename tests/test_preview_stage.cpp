// The preview in the pipeline: scene keys, the "preview" frame stage's files
// and errors, and `hairpipe view` in a scripted run under Xvfb.
#include "test_support.h"

#include "pipeline/scene/preview_settings.h"
#include "pipeline/scene/scene.h"
#include "pipeline/stages/stages.h"
#include "render/preview/gl_context.h"
#include "render/image/image_io.h"
#include "sim/strands/synthetic.h"

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <thread>

namespace hp {
namespace {

using test::TempDir;

/// Headless GL availability, with EGL's reason when missing.
bool haveGl(std::string* why) {
    try {
        GlContext::createHeadless();
        return true;
    } catch (const Error& e) {
        *why = e.what();
        return false;
    }
}

TEST(PreviewStage, KeysMapOntoSettings) {
    const Scene scene = Scene::parse(R"(
preview:
  msaa: 2
  shading: fragment
  tessellation: {curve: b-spline, level: 5, pixels: 3}
  shadow: {voxel_mode: binary, resolution: 64, alpha: 0.5, map: false, pcf_radius: 2}
  generated:
    enabled: true
    types: [{segments: 7}, {color: [1, 0, 0], segment_length: 0.01}]
    regions: [{shape: all, type: 1}, {shape: cap, axis: [0, 0, 1], angle: 30}]
)",
                                     "keys.yaml", ".");
    const PreviewSettings s = makePreviewSettings(scene);
    EXPECT_EQ(s.msaa, 2);
    EXPECT_TRUE(s.shadePerFragment);
    EXPECT_FALSE(s.shadeInCompute);
    const Scene compute = Scene::parse("preview: {shading: compute}\n", "keys.yaml", ".");
    EXPECT_FALSE(makePreviewSettings(compute).shadePerFragment);
    EXPECT_TRUE(makePreviewSettings(compute).shadeInCompute);
    EXPECT_FALSE(makePreviewSettings(Scene::parse("preview: {}\n", "keys.yaml", ".")).shadeInCompute);
    EXPECT_EQ(s.curve, CurveType::BSpline);
    EXPECT_EQ(s.tessellationLevel, 5);
    EXPECT_EQ(s.shadow.mode, VoxelMode::Binary);
    EXPECT_EQ(s.shadow.resolution, 64);
    EXPECT_FALSE(s.shadow.shadowMap);
    ASSERT_EQ(s.generated.types.size(), 2u);
    EXPECT_EQ(s.generated.types[0].segments, 7);
    EXPECT_FLOAT_EQ(s.generated.types[1].segmentLength, 0.01f);
    ASSERT_EQ(s.generated.regions.size(), 2u);
    EXPECT_EQ(s.generated.regions[0].shape, HairRegion::Shape::All);
    EXPECT_EQ(s.generated.regions[0].type, 1);
    EXPECT_FLOAT_EQ(s.generated.regions[1].angle, 30.f);
}

TEST(PreviewStage, CrossKeyErrorsNameTheKey) {
    auto message = [](const std::string& yaml) {
        try {
            makePreviewSettings(Scene::parse(yaml, "bad.yaml", "."));
        } catch (const SceneError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(message("preview: {shadow: {voxel_mode: binary, splat: trilinear}}").find("preview.shadow.splat"),
              std::string::npos);
    EXPECT_NE(message("preview: {shadow: {max_lights: 5}}").find("preview.shadow.max_lights"), std::string::npos);
    EXPECT_NE(message("preview: {generated: {regions: [{type: 2}]}}").find("preview.generated.regions[0].type"),
              std::string::npos);
    try {
        const Scene s = Scene::parse("preview: {enabled: true, exr: out.exr}", "bad.yaml", ".");
        makePreviewStage(s, ShotSettings{});
        FAIL() << "a template without a frame token must be refused";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("preview.exr"), std::string::npos) << e.what();
    }
}

TEST(PreviewStage, WritesExrWithAlphaAndDepthAndPng) {
    std::string why;
    if (!haveGl(&why)) GTEST_SKIP() << "no headless OpenGL 4.5 through EGL: " << why;
    TempDir dir;
    const Scene scene = Scene::parse(R"(
render: {camera: {width: 160, height: 90}}
preview: {enabled: true, shadow: {resolution: 32, map_size: 256}}
)",
                                     "stage.yaml", dir.path());
    ShotSettings shot;
    shot.outputDir = dir.path();
    StagePtr stage = makePreviewStage(scene, shot);
    ASSERT_TRUE(stage);
    EXPECT_EQ(stage->name(), "preview");
    const auto outputs = stage->outputs(7);
    ASSERT_EQ(outputs.size(), 2u);
    EXPECT_EQ(outputs[0], dir.path() / "preview/preview.0007.exr");

    // Neither strands nor head: a clear frame error.
    FrameData empty;
    empty.frame = 7;
    try {
        stage->run(empty);
        FAIL() << "expected a FrameError";
    } catch (const FrameError& e) {
        EXPECT_NE(std::string(e.what()).find("neither hair strands nor a head"), std::string::npos) << e.what();
    }

    SyntheticHairSettings hs;
    hs.strands = 2000;
    const StrandFrame strands = makeSyntheticHair(hs);
    const HeadPose head = SpinningSphere(0.1f, 90.f, 16, 32).sample(0.25);
    FrameData data;
    data.frame = 7;
    data.time = 7 / 24.0;
    data.strands = &strands;
    data.head = &head;
    stage->run(data);
    const Image exr = readImage(outputs[0].string());
    ASSERT_EQ(exr.channels, (std::vector<std::string>{"R", "G", "B", "A", "Z"}));
    double alpha = 0.0;
    float nearest = INFINITY, farthest = 0.f;
    for (int y = 0; y < exr.height; ++y)
        for (int x = 0; x < exr.width; ++x) {
            alpha += exr.at(x, y, 3);
            if (exr.at(x, y, 3) > 0.5f) {
                nearest = std::min(nearest, exr.at(x, y, 4));
                farthest = std::max(farthest, exr.at(x, y, 4));
            }
        }
    EXPECT_GT(alpha, 0.04 * exr.width * exr.height);  // the head alone covers ~4 %
    EXPECT_TRUE(std::isinf(exr.at(0, 0, 4))) << "empty corner: Z = +inf";
    // Camera at 0.9 m from the sphere's centre: covered depths lie between the hair's front and the sphere's back.
    EXPECT_GT(nearest, 0.9f - 0.36f);
    EXPECT_LT(farthest, 0.9f + 0.1f);
    const Image png = readImage(outputs[1].string());
    EXPECT_EQ(png.channelCount(), 4);
    EXPECT_EQ(png.width, 160);
    // Resume: the stage's files exist, so the scheduler would skip the frame.
    EXPECT_TRUE(std::filesystem::exists(outputs[1]));
}

TEST(PreviewStage, RenderCommandReportsMissingGeometry) {
    TempDir dir;
    test::writeFile(dir / "s.yaml", "frames: 1-2\npreview: {enabled: true}\n");
    const test::ProcessResult r = test::runHairpipe("render --preview s.yaml --out out", dir.path());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("neither hair strands nor a head"), std::string::npos) << r.output;
}

/// An X server of our own for the viewer test; stopped by its pid.
class Xvfb {
  public:
    Xvfb() {
        const std::string cmd = "Xvfb -displayfd 3 -screen 0 640x480x24 -nolisten tcp 3>'" +
                                (dir_ / "display").string() + "' >/dev/null 2>&1 & echo $! > '" +
                                (dir_ / "pid").string() + "'";
        if (std::system(("command -v Xvfb >/dev/null && (" + cmd + ")").c_str()) != 0) return;
        pid_ = std::atoi(test::readFile(dir_ / "pid").c_str());
        for (int i = 0; i < 100 && display_.empty(); ++i) {
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
            std::string text = test::readFile(dir_ / "display");
            if (!text.empty() && text.back() == '\n') display_ = ":" + text.substr(0, text.size() - 1);
        }
    }
    ~Xvfb() {
        if (pid_ > 0) ::kill(pid_, SIGTERM);
    }
    const std::string& display() const { return display_; }

  private:
    TempDir dir_;
    int pid_ = 0;
    std::string display_;
};

TEST(PreviewStage, ViewerRendersUnderXvfb) {
    Xvfb server;
    if (server.display().empty()) GTEST_SKIP() << "no X server: Xvfb (Debian package xvfb) is missing or did not start";
    setenv("DISPLAY", server.display().c_str(), 1);
    TempDir dir;
    test::writeFile(dir / "v.yaml", "frames: 1-2\npreview: {shadow: {resolution: 32}, generated: {enabled: true}}\n");
    const test::ProcessResult r = test::runHairpipe(
        "view v.yaml --synthetic 1000 --size 200x150 --exit-after 2 --screenshot shot.png", dir.path());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const Image shot = readImage((dir / "shot.png").string());
    ASSERT_EQ(shot.width, 200);
    ASSERT_EQ(shot.height, 150);
    // The sphere and its hair cover the middle; the corners stay background.
    size_t lit = 0;
    for (int y = 0; y < shot.height; ++y)
        for (int x = 0; x < shot.width; ++x) lit += shot.at(x, y, 0) + shot.at(x, y, 1) + shot.at(x, y, 2) > 0.1f;
    EXPECT_GT(lit, size_t(shot.width * shot.height / 10)) << r.output;
    EXPECT_LT(shot.at(0, 0, 0) + shot.at(0, 0, 1) + shot.at(0, 0, 2), 0.05f);
}

TEST(PreviewStage, ViewerWithoutDisplayIsAClearError) {
    TempDir dir;
    test::writeFile(dir / "v.yaml", "frames: 1\n");
    setenv("DISPLAY", ":9999", 1);  // nothing listens there
    const test::ProcessResult r = test::runHairpipe("view v.yaml --exit-after 1", dir.path());
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find("needs a display"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace hp
