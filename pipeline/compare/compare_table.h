// The comparison's tables: per-frame metrics as JSON (metrics.####.json,
// read back when a run is resumed) and the run's CSV and JSON tables with
// summary statistics. Infinite PSNR (identical frames) is written as `null`
// in JSON and `inf` in CSV.
#pragma once

#include "pipeline/compare/compare_job.h"

#include <string>
#include <vector>

namespace hp {

/// Mean, minimum and maximum of one metric over the compared frames.
struct MetricSummary {
    int count = 0;
    double mean = 0, min = 0, max = 0;
};

struct CompareSummary {
    int frames = 0;    ///< frames in the run
    int compared = 0;  ///< frames with metrics
    int failed = 0;    ///< frames failing a threshold or not compared
    MetricSummary rmse, psnr, ssim, flip;
    bool pass() const { return failed == 0 && frames > 0; }
};

CompareSummary summarize(const std::vector<FrameRecord>& records);

/// One frame's record as a JSON object (the metrics.####.json format).
std::string frameRecordJson(const FrameRecord& record);
/// Parses frameRecordJson's output; throws AssetError naming `path` when malformed.
FrameRecord parseFrameRecord(const std::string& text, const std::string& path);

/// The run's table: a header and one row per frame.
std::string metricsCsv(const std::vector<FrameRecord>& records);
/// The run as JSON: inputs, settings, thresholds, summary, frames.
std::string metricsJson(const CompareJob& job, const std::vector<FrameRecord>& records);

}  // namespace hp
