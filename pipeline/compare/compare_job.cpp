#include "pipeline/compare/compare_job.h"

#include "core/errors.h"
#include "core/log.h"
#include "pipeline/compare/compare_report.h"
#include "pipeline/compare/compare_table.h"
#include "pipeline/batch/output.h"
#include "pipeline/batch/path_template.h"

#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>

namespace fs = std::filesystem;

namespace hp {

namespace {

fs::path perFrame(const CompareJob& job, const char* pattern, int frame) {
    return job.outputDir / expandFrame(pattern, frame);
}

std::set<int> framesOnDisk(const std::string& pattern) {
    std::set<int> frames;
    const fs::path p(pattern);
    const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
    const std::string name = p.filename().string();
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        int frame = 0;
        if (it->is_regular_file(ec) && matchFrame(name, it->path().filename().string(), &frame)) frames.insert(frame);
    }
    return frames;
}

std::string formatValue(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
}

}  // namespace

fs::path flipImagePath(const CompareJob& job, int frame) { return perFrame(job, "flip.####.png", frame); }
fs::path diffImagePath(const CompareJob& job, int frame) { return perFrame(job, "absdiff.####.exr", frame); }
fs::path frameMetricsPath(const CompareJob& job, int frame) { return perFrame(job, "metrics.####.json", frame); }

std::vector<fs::path> frameOutputs(const CompareJob& job, int frame) {
    return {flipImagePath(job, frame), diffImagePath(job, frame), frameMetricsPath(job, frame)};
}

FrameRecord compareFrame(const CompareJob& job, int frame) {
    FrameRecord r;
    r.frame = frame;
    r.a = expandFrame(job.a, frame);
    r.b = expandFrame(job.b, frame);
    // readImage throws AssetError naming the file ("no such file", "cannot read image").
    const Image a = readImage(r.a, true);
    const Image b = readImage(r.b, true);
    if (a.width != b.width || a.height != b.height)
        throw FrameError(cat("resolutions differ: ", r.a, " is ", a.width, "x", a.height, ", ", r.b, " is ", b.width,
                             "x", b.height));
    Comparison c;
    try {
        c = compareImages(a, b, job.settings);
    } catch (const Error& e) {
        throw FrameError(cat(r.a, " vs ", r.b, ": ", e.what()));
    }
    r.width = a.width;
    r.height = a.height;
    r.metrics = c.metrics;
    r.compared = true;

    ImageWriteOptions heat;
    heat.srgbFor8Bit = false;  // the colour map is already display-encoded
    writeAtomically(flipImagePath(job, frame),
                    [&](const fs::path& tmp) { writeImage(tmp.string(), flipHeatmap(c.flipMap), heat); });
    writeAtomically(diffImagePath(job, frame), [&](const fs::path& tmp) { writeImage(tmp.string(), c.absDiff); });
    // The metrics file last: its presence marks the frame as complete.
    writeTextAtomically(frameMetricsPath(job, frame), frameRecordJson(r) + "\n");
    return r;
}

FrameRecord loadFrameRecord(const CompareJob& job, int frame) {
    const fs::path path = frameMetricsPath(job, frame);
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        FrameRecord r;
        r.frame = frame;
        r.a = expandFrame(job.a, frame);
        r.b = expandFrame(job.b, frame);
        r.error = "not compared (no " + path.filename().string() + "; see the errors above)";
        return r;
    }
    std::ostringstream text;
    text << in.rdbuf();
    return parseFrameRecord(text.str(), path.string());
}

std::vector<std::string> checkThresholds(const FrameMetrics& m, const CompareThresholds& t) {
    std::vector<std::string> out;
    if (m.flip > t.maxFlip) out.push_back("FLIP " + formatValue(m.flip) + " > " + formatValue(t.maxFlip));
    if (m.psnr < t.minPsnr) out.push_back("PSNR " + formatValue(m.psnr) + " dB < " + formatValue(t.minPsnr) + " dB");
    if (m.ssim < t.minSsim) out.push_back("SSIM " + formatValue(m.ssim) + " < " + formatValue(t.minSsim));
    if (m.rmse > t.maxRmse) out.push_back("RMSE " + formatValue(m.rmse) + " > " + formatValue(t.maxRmse));
    return out;
}

std::vector<int> framesInBoth(const std::string& a, const std::string& b) {
    const std::set<int> fa = framesOnDisk(a), fb = framesOnDisk(b);
    std::vector<int> both;
    for (int f : fa)
        if (fb.count(f)) both.push_back(f);
    return both;
}

std::vector<std::string> finishCompare(const CompareJob& job, std::vector<FrameRecord>& records) {
    std::vector<std::string> failures;
    for (FrameRecord& r : records) {
        if (!r.compared) {
            failures.push_back(cat("frame ", r.frame, ": ", r.error));
            continue;
        }
        r.failures = checkThresholds(r.metrics, job.thresholds);
        std::string line;
        for (const std::string& f : r.failures) line += (line.empty() ? "" : ", ") + f;
        if (!line.empty()) failures.push_back(cat("frame ", r.frame, ": ", line));
    }
    writeTextAtomically(job.outputDir / "metrics.csv", metricsCsv(records));
    writeTextAtomically(job.outputDir / "metrics.json", metricsJson(job, records));
    if (!job.report.empty()) {
        writeTextAtomically(job.report, compareReportHtml(job, records));
        logInfo("compare: report ", job.report.string());
    }
    return failures;
}

}  // namespace hp
