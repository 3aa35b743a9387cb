#include "pipeline/stages/camera_track.h"
#include "pipeline/scene/key_fields.h"

#include "core/log.h"
#include "pipeline/head/clip_cuts.h"
#include "pipeline/scene/curly_settings.h"
#include "pipeline/stages/hair_source.h"
#include "pipeline/head/head_setup.h"
#include "pipeline/stages/shot_simulation.h"
#include "pipeline/batch/strand_cache.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <mutex>
#include <optional>

namespace hp {

std::vector<FramingSample> sampleHeadForFraming(const HeadMotion& head, const std::vector<uint8_t>& scalp,
                                                float reach, const std::vector<int>& frames, double fps) {
    std::vector<FramingSample> samples;
    samples.reserve(frames.size());
    std::vector<uint32_t> scalpVertices;
    for (int frame : frames) {
        const HeadPose pose = head.sample(frame / fps);
        if (samples.empty() && reach > 0.f) {
            std::vector<uint8_t> used(pose.mesh.positions.size(), 0);
            for (size_t t = 0; t < scalp.size() && t < pose.mesh.triangles.size(); ++t)
                if (scalp[t])
                    for (uint32_t v : pose.mesh.triangles[t]) used[v] = 1;
            for (uint32_t v = 0; v < used.size(); ++v)
                if (used[v]) scalpVertices.push_back(v);
        }
        FramingSample s;
        s.frame = frame;
        s.head = pose.transform;
        s.spheres.reserve(pose.mesh.positions.size() + scalpVertices.size());
        for (const Vec3f& p : pose.mesh.positions) s.spheres.push_back({p, 0.f});
        for (uint32_t v : scalpVertices) s.spheres.push_back({pose.mesh.positions[v], reach});
        samples.push_back(std::move(s));
    }
    return samples;
}

float hairReach(const Scene& scene) {
    if (!sceneHasHair(scene)) return 0.f;
    const double length = scene.number(usesCurlyWetModel(scene) ? "hair.curly.length" : "hair.guides.length");
    return float(1.1 * length + scene.number("hair.guides.collision_radius"));
}

namespace {

/// render.camera.mode, or without the key: fixed when a position is given, else auto.
std::string cameraMode(const Scene& scene) {
    if (!scene.given("render.camera.mode") && scene.given("render.camera.position")) return "fixed";
    return scene.text("render.camera.mode");
}

}  // namespace

FramingSettings framingSettings(const Scene& scene) {
    FramingSettings f;
    readKeys(scene, f, {
        {"render.camera.facing", &FramingSettings::facing},
        {"render.camera.up", &FramingSettings::up},
        {"render.camera.azimuth", &FramingSettings::azimuthDegrees},
        {"render.camera.elevation", &FramingSettings::elevationDegrees},
        {"render.camera.margin", &FramingSettings::margin},
        {"simulation.cut_distance", &FramingSettings::cutDistance},
        {"simulation.cut_angle", &FramingSettings::cutAngleDegrees},
    });
    if (f.facing.norm() < 1e-6f) scene.fail("render.camera.facing", "must be a non-zero direction");
    if (f.up.norm() < 1e-6f) scene.fail("render.camera.up", "must be a non-zero direction");
    return f;
}

namespace {

/// render.camera.hair, or without the key: cache, unless the scene writes no
/// strand cache (cache.enabled false), where the default falls back to reach
/// rather than making a scene that gives neither key fail.
std::string cameraHair(const Scene& scene) {
    if (!scene.given("render.camera.hair") && !scene.flag("cache.enabled")) return "reach";
    return scene.text("render.camera.hair");
}

}  // namespace

bool cameraReadsStrandCache(const Scene& scene) {
    return sceneHasHair(scene) && cameraHair(scene) == "cache" && cameraMode(scene) != "fixed";
}

void checkCameraKeys(const Scene& scene) {
    const std::string mode = cameraMode(scene);
    if (mode == "fixed") return;
    for (const char* key : {"render.camera.position", "render.camera.target"})
        if (scene.given(key))
            scene.fail(key, "is not used by render.camera.mode: " + mode +
                                " (the camera frames the head); remove it, or set render.camera.mode: fixed");
    if (cameraHair(scene) == "cache" && sceneHasHair(scene) && !scene.flag("cache.enabled"))
        scene.fail("render.camera.hair", "cache reads the strand cache, but cache.enabled is false");
    framingSettings(scene);
}

namespace {

/// Adds to `sample` the cached hair's extreme points along the four fit
/// normals of its view (render/view/camera_framing.h): the only strand points
/// that can touch the frame's border.
void addCachedHair(FramingSample& sample, const StrandFrame& hair, const std::array<Vec3f, 4>& normals) {
    if (hair.positions.empty()) return;
    float radius = 0.f;
    for (float r : hair.radii) radius = std::max(radius, r);
    for (const Vec3f& m : normals) {
        const auto best = std::max_element(hair.positions.begin(), hair.positions.end(),
                                           [&](const Vec3f& a, const Vec3f& b) { return a.dot(m) < b.dot(m); });
        sample.spheres.push_back({*best, radius});
    }
}

}  // namespace

namespace {

/// For each sample, the index of its segment's first sample: a segment ends
/// where the shot cuts, found as the simulation finds its cuts (per
/// simulation step, simulation.cut_distance / cut_angle), so the camera
/// re-frames on the frame where the hair restarts.
std::vector<size_t> clipSegmentStarts(const Scene& scene, const HeadSetup& head,
                                      const std::vector<FramingSample>& samples, double fps) {
    std::vector<size_t> starts(samples.size(), 0);
    if (samples.empty()) return starts;
    const double step = frameAlignedStep(fps, scene.number("simulation.time_step"));
    const std::vector<ClipCut> cuts =
        findClipCuts(scene, head, samples.front().frame / fps, samples.back().frame / fps, step);
    size_t c = 0;
    for (size_t i = 1; i < samples.size(); ++i) {
        const double before = samples[i - 1].frame / fps, now = samples[i].frame / fps + 1e-9;
        bool cut = false;
        for (; c < cuts.size() && cuts[c].time <= now; ++c) cut |= cuts[c].time > before;
        starts[i] = cut ? i : starts[i - 1];
    }
    return starts;
}

CameraTrack computeCameraTrack(const Scene& scene, const Camera& lens, const std::filesystem::path& outputDir,
                               bool allowCache) {
    const std::string mode = cameraMode(scene);
    if (mode == "fixed") return CameraTrack(lens);
    FramingSettings settings = framingSettings(scene);
    settings.follow = mode == "follow";
    if (!sceneHasHead(scene)) {
        logVerbose("camera ", mode, ": the scene has no head to frame; using the fixed camera");
        return CameraTrack(lens);
    }
    const auto start = std::chrono::steady_clock::now();
    const HeadSetup head = loadHead(scene);
    // The framing only needs posed meshes: no collider per sample.
    HeadAnimationSettings animation = head.motion->settings();
    animation.collider = ColliderMethod::None;
    AnimatedHead posed(head.rig, animation);
    if (!head.scalp.empty()) posed.setFitTriangles(head.scalp);
    // The whole clip (the scene's frames, not this run's), so every run and
    // every chunk of one frames the shot alike.
    const std::vector<int>& frames = scene.frames("frames");
    const bool cached = allowCache && cameraReadsStrandCache(scene);
    std::vector<FramingSample> samples =
        sampleHeadForFraming(posed, head.scalp, cached ? 0.f : hairReach(scene), frames, scene.number("fps"));
    // Segments between the shot's cuts: the simulation's own test (pipeline/head/clip_cuts.h).
    const std::vector<size_t> starts = clipSegmentStarts(scene, head, samples, scene.number("fps"));
    if (cached) {
        const std::vector<Vec3f> directions = viewDirections(samples, starts, settings);
        ShotSettings shot;
        shot.outputDir = outputDir;
        for (const FramingSample& sample : samples) {  // fail before reading anything
            const std::filesystem::path file = cachePath(scene, shot, "cache.strands", sample.frame);
            std::error_code ec;
            if (!std::filesystem::is_regular_file(file, ec))
                throw FrameError(cat("camera ", mode, " frames the cached hair of the whole clip (render.camera.hair: "
                                     "cache), but frame ", sample.frame, "'s strand cache ", file.string(),
                                     " is missing: simulate the clip first (`hairpipe run` does), or set "
                                     "render.camera.hair: reach"));
        }
        // Frames are independent: read them in parallel (each sample is written by one task).
        tbb::parallel_for(size_t(0), samples.size(), [&](size_t i) {
            addCachedHair(samples[i], readStrandCache(cachePath(scene, shot, "cache.strands", samples[i].frame)),
                          framingNormals(lens, directions[i], settings.up, settings.margin));
        });
    }
    const std::vector<Camera> cameras = frameSamples(samples, starts, lens, settings);
    std::map<int, Camera> perFrame;
    for (size_t i = 0; i < samples.size(); ++i) {
        perFrame.emplace(samples[i].frame, cameras[i]);
        if (i > 0 && starts[i] == i) logVerbose("camera ", mode, ": cut before frame ", samples[i].frame, ", framed anew");
    }
    const Camera& first = cameras.front();
    logVerbose("camera ", mode, " (hair ", cached ? "from the strand cache" : "bounded by its reach", "): ",
               frames.size(), " frames; frame ", frames.front(), " from (", first.position.x(), ", ",
               first.position.y(), ", ", first.position.z(), ") toward (", first.target.x(), ", ", first.target.y(),
               ", ", first.target.z(), "), framed in ",
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), " s");
    return CameraTrack(std::move(perFrame), lens);
}

}  // namespace

CameraTrack makeCameraTrack(const Scene& scene, const Camera& lens, const std::filesystem::path& outputDir,
                            bool allowCache) {
    checkCameraKeys(scene);
    // The preview and reference stages of one process ask for the same track;
    // framing the cached hair reads every clip frame, so the last track is
    // kept, keyed by everything it depends on (a pure function of these).
    static std::mutex mutex;
    static std::string lastKey;
    static std::optional<CameraTrack> last;
    const std::string key = cat(scene.dump(), "\n", outputDir.string(), "\n", allowCache, " ", lens.fovY, " ",
                                lens.width, " ", lens.height, " ", lens.nearClip, " ", lens.farClip);
    const std::lock_guard<std::mutex> lock(mutex);
    if (!last || key != lastKey) {
        last = computeCameraTrack(scene, lens, outputDir, allowCache);
        lastKey = key;
    }
    return *last;
}

}  // namespace hp
