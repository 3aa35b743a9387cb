// Camera auto (render/view/camera_framing.h, pipeline/stages/camera_track.h): for the
// project's head, a sphere-and-neck head built here and the Fox asset, the
// framed camera keeps the whole head and the hair's bounds inside the frame
// on every frame. The checks project, with the camera's own view and
// projection matrices, every head vertex of every frame and points sampled
// on the surface of every hair-reach sphere (scalp vertex grown by the
// hair's rest length), so they are independent of the fit's plane algebra.
// A rendered check (Embree reference, small frames, strands standing at
// full reach) finds alpha 0 on the whole frame border.
#include "test_support.h"
#include "batch_support.h"

#include "pipeline/stages/camera_track.h"
#include "pipeline/head/head_setup.h"
#include "pipeline/scene/scene.h"
#include "pipeline/stages/stages.h"
#include "pipeline/scene/view_settings.h"
#include "render/image/image_io.h"

#include <cmath>

namespace hp {
namespace {

using test::TempDir;

/// Normalised device coordinates of `p` (x, y in [-1, 1] inside the frame)
/// and its depth along the view axis.
Vec3f project(const Camera& c, const Vec3f& p) {
    const Vec4f clip = c.projection() * c.view() * Vec4f(p.x(), p.y(), p.z(), 1.f);
    return Vec3f(clip.x() / clip.w(), clip.y() / clip.w(), clip.w());
}

/// 100 unit directions spread over the sphere (Fibonacci lattice).
std::vector<Vec3f> sphereDirections() {
    std::vector<Vec3f> d;
    const int n = 100;
    for (int i = 0; i < n; ++i) {
        const float z = 1.f - 2.f * (i + 0.5f) / n, r = std::sqrt(1.f - z * z);
        const float phi = float(i) * 2.39996323f;
        d.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
    }
    return d;
}

/// The largest |NDC x| or |NDC y| over the frame's head vertices and its hair
/// bounds (points on every scalp-vertex sphere of radius `reach`); fails the
/// test when anything lies behind the camera.
float largestExtent(const Camera& c, const TriangleMesh& mesh, const std::vector<uint8_t>& scalp, float reach) {
    static const std::vector<Vec3f> directions = sphereDirections();
    float most = 0.f;
    auto add = [&](const Vec3f& p) {
        const Vec3f q = project(c, p);
        EXPECT_GT(q.z(), c.nearClip);
        most = std::max({most, std::abs(q.x()), std::abs(q.y())});
    };
    for (const Vec3f& p : mesh.positions) add(p);
    std::vector<uint8_t> grown(mesh.positions.size(), 0);
    for (size_t t = 0; t < scalp.size(); ++t)
        if (scalp[t])
            for (uint32_t v : mesh.triangles[t]) grown[v] = 1;
    for (size_t v = 0; v < grown.size(); ++v)
        if (grown[v])
            for (const Vec3f& d : directions) add(mesh.positions[v] + reach * d);
    return most;
}

/// A head sphere (radius 0.1 m) on an elongated-sphere neck, as one mesh;
/// `scalp` marks the head sphere's upper half.
TriangleMesh sphereAndNeck(std::vector<uint8_t>* scalp) {
    TriangleMesh head = makeSphereMesh(Vec3f(0.f, 0.1f, 0.f), 0.1f, 16, 32);
    TriangleMesh neck = makeSphereMesh(Vec3f::Zero(), 0.05f, 8, 16);
    for (Vec3f& p : neck.positions) p = Vec3f(p.x(), -0.06f + 2.f * p.y(), p.z());
    scalp->assign(head.triangles.size(), 0);
    for (size_t t = 0; t < head.triangles.size(); ++t) {
        bool upper = true;
        for (uint32_t v : head.triangles[t]) upper &= head.positions[v].y() > 0.1f;
        (*scalp)[t] = upper;
    }
    const uint32_t base = uint32_t(head.positions.size());
    head.positions.insert(head.positions.end(), neck.positions.begin(), neck.positions.end());
    for (Tri t : neck.triangles) head.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    scalp->resize(head.triangles.size(), 0);
    return head;
}

/// The sphere-and-neck head shaking (±50°) and nodding (±20°); at `cut`
/// seconds the shot cuts to the head 0.6 m to the side, turned 90°.
class ShakingHead final : public HeadMotion {
  public:
    ShakingHead(TriangleMesh rest, double cut) : rest_(std::move(rest)), cut_(cut) {}
    HeadPose sample(double t) const override {
        const float yaw = 50.f * float(std::sin(2.0 * M_PI * 0.7 * t)), pitch = 20.f * float(std::sin(2.0 * M_PI * t));
        Eigen::Isometry3f m = Eigen::Isometry3f::Identity();
        if (t >= cut_) {
            m.translate(Vec3f(0.6f, 0.2f, -0.3f));
            m.rotate(Eigen::AngleAxisf(float(M_PI / 2), Vec3f::UnitY()));
        }
        m.rotate(Eigen::AngleAxisf(yaw * float(M_PI / 180), Vec3f::UnitY()));
        m.rotate(Eigen::AngleAxisf(pitch * float(M_PI / 180), Vec3f::UnitX()));
        HeadPose pose;
        pose.time = t;
        pose.transform = m;
        pose.mesh = rest_;
        for (Vec3f& p : pose.mesh.positions) p = m * p;
        return pose;
    }

  private:
    TriangleMesh rest_;
    double cut_;
};

Camera smallLens() {
    Camera lens;
    lens.width = 320;
    lens.height = 180;
    lens.fovY = 38.f;
    return lens;
}

TEST(CameraAuto, SphereAndNeckHeadStaysInFrameAndIsReframedAfterACut) {
    std::vector<uint8_t> scalp;
    const ShakingHead head(sphereAndNeck(&scalp), 1.0);
    std::vector<int> frames;
    for (int f = 1; f <= 48; ++f) frames.push_back(f);
    const float reach = 0.2f;
    FramingSettings settings;
    const std::vector<FramingSample> samples = sampleHeadForFraming(head, scalp, reach, frames, 24.0);
    const std::vector<size_t> starts = segmentStarts(samples, settings);
    // The cut at 1 s is frame 24: one segment before, one from there.
    for (size_t i = 0; i < starts.size(); ++i) EXPECT_EQ(starts[i], frames[i] < 24 ? 0u : 23u) << "frame " << frames[i];
    for (bool follow : {false, true}) {
        settings.follow = follow;
        const std::vector<Camera> cameras = frameSamples(samples, starts, smallLens(), settings);
        float widest = 0.f;
        for (size_t i = 0; i < frames.size(); ++i) {
            const HeadPose pose = head.sample(frames[i] / 24.0);
            const float extent = largestExtent(cameras[i], pose.mesh, scalp, reach);
            EXPECT_LE(extent, 1.f - 0.5f * settings.margin) << "frame " << frames[i] << (follow ? " (follow)" : "");
            widest = std::max(widest, extent);
        }
        // Tight, not merely inside: the bounds reach the margin on some frame.
        EXPECT_GT(widest, 1.f - 2.f * settings.margin) << (follow ? "follow" : "auto");
    }
    // The re-framing matters: the first segment's camera loses the head after the cut.
    settings.follow = false;
    const std::vector<Camera> cameras = frameSamples(samples, starts, smallLens(), settings);
    const HeadPose after = head.sample(30 / 24.0);
    EXPECT_GT(largestExtent(cameras.front(), after.mesh, scalp, reach), 1.f);
}

/// Checks makeCameraTrack's camera of a scene's head over its whole clip,
/// against the head sampled here and its hair reach (hair.guides.length).
void expectHeadAndHairInFrame(const Scene& scene) {
    const Camera lens = makeView(scene).camera;
    const CameraTrack track = makeCameraTrack(scene, lens, std::filesystem::temp_directory_path(), false);
    ASSERT_TRUE(track.framed());
    const HeadSetup head = loadHead(scene);
    const float reach = float(scene.number("hair.guides.length"));
    const float margin = float(scene.number("render.camera.margin"));
    float widest = 0.f;
    for (int frame : scene.frames("frames")) {
        const HeadPose pose = head.motion->sample(frame / scene.number("fps"));
        const float extent = largestExtent(track.at(frame), pose.mesh, head.scalp, reach);
        EXPECT_LE(extent, 1.f - 0.5f * margin) << scene.name() << " frame " << frame;
        widest = std::max(widest, extent);
    }
    // The head is framed, not lost in the distance: its hair reach (10%
    // larger in the fit) fills the frame to within a few percent of the margin.
    EXPECT_GT(widest, 1.f - 3.f * margin) << scene.name();
}

TEST(CameraAuto, ProjectHeadAndHairStayInFrame) {
    // The default scene's head, clip and scalp, framed by the hair's reach,
    // with camera auto (the whole clip at once) and follow (each frame alone,
    // what the default scene uses).
    const Scene scene = Scene::load(test::sourcePath("scenes/default.yaml"),
                                    {"render.camera.hair=reach", "render.camera.mode=auto"});
    expectHeadAndHairInFrame(scene);
    const Scene follow = Scene::load(test::sourcePath("scenes/default.yaml"), {"render.camera.hair=reach"});
    EXPECT_EQ(follow.text("render.camera.mode"), "follow") << "the default scene frames each frame";
    expectHeadAndHairInFrame(follow);
}

TEST(CameraAuto, StressClipIsReframedAtItsSceneCut) {
    // The stress clip cuts to another pose at 2 s (frame 50; `hairpipe info
    // scenes/stress.yaml`): the camera changes exactly there, and head and
    // hair stay in frame on both sides.
    // Camera auto (one framing per segment) by the hair's reach.
    const Scene scene = Scene::load(test::sourcePath("scenes/stress.yaml"),
                                    {"render.camera.mode=auto", "render.camera.hair=reach"});
    const CameraTrack track = makeCameraTrack(scene, makeView(scene).camera, std::filesystem::temp_directory_path(), false);
    for (int frame = 2; frame <= 62; ++frame) {
        const bool moved = !track.at(frame).position.isApprox(track.at(frame - 1).position);
        EXPECT_EQ(moved, frame == 50) << "frame " << frame;
    }
    expectHeadAndHairInFrame(scene);
}

TEST(CameraAuto, FoxStaysInFrame) {
    HP_REQUIRE_ASSET(fox, "Fox.glb");
    const Scene scene = Scene::parse("frames: 1-40\nhead: {file: '" + fox.string() +
                                         "', unit_scale: 0.01, clip: Survey}\n"
                                         "hair: {guides: {count: 10, length: 0.08}}\n"
                                         "render: {camera: {width: 320, height: 180}}\n",
                                     "fox.yaml", ".");
    expectHeadAndHairInFrame(scene);
}

TEST(CameraAuto, PositionWithAutoIsAnErrorAndPositionAloneIsFixed) {
    try {
        checkCameraKeys(Scene::parse("render: {camera: {mode: auto, position: [0, 0, 1]}}", "cam.yaml", "."));
        FAIL() << "a position with mode auto must be refused";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("render.camera.position"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("mode: fixed"), std::string::npos) << e.what();
    }
    const Scene fixed = Scene::parse("render: {camera: {position: [0.3, 0.1, 1]}}", "cam.yaml", ".");
    const CameraTrack track = makeCameraTrack(fixed, makeView(fixed).camera, ".");
    EXPECT_FALSE(track.framed());
    EXPECT_TRUE(track.at(1).position.isApprox(Vec3f(0.3f, 0.1f, 1.f)));
}

TEST(CameraAuto, MissingStrandCacheNamesTheFile) {
    TempDir dir;
    const Scene scene = Scene::load(test::sourcePath("scenes/default.yaml"), {"render.camera.hair=cache"});
    try {
        makeCameraTrack(scene, makeView(scene).camera, dir.path()).at(1);  // read on first use
        FAIL() << "camera auto with hair: cache needs the strand cache";
    } catch (const FrameError& e) {
        EXPECT_NE(std::string(e.what()).find("strands.0001.hpc"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("render.camera.hair: reach"), std::string::npos) << e.what();
    }
}

TEST(CameraAuto, DefaultFramesTheCachedHairUnlessTheSceneWritesNoCache) {
    // The default camera is the default shot's: follow, on the cached hair.
    const std::string head = "head: {file: " + test::sourcePath("scenes/assets/head.glb").string() + "}\n";
    const Scene plain = Scene::parse(head, "cam.yaml", ".");
    EXPECT_EQ(plain.text("render.camera.mode"), "follow");
    EXPECT_TRUE(cameraReadsStrandCache(plain));
    // Without a cache the default frames by the hair's reach instead of
    // failing the scene; asked for explicitly, the cache stays an error.
    const Scene noCache = Scene::parse(head + "cache: {enabled: false}\n", "cam.yaml", ".");
    EXPECT_FALSE(cameraReadsStrandCache(noCache));
    EXPECT_NO_THROW(checkCameraKeys(noCache));
    const Scene asked = Scene::parse(head + "cache: {enabled: false}\nrender: {camera: {hair: cache}}\n", "cam.yaml", ".");
    const SceneError e = test::sceneErrorOf([&] { checkCameraKeys(asked); }, "hair: cache without a cache");
    EXPECT_EQ(e.key(), "render.camera.hair");
    // A fixed camera reads nothing.
    EXPECT_FALSE(cameraReadsStrandCache(Scene::parse(head + "render: {camera: {position: [0, 0, 1]}}\n", "c.yaml", ".")));
}

/// Straight strands from every scalp vertex of `mesh`, `length` long, along
/// the vertex's direction from the head's centre tilted up: hair standing at
/// its full reach, the case the framing must still hold.
StrandFrame standingHair(const TriangleMesh& mesh, const std::vector<uint8_t>& scalp, float length) {
    const Vec3f centre = mesh.bounds().center();
    std::vector<uint8_t> used(mesh.positions.size(), 0);
    for (size_t t = 0; t < scalp.size(); ++t)
        if (scalp[t])
            for (uint32_t v : mesh.triangles[t]) used[v] = 1;
    StrandFrame hair;
    for (uint32_t v = 0; v < used.size(); ++v) {
        if (!used[v]) continue;
        const Vec3f root = mesh.positions[v];
        const Vec3f dir = ((root - centre).normalized() + Vec3f(0.f, 0.5f, 0.f)).normalized();
        std::vector<Vec3f> points;
        for (int k = 0; k <= 8; ++k) points.push_back(root + (length * k / 8.f) * dir);
        const std::vector<float> radii(points.size(), 0.0005f);
        hair.addStrand(v, points.data(), radii.data(), points.size());
    }
    return hair;
}

TEST(CameraAuto, RenderedBorderHasNoCoverage) {
    TempDir dir;
    // The default scene's shoulders (head.colliders[0]) are drawn as a bust
    // the frame cuts by design; the camera frames the head and its hair,
    // which is what this test checks, so they are hidden here.
    const Scene scene = Scene::load(
        test::sourcePath("scenes/default.yaml"),
        {"render.camera.hair=reach", "render.camera.width=96", "render.camera.height=54", "reference.samples=1",
         "reference.mode=kajiya-kay", "reference.kajiya_kay.enabled=false", "reference.png=''",
         "head.colliders[0].visible=false"});
    ShotSettings shot;
    shot.outputDir = dir.path();
    shot.fps = scene.number("fps");
    StagePtr stage = makeReferenceStage(scene, shot);
    ASSERT_TRUE(stage);
    const HeadSetup head = loadHead(scene);
    for (int frame : {1, 42, 84}) {
        FrameData data;
        data.frame = frame;
        data.time = frame / shot.fps;
        const HeadPose pose = head.motion->sample(data.time);
        const StrandFrame hair = standingHair(pose.mesh, head.scalp, float(scene.number("hair.guides.length")));
        data.head = &pose;
        data.strands = &hair;
        stage->run(data);
        const Image image = readImage(stage->outputs(frame).front().string());
        double border = 0.0, total = 0.0;
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x) {
                const float a = image.at(x, y, 3);
                total += a;
                if (x == 0 || y == 0 || x == image.width - 1 || y == image.height - 1) border += a;
            }
        EXPECT_EQ(border, 0.0) << "frame " << frame << ": coverage on the border";
        EXPECT_GT(total, 0.1 * image.width * image.height) << "frame " << frame << ": the head and hair are framed";
    }
}

TEST(CameraAuto, RunSimulatesTheClipFirstAndChunksFrameAlike) {
    // Camera auto from the cached hair: rendering frame 2 alone needs the
    // strands of its whole cut-free segment (here the clip, which has no
    // cut), says so, and --jobs chunks must all get the same camera.
    TempDir dir;
    const std::filesystem::path scene = dir / "auto.yaml";
    test::writeFile(scene, "frames: 1-6\nseed: 3\n"
                           "head: {file: " + test::sourcePath("scenes/assets/head.glb").string() +
                               ", clip: nod_shake_turn}\n"
                               "hair: {guides: {count: 16, length: 0.15, segments: 8}, followers: {count: 300}}\n"
                               "render: {camera: {mode: auto, hair: cache, width: 64, height: 36}}\n"
                               "reference: {enabled: true, samples: 1, png: ''}\n");
    const test::ProcessResult one = test::runHairpipe("run -v " + test::q(scene) + " --out " + test::q(dir / "one") +
                                                      " --frames 2 --stages reference");
    ASSERT_EQ(one.exitCode, 0) << one.output;
    EXPECT_NE(one.output.find("frames whole segments of the clip: simulating 5 more frames (1-6)"), std::string::npos)
        << one.output;
    EXPECT_TRUE(std::filesystem::exists(dir / "one/cache/strands.0006.hpc")) << "the clip's last frame is cached";
    // A run that renders nothing needs no camera: it simulates its own frames only.
    const test::ProcessResult sim = test::runHairpipe("run -q " + test::q(scene) + " --out " + test::q(dir / "sim") +
                                                      " --frames 1-2 --stages sim");
    ASSERT_EQ(sim.exitCode, 0) << sim.output;
    EXPECT_TRUE(std::filesystem::exists(dir / "sim/cache/strands.0002.hpc"));
    EXPECT_FALSE(std::filesystem::exists(dir / "sim/cache/strands.0003.hpc")) << "sim alone stops at its frames";
    const test::ProcessResult jobs = test::runHairpipe("run -q " + test::q(scene) + " --out " + test::q(dir / "jobs") +
                                                       " --frames 1-6 --stages reference --jobs 2 --chunk 1");
    ASSERT_EQ(jobs.exitCode, 0) << jobs.output;
    // The same pixels (the files differ only in their capture date).
    const Image a = readImage((dir / "one/reference/reference.0002.exr").string());
    const Image b = readImage((dir / "jobs/reference/reference.0002.exr").string());
    EXPECT_EQ(a.pixels, b.pixels);
}

}  // namespace
}  // namespace hp
