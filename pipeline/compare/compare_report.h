// The comparison's HTML report: one self-contained file that opens in any
// browser without network access (every image is an embedded PNG data URI,
// styles and script are inline, and a Content-Security-Policy forbids any
// other source).
//
// It holds: the verdict (PASS/FAIL) and settings; summary statistics (mean,
// min, max per metric) against the thresholds; one inline SVG plot per metric
// over the frames (threshold dashed, failing frames red; click a point to jump
// to that frame); a flip-book — a slider over the frames showing
// A | B | FLIP heat map | |A − B| side by side, with an A⇄B toggle (space key)
// and playback; and the per-frame table with the files and any errors.
//
// When loaded, a small script checks that every image decoded
// (naturalWidth > 0) and every plot has a drawn path, and records the result
// on <body>: data-status="ok" or "error", data-images, data-broken,
// data-plots, data-plots-drawn (used by the tests through headless Chromium).
#pragma once

#include "pipeline/compare/compare_job.h"

#include <string>
#include <vector>

namespace hp {

/// The report for `records` (with threshold failures already set). Reads the
/// frames' A and B files and the per-frame images to embed them, scaled to
/// job.reportWidth; images that cannot be read are shown as a note instead.
std::string compareReportHtml(const CompareJob& job, const std::vector<FrameRecord>& records);

}  // namespace hp
