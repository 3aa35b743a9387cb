// The "compare" stage: compares two of the shot's sequences (compare.a and
// compare.b, by default the preview against the reference) frame by frame,
// and at the end of the run writes the tables and the HTML report for all
// the run's frames and fails the run when a frame exceeds a threshold.
#include "core/log.h"
#include "pipeline/compare_job.h"
#include "pipeline/path_template.h"
#include "pipeline/scene.h"
#include "pipeline/stages.h"
#include "pipeline/view_settings.h"

namespace fs = std::filesystem;

namespace hp {

CompareJob compareJobFromScene(const Scene& scene, const fs::path& outputDir) {
    CompareJob job;
    for (const char* key : {"compare.a", "compare.b"})
        if (!hasFrameToken(scene.text(key)))
            scene.fail(key, "'" + scene.text(key) + "' has no frame number (use #### or %04d)");
    // A relative path is under the output folder; an absolute one replaces it.
    job.a = (outputDir / scene.text("compare.a")).lexically_normal().string();
    job.b = (outputDir / scene.text("compare.b")).lexically_normal().string();
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
    return job;
}

namespace {

class CompareStage final : public FrameStage {
  public:
    explicit CompareStage(CompareJob job) : job_(std::move(job)) {}

    std::string name() const override { return "compare"; }
    std::vector<fs::path> outputs(int frame) const override { return frameOutputs(job_, frame); }
    bool needsFrameData() const override { return false; }

    void run(const FrameData& data) override {
        const FrameRecord r = compareFrame(job_, data.frame);
        // Thresholds are judged in finish() over all frames (also those a
        // resumed run skips); a warning here gives early notice.
        for (const std::string& f : checkThresholds(r.metrics, job_.thresholds))
            logWarning("frame ", data.frame, " compare: ", f);
    }

    void finish(const ShotSettings& shot) override {
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
};

}  // namespace

StagePtr makeCompareStage(const Scene& scene, const ShotSettings& shot) {
    CompareJob job = compareJobFromScene(scene, shot.outputDir);  // validates even when disabled
    if (!scene.flag("compare.enabled")) return nullptr;
    return std::make_unique<CompareStage>(std::move(job));
}

}  // namespace hp
