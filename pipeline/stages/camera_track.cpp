#include "pipeline/stages/camera_track.h"
#include "pipeline/scene/key_fields.h"

#include "core/log.h"
#include "pipeline/head/clip_cuts.h"
#include "pipeline/scene/curly_settings.h"
#include "pipeline/stages/hair_source.h"
#include "pipeline/head/head_setup.h"
#include "pipeline/stages/shot_simulation.h"
#include "pipeline/batch/strand_cache.h"
#include "pipeline/stages/cached_strands.h"


#include <algorithm>
#include <chrono>
#include <mutex>
#include <optional>
#include <set>
#include <utility>

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

/// The head sampled over the whole clip (the scene's frames, not a run's),
/// cut into segments, so every run and every chunk of one frames the shot alike.
struct HeadFraming {
    std::vector<FramingSample> samples;
    std::vector<size_t> starts;  ///< clipSegmentStarts
};

HeadFraming frameHead(const Scene& scene, bool hairFromCache) {
    const HeadSetup head = loadHead(scene);
    // The framing only needs posed meshes: no collider per sample.
    HeadAnimationSettings animation = head.motion->settings();
    animation.collider = ColliderMethod::None;
    AnimatedHead posed(head.rig, animation);
    if (!head.scalp.empty()) posed.setFitTriangles(head.scalp);
    HeadFraming h;
    h.samples = sampleHeadForFraming(posed, head.scalp, hairFromCache ? 0.f : hairReach(scene), scene.frames("frames"),
                                     scene.number("fps"));
    // Segments between the shot's cuts: the simulation's own test (pipeline/head/clip_cuts.h).
    h.starts = clipSegmentStarts(scene, head, h.samples, scene.number("fps"));
    return h;
}

/// The samples [begin, end) of the segment holding sample i.
std::pair<size_t, size_t> segmentOf(const std::vector<size_t>& starts, size_t i) {
    size_t end = i + 1;
    while (end < starts.size() && starts[end] == starts[i]) ++end;
    return {starts[i], end};
}

}  // namespace

/// Camera auto/follow: the head's samples over the clip, and the cameras
/// framed so far (shared by the copies of a track; at() may run on any thread).
class CameraFraming {
  public:
    CameraFraming(const Scene& scene, const Camera& lens, const std::filesystem::path& outputDir, bool cached)
        : scene_(scene), mode_(cameraMode(scene)), lens_(lens), cached_(cached) {
        settings_ = framingSettings(scene);
        settings_.follow = mode_ == "follow";
        head_ = frameHead(scene, cached);
        for (size_t i = 0; i < head_.samples.size(); ++i) {
            index_.emplace(head_.samples[i].frame, i);
            if (i > 0 && head_.starts[i] == i)
                logVerbose("camera ", mode_, ": cut before frame ", head_.samples[i].frame, ", framed anew");
        }
        directions_ = viewDirections(head_.samples, head_.starts, settings_);
        shot_.outputDir = outputDir;
        shot_.fps = scene.number("fps");
        for (const FramingSample& sample : head_.samples)
            files_.push_back(cachePath(scene, shot_, "cache.strands", sample.frame));
        if (!cached_) {  // the hair bounded by its reach: every camera now, from the head alone
            const std::vector<Camera> cameras = frameSamples(head_.samples, head_.starts, lens_, settings_);
            for (size_t i = 0; i < cameras.size(); ++i) cameras_.emplace(head_.samples[i].frame, cameras[i]);
        }
    }

    const Camera* at(int frame, const StrandFrame* hair) const {
        const auto it = index_.find(frame);
        if (it == index_.end()) return nullptr;
        const std::lock_guard<std::mutex> lock(mutex_);
        const auto done = cameras_.find(frame);
        if (done != cameras_.end()) return &done->second;
        frameWithCachedHair(it->second, hair && hair->frame == frame ? hair : nullptr);
        return &cameras_.at(frame);
    }

    std::vector<int> cacheFramesFor(int frame) const {
        const auto it = index_.find(frame);
        if (!cached_ || it == index_.end()) return {};
        if (settings_.follow) return {frame};
        std::vector<int> frames;
        const auto [begin, end] = segmentOf(head_.starts, it->second);
        for (size_t i = begin; i < end; ++i) frames.push_back(head_.samples[i].frame);
        return frames;
    }

  private:
    /// Frames sample i (follow: alone; auto: its whole segment) with the
    /// cached hair's extreme points added to the head's spheres. The same
    /// spheres in the same order as a whole-clip framing, so the same bits.
    void frameWithCachedHair(size_t i, const StrandFrame* hair) const {
        const auto [begin, end] = settings_.follow ? std::pair<size_t, size_t>{i, i + 1} : segmentOf(head_.starts, i);
        const bool given = settings_.follow && hair;  // the frame's own strands, from the caller
        for (size_t k = begin; k < end && !given; ++k) {  // fail before reading anything
            std::error_code ec;
            if (!std::filesystem::is_regular_file(files_[k], ec))
                throw FrameError(cat("camera ", mode_, " frames the cached hair (render.camera.hair: cache), but frame ",
                                     head_.samples[k].frame, "'s strand cache ", files_[k].string(),
                                     " is missing: simulate that frame first (`hairpipe run` does), or set "
                                     "render.camera.hair: reach"));
        }
        const auto start = std::chrono::steady_clock::now();
        std::vector<FramingSample> samples(head_.samples.begin() + long(begin), head_.samples.begin() + long(end));
        // In order: a version 2 cache rebuilds each frame's followers on the
        // frame before's (cached_strands.h), once per frame.
        for (size_t k = 0; k < samples.size(); ++k) {
            if (!reader_) reader_ = std::make_unique<CachedStrands>(scene_, shot_);
            addCachedHair(samples[k], given ? *hair : reader_->read(files_[begin + k]),
                          framingNormals(lens_, directions_[begin + k], settings_.up, settings_.margin));
        }
        // As frameSamples frames the clip (render/view/camera_framing.cpp):
        // follow, each sample alone from its segment's direction; auto, the
        // segment's spheres in sample order, from its first sample's direction.
        if (settings_.follow) {
            cameras_.emplace(samples[0].frame,
                             fitCamera(lens_, directions_[i], settings_.up, settings_.margin, samples[0].spheres));
        } else {
            std::vector<FramingSphere> all;
            for (const FramingSample& sample : samples) all.insert(all.end(), sample.spheres.begin(), sample.spheres.end());
            const Camera c = fitCamera(lens_, directions_[begin], settings_.up, settings_.margin, all);
            for (const FramingSample& sample : samples) cameras_.emplace(sample.frame, c);
        }
        const Camera& c = cameras_.at(head_.samples[i].frame);
        logVerbose("camera ", mode_, " (hair from the strand cache of frame", samples.size() > 1 ? "s " : " ",
                   samples.front().frame, samples.size() > 1 ? cat("-", samples.back().frame) : std::string(),
                   "): frame ", head_.samples[i].frame, " from (", c.position.x(), ", ", c.position.y(), ", ",
                   c.position.z(), ") toward (", c.target.x(), ", ", c.target.y(), ", ", c.target.z(), "), framed in ",
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), " s");
    }

    Scene scene_;  ///< a copy, for reader_
    ShotSettings shot_;
    std::string mode_;
    Camera lens_;
    bool cached_;
    FramingSettings settings_;
    HeadFraming head_;
    std::vector<Vec3f> directions_;
    std::vector<std::filesystem::path> files_;  ///< per sample, its strand cache
    std::map<int, size_t> index_;               ///< frame -> sample
    mutable std::mutex mutex_;
    mutable std::map<int, Camera> cameras_;     ///< framed so far (references stay valid)
    mutable std::unique_ptr<CachedStrands> reader_;  ///< the cached hair, made on first use
};

const Camera& CameraTrack::at(int frame, const StrandFrame* hair) const {
    if (!framing_) return fallback_;
    const Camera* c = framing_->at(frame, hair);
    return c ? *c : fallback_;
}

std::vector<int> CameraTrack::cacheFramesFor(int frame) const {
    return framing_ ? framing_->cacheFramesFor(frame) : std::vector<int>{};
}

std::vector<int> cameraCacheFrames(const Scene& scene, const std::vector<int>& frames) {
    if (!cameraReadsStrandCache(scene) || frames.empty()) return {};
    std::set<int> clip(scene.frames("frames").begin(), scene.frames("frames").end()), out;
    if (cameraMode(scene) == "follow") {
        for (int f : frames)
            if (clip.count(f)) out.insert(f);
    } else {
        const HeadFraming head = frameHead(scene, true);
        std::set<int> asked(frames.begin(), frames.end());
        for (size_t i = 0; i < head.samples.size(); ++i) {
            if (!asked.count(head.samples[i].frame)) continue;
            const auto [begin, end] = segmentOf(head.starts, i);
            for (size_t k = begin; k < end; ++k) out.insert(head.samples[k].frame);
        }
    }
    return {out.begin(), out.end()};
}

namespace {

CameraTrack computeCameraTrack(const Scene& scene, const Camera& lens, const std::filesystem::path& outputDir,
                               bool allowCache) {
    const std::string mode = cameraMode(scene);
    if (mode == "fixed") return CameraTrack(lens);
    framingSettings(scene);  // checks the keys
    if (!sceneHasHead(scene)) {
        logVerbose("camera ", mode, ": the scene has no head to frame; using the fixed camera");
        return CameraTrack(lens);
    }
    const auto start = std::chrono::steady_clock::now();
    const bool cached = allowCache && cameraReadsStrandCache(scene);
    auto framing = std::make_shared<const CameraFraming>(scene, lens, outputDir, cached);
    logVerbose("camera ", mode, " (hair ", cached ? "from the strand cache, read per frame on first use" : "bounded by its reach",
               "): ", scene.frames("frames").size(), " clip frames, head sampled in ",
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), " s");
    return CameraTrack(std::move(framing), lens);
}

}  // namespace

CameraTrack makeCameraTrack(const Scene& scene, const Camera& lens, const std::filesystem::path& outputDir,
                            bool allowCache) {
    checkCameraKeys(scene);
    // The preview and reference stages of one process ask for the same track;
    // it samples the head over the clip and reads the cached hair of the
    // frames asked, so the last track is kept (its copies share the cameras
    // framed so far), keyed by everything it depends on.
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
