// The "reference" frame stage: renders each frame's strands and head with the
// Embree reference renderer (render/reference/reference.h) and writes EXR (+ PNG).
#include "core/log.h"
#include "pipeline/head/animated_head.h"
#include "pipeline/stages/camera_track.h"
#include "pipeline/batch/output.h"
#include "pipeline/batch/path_template.h"
#include "pipeline/stages/stages.h"
#include "pipeline/scene/view_settings.h"
#include "render/reference/adaptive_sampling.h"
#include "render/reference/reference.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <optional>

namespace fs = std::filesystem;

namespace hp {

namespace {

ReferenceSettings referenceSettings(const Scene& s, const ShotSettings& shot) {
    ReferenceSettings r;
    r.mode = s.text("reference.mode") == "physical" ? ReferenceMode::Physical : ReferenceMode::KajiyaKay;
    r.samplesPerPixel = int(s.integer("reference.samples"));
    // Adaptive unless a fixed count is given; both at once is a contradiction.
    r.noiseThreshold = float(s.number("reference.noise_threshold"));
    if (s.given("reference.samples")) {
        if (s.given("reference.noise_threshold") && r.noiseThreshold > 0.f)
            s.fail("reference.noise_threshold",
                   "asks for adaptive sampling, but reference.samples fixes the sample count: give one of them "
                   "(or noise_threshold: 0)");
        r.noiseThreshold = 0.f;
    }
    r.minSamples = int(s.integer("reference.min_samples"));
    r.maxSamples = int(s.integer("reference.max_samples"));
    if (r.noiseThreshold > 0.f) {
        for (const char* key : {"reference.min_samples", "reference.max_samples"})
            if (!isPowerOfTwo(uint32_t(s.integer(key))))
                s.fail(key, cat(s.integer(key), " is not a power of two (sample counts double from pass to pass, "
                                "which keeps the sampler's strata)"));
        if (r.maxSamples < r.minSamples)
            s.fail("reference.max_samples", cat(r.maxSamples, " is below reference.min_samples (", r.minSamples, ")"));
    }
    r.timeLimit = s.number("reference.time_limit");
    r.filter.type = s.text("reference.filter.type") == "box" ? PixelFilterType::Box : PixelFilterType::Gaussian;
    r.filter.radius = r.filter.type == PixelFilterType::Box ? 0.5f : float(s.number("reference.filter.radius"));
    r.filter.sigma = float(s.number("reference.filter.sigma"));
    r.bounces = int(s.integer("reference.depth"));
    r.bounceSplits = int(s.integer("reference.bounce_splits"));
    r.efficiencySplitting = s.text("reference.splitting") == "efficiency";
    r.sampler = s.text("reference.sampler") == "independent" ? sampling::SamplerType::Independent
                                                              : sampling::SamplerType::ZSobol;
    r.seed = s.has("reference.seed") ? uint64_t(s.integer("reference.seed")) : uint64_t(shot.seed);
    r.shadows = s.flag("reference.shadows");
    r.shadowRouletteThreshold = float(s.number("reference.shadow_roulette"));
    r.unshadowedLights = s.text("reference.physical.unshadowed_lights") == "first-hit" ? UnshadowedLights::FirstHit
                                                                                        : UnshadowedLights::Shadowed;
    r.diffuseSpecularLayers = s.flag("reference.layers.diffuse_specular");
    r.strandIdLayer = s.flag("reference.layers.strand_id");
    r.fiber = hairFiber(s);
    return r;
}

/// `value` with `digits` decimals.
std::string fixed(double value, int digits) {
    char text[64];
    std::snprintf(text, sizeof text, "%.*f", digits, value);
    return text;
}

/// "64 spp" or "spp 16..1024 (mean 212.4), 97.1% below noise 0.01".
std::string samplesText(const ReferenceSettings& s, const ReferenceStats& st) {
    if (!(s.noiseThreshold > 0.f)) return cat(s.samplesPerPixel, " spp");
    return cat("spp ", st.minSamples, "..", st.maxSamples, " (mean ", fixed(st.meanSamples, 1), "), ",
               fixed(100.0 * st.convergedFraction, 1), "% below noise ", s.noiseThreshold,
               st.timeLimitReached ? " (time limit reached)" : "");
}

std::string checkedTemplate(const Scene& s, const std::string& key, bool required) {
    const std::string& t = s.text(key);
    if (t.empty()) {
        if (required) s.fail(key, "must name the output file template");
        return t;
    }
    if (!hasFrameToken(t)) s.fail(key, "needs a frame token (#### or %04d) so frames do not overwrite each other");
    return t;
}

/// One sequence the stage writes: its shading and file templates.
struct ReferenceOutput {
    ReferenceSettings settings;
    std::string exr, png;
};

class ReferenceStage final : public FrameStage {
  public:
    ReferenceStage(const Scene& scene, const ShotSettings& shot)
        : shot_(shot), view_(makeView(scene)), scene_(scene), display_(makeDisplaySettings(scene)),
          scale_(scene.number("reference.scale")), sceneName_(scene.name()) {
        checkCameraKeys(scene);
        sequences_.push_back({referenceSettings(scene, shot), checkedTemplate(scene, "reference.exr", true),
                              checkedTemplate(scene, "reference.png", false)});
        if (scene.flag("reference.kajiya_kay.enabled")) {
            if (sequences_.front().settings.mode != ReferenceMode::Physical)
                scene.fail("reference.kajiya_kay.enabled",
                           "adds a Kajiya-Kay reference beside a physical one, but reference.mode is already "
                           "kajiya-kay");
            ReferenceOutput kk = sequences_.front();
            kk.settings.mode = ReferenceMode::KajiyaKay;
            // Its own budget: a smooth direct-light model needs far fewer
            // samples than the path-traced fibre it sits beside, and a fixed
            // count keeps it reproducible under the physical time limit.
            if (const int samples = int(scene.integer("reference.kajiya_kay.samples")); samples > 0) {
                kk.settings.samplesPerPixel = samples;
                kk.settings.noiseThreshold = 0.f;
                kk.settings.timeLimit = 0.0;
            }
            kk.exr = checkedTemplate(scene, "reference.kajiya_kay.exr", true);
            kk.png = checkedTemplate(scene, "reference.kajiya_kay.png", false);
            if (kk.exr == sequences_.front().exr)
                scene.fail("reference.kajiya_kay.exr", "must differ from reference.exr, or one overwrites the other");
            sequences_.push_back(std::move(kk));
        }
    }

    std::string name() const override { return "reference"; }
    /// Samples on every core, to a time limit counted in wall time.
    bool exclusive() const override { return true; }

    std::vector<fs::path> outputs(int frame) const override {
        std::vector<fs::path> out;
        for (const ReferenceOutput& s : sequences_) append(out, s, frame);
        return out;
    }

    void run(const FrameData& data) override {
        TriangleMesh drawn;  // the head with the visible colliders beside it
        const TriangleMesh* head =
            data.head && !data.head->mesh.triangles.empty() ? &drawnMesh(*data.head, drawn) : nullptr;
        if (!data.strands && !head)
            throw FrameError(cat("frame ", data.frame,
                                 " has neither strands nor a head to render (no hair or head stage produced them)"));
        if (!data.strands) logVerbose("reference: frame ", data.frame, " has no strands; rendering the head alone");
        View view = view_;
        view.camera = cameraAt(data.frame, data.strands);
        view.camera.width = std::max(1, int(std::lround(view.camera.width * scale_)));
        view.camera.height = std::max(1, int(std::lround(view.camera.height * scale_)));
        // One Embree scene for the physical reference and its Kajiya-Kay
        // companion: the BVH of the frame's hair is built once.
        const auto geometry = renderer_.build(data.strands, head);
        for (const ReferenceOutput& s : sequences_) render(view, s, data, *geometry);
    }

  private:
    void append(std::vector<fs::path>& out, const ReferenceOutput& s, int frame) const {
        out.push_back(shot_.outputDir / expandFrame(s.exr, frame));
        if (!s.png.empty()) out.push_back(shot_.outputDir / expandFrame(s.png, frame));
    }

    void render(const View& view, const ReferenceOutput& sequence, const FrameData& data,
                const ReferenceGeometry& geometry) {
        ReferenceSettings settings = sequence.settings;
        settings.frame = data.frame;
        int lastDecile = 0;
        settings.progress = [&](size_t done, size_t total) {
            const int decile = int(10 * done / total);
            if (decile > lastDecile) {
                lastDecile = decile;
                logVerbose("reference: frame ", data.frame, " ", 10 * decile, "%");
            }
        };
        settings.passDone = [&](int samples, double sampling) {
            if (settings.noiseThreshold > 0.f)
                logVerbose("reference: frame ", data.frame, " pass to ", samples, " spp, ", fixed(100.0 * sampling, 1),
                           "% of pixels still sampling");
        };
        ReferenceStats stats;
        const Image image = renderer_.render(view, geometry, settings, &stats);
        logVerbose("reference: frame ", data.frame, ": ", stats.strands, " strands, ", referenceModeName(settings.mode),
                   ", ", samplesText(settings, stats), ", build ", fixed(stats.buildSeconds, 2), " s (", fixed(stats.buildCpuSeconds, 1), " CPU-s), render ",
                   fixed(stats.renderSeconds, 2), " s (", fixed(stats.renderCpuSeconds, 1), " CPU-s, ",
                   fixed(double(stats.rays) / std::max(1.0, stats.meanSamples * double(image.width) * image.height), 1),
                   " rays a sample), Embree ", stats.sceneBytes / (1 << 20), " MiB");

        ImageWriteOptions options;
        options.metadata = {{"hairpipe:stage", "reference"},
                            {"hairpipe:scene", sceneName_},
                            {"hairpipe:frame", std::to_string(data.frame)},
                            {"hairpipe:seed", std::to_string(shot_.seed)},
                            {"hairpipe:mode", referenceModeName(settings.mode)},
                            {"hairpipe:samples", samplesText(settings, stats)},
                            {"hairpipe:sampler_seed", std::to_string(settings.seed)},
                            {"hairpipe:strands", std::to_string(stats.strands)}};
        std::vector<fs::path> paths;
        append(paths, sequence, data.frame);
        for (const fs::path& path : paths)
            writeAtomically(path, [&](const fs::path& tmp) { writeImageWithDisplay(tmp.string(), image, display_, options); });
    }

    ShotSettings shot_;
    View view_;
    Scene scene_;  ///< a copy: callers may pass a temporary scene
    std::optional<CameraTrack> track_;  ///< made on the first frame: it may read the strand cache

    /// The camera of `frame` (camera auto reads the clip once, on first use).
    const Camera& cameraAt(int frame, const StrandFrame* hair) {
        if (!track_) track_ = makeCameraTrack(scene_, view_.camera, shot_.outputDir);
        return track_->at(frame, hair);
    }
    DisplaySettings display_;  // PNG frames only; EXRs stay linear
    double scale_;
    std::string sceneName_;
    /// The scene's reference, then (reference.kajiya_kay.enabled) its Kajiya-Kay companion.
    std::vector<ReferenceOutput> sequences_;
    ReferenceRenderer renderer_;  // one Embree device for the whole shot
};

}  // namespace

StagePtr makeReferenceStage(const Scene& scene, const ShotSettings& shot) {
    if (!scene.flag("reference.enabled")) return nullptr;
    return std::make_unique<ReferenceStage>(scene, shot);
}

}  // namespace hp
