// The "compare" stage: compares two of the shot's sequences (compare.a and
// compare.b, by default the preview against the reference) frame by frame,
// and at the end of the run writes the tables and the HTML report for all
// the run's frames and fails the run when a frame exceeds a threshold. A
// second, diagnostic pair (compare.diagnostic: by default the Kajiya-Kay
// reference, "same model, other visibility") is measured and reported beside
// it in compare.output/diagnostic/ and never fails the run.
#include "core/log.h"
#include "pipeline/compare/compare_job.h"
#include "pipeline/batch/path_template.h"
#include "pipeline/scene/scene.h"
#include "pipeline/stages/stages.h"
#include "pipeline/scene/view_settings.h"

namespace fs = std::filesystem;

namespace hp {

namespace {

/// A template as the compare job sees it: a relative path is under the
/// output folder, an absolute one replaces it.
std::string resolved(const fs::path& outputDir, const std::string& t) {
    return (outputDir / t).lexically_normal().string();
}

/// What the sequence `key` names is, from the scene: the preview, the
/// reference (renderer, shading, samples) or its Kajiya-Kay companion;
/// otherwise the template itself. compare.<x>_label overrides it.
std::string sequenceLabel(const Scene& scene, const fs::path& outputDir, const std::string& key) {
    if (!scene.text(key + "_label").empty()) return scene.text(key + "_label");
    const std::string path = resolved(outputDir, scene.text(key));
    auto is = [&](const char* other) {
        return !scene.text(other).empty() && resolved(outputDir, scene.text(other)) == path;
    };
    const std::string spp = cat(scene.integer("reference.samples"), " spp");
    if (is("preview.exr") || is("preview.png")) return "preview (OpenGL)";
    if (is("reference.exr") || is("reference.png"))
        return cat("reference (Embree, ", scene.text("reference.mode"), ", ", spp, ")");
    if (scene.flag("reference.kajiya_kay.enabled") && (is("reference.kajiya_kay.exr") || is("reference.kajiya_kay.png"))) {
        const long own = scene.integer("reference.kajiya_kay.samples");  // 0: sampled as the physical reference
        return cat("reference (Embree, kajiya-kay, ", own > 0 ? cat(own, " spp") : spp, ")");
    }
    return scene.text(key);
}

}  // namespace

CompareJob compareJobFromScene(const Scene& scene, const fs::path& outputDir) {
    CompareJob job;
    for (const char* key : {"compare.a", "compare.b"})
        if (!hasFrameToken(scene.text(key)))
            scene.fail(key, "'" + scene.text(key) + "' has no frame number (use #### or %04d)");
    if (!scene.text("compare.beside").empty() && !hasFrameToken(scene.text("compare.beside")))
        scene.fail("compare.beside", "'" + scene.text("compare.beside") + "' has no frame number (use #### or %04d)");
    job.a = resolved(outputDir, scene.text("compare.a"));
    job.b = resolved(outputDir, scene.text("compare.b"));
    job.aLabel = sequenceLabel(scene, outputDir, "compare.a");
    job.bLabel = sequenceLabel(scene, outputDir, "compare.b");
    if (!scene.text("compare.beside").empty()) {
        job.beside = resolved(outputDir, scene.text("compare.beside"));
        job.besideLabel = sequenceLabel(scene, outputDir, "compare.beside");
    }
    job.outputDir = (outputDir / scene.text("compare.output")).lexically_normal();
    const std::string& report = scene.text("compare.report");
    if (!report.empty()) job.report = (outputDir / report).lexically_normal();
    job.settings.mask = scene.text("compare.mask") == "hair" ? MaskMode::Hair : MaskMode::None;
    job.settings.flip.pixelsPerDegree = scene.number("compare.pixels_per_degree");
    job.thresholds.maxFlip = scene.number("compare.max_flip");
    job.thresholds.minPsnr = scene.number("compare.min_psnr");
    job.thresholds.minSsim = scene.number("compare.min_ssim");
    job.thresholds.maxRmse = scene.number("compare.max_rmse");
    job.reportWidth = int(scene.integer("compare.report_width"));
    job.display = makeDisplaySettings(scene);
    job.pair = cat("gate: ", job.aLabel, " against ", job.bLabel,
                   " (the thresholds apply to this pair)");
    return job;
}

std::optional<CompareJob> diagnosticJobFromScene(const Scene& scene, const fs::path& outputDir) {
    const std::string& t = scene.text("compare.diagnostic");
    if (t.empty()) return std::nullopt;
    if (!hasFrameToken(t)) scene.fail("compare.diagnostic", "'" + t + "' has no frame number (use #### or %04d)");
    CompareJob job = compareJobFromScene(scene, outputDir);
    if (resolved(outputDir, t) == job.b)
        scene.fail("compare.diagnostic", "is the gate's own sequence compare.b; name another one or leave it empty");
    job.b = resolved(outputDir, t);
    job.bLabel = sequenceLabel(scene, outputDir, "compare.diagnostic");
    job.beside.clear();
    job.besideLabel.clear();
    job.thresholds = CompareThresholds{};
    job.outputDir = job.outputDir / "diagnostic";
    if (!job.report.empty()) job.report = job.report.parent_path() / "diagnostic.html";
    job.pair = cat("diagnostic, ", scene.text("compare.diagnostic_pair"), ": ", job.aLabel, " against ", job.bLabel,
                   " (no thresholds; the gate is ", scene.text("compare.b"), ")");
    return job;
}

namespace {

class CompareStage final : public FrameStage {
  public:
    CompareStage(CompareJob job, std::optional<CompareJob> diagnostic)
        : job_(std::move(job)), diagnostic_(std::move(diagnostic)) {}

    std::string name() const override { return "compare"; }
    std::vector<fs::path> outputs(int frame) const override {
        std::vector<fs::path> out = frameOutputs(job_, frame);
        if (diagnostic_)
            for (fs::path& p : frameOutputs(*diagnostic_, frame)) out.push_back(std::move(p));
        return out;
    }
    bool needsFrameData() const override { return false; }
    /// Reads the frame's preview and reference files, written before it on the main lane.
    bool overlaps() const override { return true; }

    void run(const FrameData& data) override {
        const FrameRecord r = compareFrame(job_, data.frame);
        // Thresholds are judged in finish() over all frames (also those a
        // resumed run skips); a warning here gives early notice.
        for (const std::string& f : checkThresholds(r.metrics, job_.thresholds))
            logWarning("frame ", data.frame, " compare: ", f);
        if (diagnostic_) compareFrame(*diagnostic_, data.frame);
    }

    void finish(const ShotSettings& shot) override {
        if (diagnostic_) {
            std::vector<FrameRecord> diagnostic;
            for (int frame : shot.frames) diagnostic.push_back(loadFrameRecord(*diagnostic_, frame));
            finishCompare(*diagnostic_, diagnostic);
        }
        std::vector<FrameRecord> records;
        for (int frame : shot.frames) records.push_back(loadFrameRecord(job_, frame));
        finishCompare(job_, records);
        // Frames that could not be compared already failed in run(); list the threshold failures.
        std::string lines;
        int failed = 0;
        for (const FrameRecord& r : records) {
            if (r.failures.empty()) continue;
            ++failed;
            lines += cat("\n  frame ", r.frame, ":");
            for (size_t k = 0; k < r.failures.size(); ++k) lines += (k ? ", " : " ") + r.failures[k];
        }
        if (failed)
            throw FrameError(cat(failed, " of ", records.size(), " frames fail the comparison thresholds (report: ",
                                 job_.report.empty() ? (job_.outputDir / "metrics.csv").string() : job_.report.string(),
                                 "):", lines));
    }

  private:
    CompareJob job_;
    std::optional<CompareJob> diagnostic_;
};

}  // namespace

StagePtr makeCompareStage(const Scene& scene, const ShotSettings& shot) {
    CompareJob job = compareJobFromScene(scene, shot.outputDir);  // validates even when disabled
    std::optional<CompareJob> diagnostic = diagnosticJobFromScene(scene, shot.outputDir);
    if (!scene.flag("compare.enabled")) return nullptr;
    return std::make_unique<CompareStage>(std::move(job), std::move(diagnostic));
}

}  // namespace hp
