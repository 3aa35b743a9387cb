// Comparing two image sequences frame by frame (render/compare/compare.h), shared by
// the `hairpipe compare` command and the "compare" stage of `hairpipe run`.
//
// Per frame, compareFrame writes into the job's output folder
//   flip.####.png     the FLIP error map through the magma colour map
//   absdiff.####.exr  |A − B| of the display values (linear, half float)
//   metrics.####.json the frame's metrics and the two files compared
// and finishCompare assembles, from those files, the whole run's
//   metrics.csv, metrics.json  one row per frame, summary, pass/fail
//   report.html (or the job's report path)  a self-contained HTML report.
// Building the run's tables from per-frame files (not from memory) lets a
// resumed run, which skips frames already compared, still report every frame.
#pragma once

#include "render/compare/compare.h"
#include "render/image/display_transform.h"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace hp {

class Scene;

/// Pass/fail limits on each frame's metrics. The defaults are the metrics'
/// bounds, i.e. no limit: FLIP ≤ 1, PSNR ≥ 0 dB, SSIM ≥ −1, RMSE ≤ 1 always hold.
struct CompareThresholds {
    double maxFlip = 1.0;   ///< fail when mean FLIP > maxFlip
    double minPsnr = 0.0;   ///< fail when PSNR < minPsnr (dB)
    double minSsim = -1.0;  ///< fail when SSIM < minSsim
    double maxRmse = 1.0;   ///< fail when RMSE > maxRmse
};

struct CompareJob {
    std::string a;  ///< template of sequence A (the reference for FLIP), with #### or %04d
    std::string b;  ///< template of sequence B (the test)
    std::filesystem::path outputDir;  ///< per-frame images and the tables
    std::filesystem::path report;     ///< HTML report; empty: none
    CompareSettings settings;
    CompareThresholds thresholds;
    int reportWidth = 512;  ///< width of the images embedded in the report, pixels
    /// How the report shows A and B: the scene's display transform
    /// (render.ocio.*, render.exposure, render.background), as its PNGs.
    DisplaySettings display;
    /// What A and B are ("preview (OpenGL)", "reference (Embree, physical, 8 spp)"); empty: "A", "B".
    std::string aLabel, bLabel;
    /// A third sequence the report shows beside A and B without measuring it; empty: none.
    std::string beside, besideLabel;
    /// Which pair this is and what it measures ("gate: preview against the
    /// physical reference", "diagnostic: same model, other visibility"),
    /// written into the report and metrics.json; empty: none.
    std::string pair;
};

/// The job the scene's compare.* keys describe, with templates and folders
/// resolved against the shot's output folder (stage_compare.cpp). Throws
/// SceneError at compare.a / compare.b when a template has no frame number.
CompareJob compareJobFromScene(const Scene& scene, const std::filesystem::path& outputDir);

/// The diagnostic pair compare.diagnostic describes (compare.a against it,
/// measured and reported in compare.output/diagnostic/, never failing the
/// run), or nothing when compare.diagnostic is empty.
std::optional<CompareJob> diagnosticJobFromScene(const Scene& scene, const std::filesystem::path& outputDir);

/// The outcome for one frame.
struct FrameRecord {
    int frame = 0;
    std::string a, b;       ///< the two files
    bool compared = false;  ///< metrics are valid
    std::string error;      ///< why the frame was not compared
    int width = 0, height = 0;
    FrameMetrics metrics;
    std::vector<std::string> failures;  ///< threshold failures ("FLIP 0.21 > 0.1"), set by finishCompare
};

/// The per-frame files compareFrame writes.
std::filesystem::path flipImagePath(const CompareJob& job, int frame);
std::filesystem::path diffImagePath(const CompareJob& job, int frame);
std::filesystem::path frameMetricsPath(const CompareJob& job, int frame);
std::vector<std::filesystem::path> frameOutputs(const CompareJob& job, int frame);

/// Reads frame `frame` of both sequences, compares them and writes the
/// per-frame files. Throws AssetError naming a missing or unreadable file, or
/// FrameError naming both files when their resolutions differ.
FrameRecord compareFrame(const CompareJob& job, int frame);

/// The record compareFrame wrote for `frame`; when there is none, a record
/// with `error` set (the frame was not compared).
FrameRecord loadFrameRecord(const CompareJob& job, int frame);

/// Threshold failures of one frame's metrics, e.g. "FLIP 0.213 > 0.1".
std::vector<std::string> checkThresholds(const FrameMetrics& metrics, const CompareThresholds& thresholds);

/// Frames that have a file in both sequences, sorted. The frame token must be
/// in the file name (not a folder name). Unreadable folders count as empty.
std::vector<int> framesInBoth(const std::string& a, const std::string& b);

/// Sets each record's threshold failures, writes metrics.csv, metrics.json and
/// the HTML report, and returns one line per failed frame (threshold failures
/// or not compared); empty when every frame passed.
std::vector<std::string> finishCompare(const CompareJob& job, std::vector<FrameRecord>& records);

}  // namespace hp
