#include "pipeline/compare/compare_table.h"

#include "core/errors.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace hp {

namespace {

/// A number for JSON ("null" when not finite), 10 significant digits.
std::string jsonNumber(double v) {
    if (!std::isfinite(v)) return "null";
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.10g", v);
    return buf;
}

/// A JSON string literal with escapes.
std::string jsonString(const std::string& s) {
    std::string out = "\"";
    for (unsigned char c : s) {
        switch (c) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\n': out += "\\n"; break;
            case '\t': out += "\\t"; break;
            case '\r': out += "\\r"; break;
            default:
                if (c < 0x20) {
                    char buf[8];
                    std::snprintf(buf, sizeof buf, "\\u%04x", c);
                    out += buf;
                } else {
                    out += char(c);
                }
        }
    }
    return out + "\"";
}

void add(MetricSummary& s, double v) {
    if (std::isnan(v)) return;
    s.mean += v;  // a running sum until summarize divides it
    s.min = s.count ? std::min(s.min, v) : v;
    s.max = s.count ? std::max(s.max, v) : v;
    ++s.count;
}

const char* maskName(MaskMode m) { return m == MaskMode::Hair ? "hair" : "none"; }

std::string csvField(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string out = "\"";
    for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

std::string csvNumber(double v) {
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    return jsonNumber(v) == "null" ? "" : jsonNumber(v);
}

std::string status(const FrameRecord& r) { return !r.compared ? "error" : r.failures.empty() ? "pass" : "fail"; }

std::string join(const std::vector<std::string>& items, const std::string& sep) {
    std::string out;
    for (const std::string& s : items) out += (out.empty() ? "" : sep) + s;
    return out;
}

void summaryJson(std::ostringstream& out, const char* name, const MetricSummary& s, bool last) {
    out << "    " << jsonString(name) << ": {\"mean\": " << (s.count ? jsonNumber(s.mean) : "null")
        << ", \"min\": " << (s.count ? jsonNumber(s.min) : "null") << ", \"max\": " << (s.count ? jsonNumber(s.max) : "null")
        << "}" << (last ? "\n" : ",\n");
}

}  // namespace

CompareSummary summarize(const std::vector<FrameRecord>& records) {
    CompareSummary s;
    s.frames = int(records.size());
    for (const FrameRecord& r : records) {
        if (!r.compared || !r.failures.empty()) ++s.failed;
        if (!r.compared) continue;
        ++s.compared;
        add(s.rmse, r.metrics.rmse);
        add(s.psnr, r.metrics.psnr);
        add(s.ssim, r.metrics.ssim);
        add(s.flip, r.metrics.flip);
    }
    for (MetricSummary* m : {&s.rmse, &s.psnr, &s.ssim, &s.flip})
        if (m->count) m->mean /= m->count;  // +inf stays +inf (identical frames)
    return s;
}

std::string frameRecordJson(const FrameRecord& r) {
    std::ostringstream out;
    out << "{\"frame\": " << r.frame << ", \"a\": " << jsonString(r.a) << ", \"b\": " << jsonString(r.b)
        << ", \"width\": " << r.width << ", \"height\": " << r.height << ", \"pixels\": " << r.metrics.pixels
        << ", \"rmse\": " << jsonNumber(r.metrics.rmse) << ", \"psnr\": " << jsonNumber(r.metrics.psnr)
        << ", \"max_error\": " << jsonNumber(r.metrics.maxError) << ", \"ssim\": " << jsonNumber(r.metrics.ssim)
        << ", \"flip\": " << jsonNumber(r.metrics.flip) << "}";
    return out.str();
}

FrameRecord parseFrameRecord(const std::string& text, const std::string& path) {
    FrameRecord r;
    try {
        const YAML::Node n = YAML::Load(text);
        r.frame = n["frame"].as<int>();
        r.a = n["a"].as<std::string>();
        r.b = n["b"].as<std::string>();
        r.width = n["width"].as<int>();
        r.height = n["height"].as<int>();
        r.metrics.pixels = n["pixels"].as<long>();
        r.metrics.rmse = n["rmse"].as<double>();
        // PSNR is null for identical frames (+inf); the other metrics are always finite.
        r.metrics.psnr = n["psnr"].IsNull() ? std::numeric_limits<double>::infinity() : n["psnr"].as<double>();
        r.metrics.maxError = n["max_error"].as<double>();
        r.metrics.ssim = n["ssim"].as<double>();
        r.metrics.flip = n["flip"].as<double>();
    } catch (const YAML::Exception& e) {
        throw AssetError(path, std::string("malformed per-frame metrics (rerun with --force): ") + e.what());
    }
    r.compared = true;
    return r;
}

std::string metricsCsv(const std::vector<FrameRecord>& records) {
    std::ostringstream out;
    out << "frame,a,b,status,pixels,rmse,psnr,max_error,ssim,flip,problems\n";
    for (const FrameRecord& r : records) {
        out << r.frame << "," << csvField(r.a) << "," << csvField(r.b) << "," << status(r) << ",";
        if (r.compared)
            out << r.metrics.pixels << "," << csvNumber(r.metrics.rmse) << "," << csvNumber(r.metrics.psnr) << ","
                << csvNumber(r.metrics.maxError) << "," << csvNumber(r.metrics.ssim) << ","
                << csvNumber(r.metrics.flip) << ",";
        else
            out << ",,,,,,";
        out << csvField(r.compared ? join(r.failures, "; ") : r.error) << "\n";
    }
    return out.str();
}

std::string metricsJson(const CompareJob& job, const std::vector<FrameRecord>& records) {
    const CompareSummary s = summarize(records);
    const CompareThresholds& t = job.thresholds;
    std::ostringstream out;
    out << "{\n  \"pair\": " << jsonString(job.pair) << ",\n  \"a\": " << jsonString(job.a) << ",\n  \"b\": " << jsonString(job.b) << ",\n"
        << "  \"settings\": {\"mask\": " << jsonString(maskName(job.settings.mask))
        << ", \"pixels_per_degree\": " << jsonNumber(job.settings.flip.pixelsPerDegree) << "},\n"
        << "  \"thresholds\": {\"max_flip\": " << jsonNumber(t.maxFlip) << ", \"min_psnr\": " << jsonNumber(t.minPsnr)
        << ", \"min_ssim\": " << jsonNumber(t.minSsim) << ", \"max_rmse\": " << jsonNumber(t.maxRmse) << "},\n"
        << "  \"pass\": " << (s.pass() ? "true" : "false") << ",\n"
        << "  \"summary\": {\n    \"frames\": " << s.frames << ", \"compared\": " << s.compared
        << ", \"failed\": " << s.failed << ",\n";
    summaryJson(out, "rmse", s.rmse, false);
    summaryJson(out, "psnr", s.psnr, false);
    summaryJson(out, "ssim", s.ssim, false);
    summaryJson(out, "flip", s.flip, true);
    out << "  },\n  \"frames\": [";
    for (size_t i = 0; i < records.size(); ++i) {
        const FrameRecord& r = records[i];
        out << (i ? ",\n    " : "\n    ");
        if (r.compared) {
            std::string rec = frameRecordJson(r);
            rec.pop_back();  // reopen the object to append status and failures
            out << rec << ", \"status\": " << jsonString(status(r)) << ", \"failures\": [";
            for (size_t k = 0; k < r.failures.size(); ++k) out << (k ? ", " : "") << jsonString(r.failures[k]);
            out << "]}";
        } else {
            out << "{\"frame\": " << r.frame << ", \"a\": " << jsonString(r.a) << ", \"b\": " << jsonString(r.b)
                << ", \"status\": \"error\", \"error\": " << jsonString(r.error) << "}";
        }
    }
    out << (records.empty() ? "]\n}\n" : "\n  ]\n}\n");
    return out.str();
}

}  // namespace hp
