// `hairpipe compare A B`: compares two image sequences frame by frame, writes
// difference images, tables and an HTML report, and exits 2 when a frame is
// missing or unreadable or fails a threshold — a regression gate for CI.
#include "core/log.h"
#include "pipeline/cli/commands.h"
#include "pipeline/compare/compare_job.h"
#include "pipeline/batch/frame_range.h"
#include "pipeline/batch/path_template.h"
#include "pipeline/batch/progress.h"

#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>

namespace fs = std::filesystem;

namespace hp {

namespace {

double numberOption(const CommandLine& cl, const std::string& option, double lo, double hi) {
    const std::string text = cl.value(option);
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !std::isfinite(v) || v < lo || v > hi)
        throw UsageError(cat("option ", option, " expects a number in [", lo, ", ", hi, "], got '", text, "'"));
    return v;
}

std::string absoluteTemplate(const std::string& pattern, const char* which) {
    if (!hasFrameToken(pattern))
        throw UsageError(cat("hairpipe compare: ", which, " '", pattern,
                             "' has no frame number; use a template such as render.####.exr or render.%04d.exr"));
    return fs::absolute(pattern).lexically_normal().string();
}

std::string cell(double v) {
    char buf[32];
    if (std::isinf(v)) return "inf";
    std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
}

void printTable(const std::vector<FrameRecord>& records) {
    std::printf("%7s %9s %9s %9s %9s  %s\n", "frame", "FLIP", "SSIM", "PSNR", "RMSE", "result");
    for (const FrameRecord& r : records) {
        if (!r.compared) {
            std::printf("%7d %9s %9s %9s %9s  error: %s\n", r.frame, "-", "-", "-", "-", r.error.c_str());
            continue;
        }
        std::string result = r.failures.empty() ? "pass" : "FAIL";
        for (size_t k = 0; k < r.failures.size(); ++k) result += (k ? ", " : ": ") + r.failures[k];
        std::printf("%7d %9s %9s %9s %9s  %s\n", r.frame, cell(r.metrics.flip).c_str(), cell(r.metrics.ssim).c_str(),
                    cell(r.metrics.psnr).c_str(), cell(r.metrics.rmse).c_str(), result.c_str());
    }
    std::fflush(stdout);
}

int runCompare(const CommandLine& cl) {
    std::unique_ptr<tbb::global_control> threads;
    if (cl.has("--threads")) {
        const double n = numberOption(cl, "--threads", 1, 1024);
        if (n != std::floor(n)) throw UsageError("option --threads expects an integer, got '" + cl.value("--threads") + "'");
        threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(n));
    }
    CompareJob job;
    std::vector<int> frames;
    if (cl.has("--scene")) {
        // The scene supplies defaults: its compare.* keys, output folder and frames.
        const Scene scene = Scene::load(cl.value("--scene"));
        const ShotSettings shot = resolveShot(scene, RunOptions{});
        job = compareJobFromScene(scene, shot.outputDir);
        frames = shot.frames;
    } else {
        job.outputDir = "compare";
    }
    if (cl.positional.size() == 2) {
        job.a = cl.positional[0];
        job.b = cl.positional[1];
    } else if (!(cl.positional.empty() && cl.has("--scene"))) {
        throw UsageError("hairpipe compare: expected two image sequences A and B (see --help)");
    }
    job.a = absoluteTemplate(job.a, "A");
    job.b = absoluteTemplate(job.b, "B");
    if (cl.has("--out") || !cl.has("--scene")) {
        if (cl.has("--out")) job.outputDir = cl.value("--out");
        job.outputDir = fs::absolute(job.outputDir).lexically_normal();
        job.report = job.outputDir / "report.html";
    }
    if (cl.has("--report")) job.report = cl.value("--report") == "none" ? fs::path() : fs::absolute(cl.value("--report"));
    if (cl.has("--mask")) {
        const std::string m = cl.value("--mask");
        if (m != "hair" && m != "none") throw UsageError("option --mask expects hair or none, got '" + m + "'");
        job.settings.mask = m == "hair" ? MaskMode::Hair : MaskMode::None;
    }
    if (cl.has("--ppd")) job.settings.flip.pixelsPerDegree = numberOption(cl, "--ppd", 1, 1000);
    if (cl.has("--max-flip")) job.thresholds.maxFlip = numberOption(cl, "--max-flip", 0, 1);
    if (cl.has("--min-psnr")) job.thresholds.minPsnr = numberOption(cl, "--min-psnr", 0, 1000);
    if (cl.has("--min-ssim")) job.thresholds.minSsim = numberOption(cl, "--min-ssim", -1, 1);
    if (cl.has("--max-rmse")) job.thresholds.maxRmse = numberOption(cl, "--max-rmse", 0, 1);
    if (cl.has("--report-width")) job.reportWidth = int(numberOption(cl, "--report-width", 16, 8192));

    if (cl.has("--frames")) frames = parseFrameRange(cl.value("--frames"));
    else if (!cl.has("--scene")) frames = framesInBoth(job.a, job.b);
    if (frames.empty())
        throw UsageError(cat("hairpipe compare: no frames to compare: no frame number has a file in both\n  A ",
                             job.a, "\n  B ", job.b, "\n(check the templates, or name the frames with --frames)"));

    logInfo("hairpipe compare: frames ", formatFrameRange(frames), " -> ", job.outputDir.string());
    std::vector<FrameRecord> records;
    Progress progress("frames", frames.size());
    for (int frame : frames) {
        try {
            records.push_back(compareFrame(job, frame));
        } catch (const Error& e) {
            // A missing or mismatched frame fails that frame; the others still run.
            FrameRecord r;
            r.frame = frame;
            r.a = expandFrame(job.a, frame);
            r.b = expandFrame(job.b, frame);
            r.error = e.what();
            logError("frame ", frame, ": ", e.what());
            records.push_back(r);
        }
        progress.advance(cat("frame ", frame));
    }
    const std::vector<std::string> failures = finishCompare(job, records);
    printTable(records);
    if (failures.empty()) {
        logInfo("hairpipe compare: all ", records.size(), " frames pass");
        return kExitOk;
    }
    logError("hairpipe compare: ", failures.size(), " of ", records.size(), " frames FAIL:");
    for (const std::string& f : failures) logError(f);
    return kExitFrameFailed;
}

}  // namespace

CommandSpec compareCommandSpec() {
    CommandSpec c{"compare", "[options] A B   (or: --scene scene.yaml [A B])",
                  "compare two image sequences: FLIP, SSIM, PSNR, RMSE, difference images, HTML report"};
    c.details =
        "A and B are frame templates (render.####.exr or render.%04d.exr), e.g. the preview\n"
        "against the Embree reference, another renderer, or yesterday's output; any\n"
        "format OpenImageIO reads (8-bit files are linearised). Without --frames, the\n"
        "frames that have a file in both sequences are compared.\n\n"
        "Writes to --out: flip.####.png (FLIP error heat map), absdiff.####.exr (|A-B|),\n"
        "metrics.####.json, metrics.csv, metrics.json and report.html (self-contained).\n\n"
        "Exit codes: 0 every frame compared and passed; 1 usage error (bad option, no\n"
        "frames found); 2 some frame failed a threshold, or was missing, unreadable or of\n"
        "another resolution (those frames are listed; the others are still compared).\n"
        "With --scene, the scene's compare.* keys give the defaults (templates relative\n"
        "to its output folder, thresholds, mask) and its frames are compared.";
    c.sceneOptions = false;
    c.options = {
        {"--frames", "RANGE", "frames to compare: 5, 1-120, 1-120x2, 3,7,10-20 (default: those in both)"},
        {"--out", "DIR", "folder for difference images and tables (default: ./compare)"},
        {"--report", "PATH", "HTML report (default: DIR/report.html; 'none' for no report)"},
        {"--max-flip", "X", "fail a frame whose mean FLIP is above X (0..1)"},
        {"--min-psnr", "DB", "fail a frame whose PSNR is below DB"},
        {"--min-ssim", "X", "fail a frame whose SSIM is below X (-1..1)"},
        {"--max-rmse", "X", "fail a frame whose RMSE is above X (0..1)"},
        {"--mask", "hair|none", "average the metrics over pixels with alpha > 0 in A or B (default: none)"},
        {"--ppd", "N", "FLIP viewing condition, pixels per degree (default 67)"},
        {"--report-width", "PX", "width of the images in the report (default 512)"},
        {"--scene", "FILE", "take templates, thresholds, mask and frames from a scene's compare section"},
        {"--threads", "N", "worker threads (default: all cores)"},
    };
    c.run = runCompare;
    return c;
}

}  // namespace hp
