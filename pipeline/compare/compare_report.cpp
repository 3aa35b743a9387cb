#include "pipeline/compare/compare_report.h"

#include "core/errors.h"
#include "core/log.h"
#include "pipeline/compare/compare_table.h"
#include "pipeline/batch/path_template.h"
#include "render/image/image_encode.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <sstream>

namespace hp {

namespace {

std::string html(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            default: out += c;
        }
    }
    return out;
}

std::string num(double v) {
    if (std::isinf(v)) return v > 0 ? "∞" : "−∞";
    if (std::isnan(v)) return "—";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
}

std::string fixed(double v, int decimals) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return buf;
}

/// Data URIs of one frame's four panels; empty where the image is unavailable.
struct FrameImages {
    std::string a, b, beside, flip, diff;
};

/// The image as an embedded PNG, or empty (the page then says the image is
/// missing) when it cannot be read: a report of a partly failed shot must
/// still be written, so this warns with the file and the reason instead of
/// failing the report.
std::string thumbnail(const std::string& path, bool linearize, bool srgbEncode, int width) {
    try {
        const Image image = readImage(path, linearize);
        return pngDataUri(resizeToWidth(displayImage(image), width), srgbEncode);
    } catch (const Error& e) {
        logWarning("compare report: no thumbnail of ", path, ": ", e.what());
        return {};
    }
}

/// A render (linear EXR, or an 8-bit file linearised) through the job's
/// display transform, as the stages' PNGs show it.
std::string renderThumbnail(const std::string& path, const DisplaySettings& display, int width) {
    try {
        return pngDataUri(toDisplay(resizeToWidth(readImage(path, true), width), display), false);
    } catch (const Error& e) {
        logWarning("compare report: no thumbnail of ", path, ": ", e.what());
        return {};
    }
}

FrameImages loadImages(const CompareJob& job, const FrameRecord& r) {
    FrameImages f;
    f.a = renderThumbnail(r.a, job.display, job.reportWidth);
    f.b = renderThumbnail(r.b, job.display, job.reportWidth);
    if (!job.beside.empty()) f.beside = renderThumbnail(expandFrame(job.beside, r.frame), job.display, job.reportWidth);
    if (r.compared) {
        // The heat map PNG holds display values already: read and write it as stored.
        f.flip = thumbnail(flipImagePath(job, r.frame).string(), false, false, job.reportWidth);
        f.diff = thumbnail(diffImagePath(job, r.frame).string(), false, true, job.reportWidth);
    }
    return f;
}

struct Series {
    const char* name;
    const char* better;  ///< "lower" or "higher"
    double threshold;
    bool active;  ///< threshold differs from the metric's bound
    std::function<double(const FrameMetrics&)> get;
};

std::vector<Series> seriesOf(const CompareThresholds& t) {
    return {
        {"FLIP", "lower", t.maxFlip, t.maxFlip < 1.0, [](const FrameMetrics& m) { return m.flip; }},
        {"SSIM", "higher", t.minSsim, t.minSsim > -1.0, [](const FrameMetrics& m) { return m.ssim; }},
        {"PSNR (dB)", "higher", t.minPsnr, t.minPsnr > 0.0, [](const FrameMetrics& m) { return m.psnr; }},
        {"RMSE", "lower", t.maxRmse, t.maxRmse < 1.0, [](const FrameMetrics& m) { return m.rmse; }},
    };
}

/// One metric over the frames as an inline SVG line plot.
std::string plotSvg(const Series& s, const std::vector<FrameRecord>& records) {
    constexpr double W = 460, H = 180, x0 = 56, x1 = 446, y0 = 14, y1 = 150;
    double lo = INFINITY, hi = -INFINITY;
    bool infinite = false;
    for (const FrameRecord& r : records) {
        if (!r.compared) continue;
        const double v = s.get(r.metrics);
        if (std::isinf(v)) infinite = true;
        else lo = std::min(lo, v), hi = std::max(hi, v);
    }
    if (s.active) lo = std::min(lo, s.threshold), hi = std::max(hi, s.threshold);
    if (!(lo <= hi)) lo = 0, hi = 1;  // only infinite values
    const double pad = hi > lo ? 0.08 * (hi - lo) : std::max(1e-3, 0.05 * std::abs(hi));
    lo -= pad;
    hi += infinite ? 3 * pad : pad;  // room at the top for +∞ points
    const size_t n = records.size();
    auto X = [&](size_t i) { return n > 1 ? x0 + (x1 - x0) * double(i) / double(n - 1) : 0.5 * (x0 + x1); };
    auto Y = [&](double v) { return std::isinf(v) ? y0 : y1 - (y1 - y0) * (v - lo) / (hi - lo); };

    std::ostringstream out;
    out << "<svg class=\"plot\" viewBox=\"0 0 " << W << " " << H << "\" width=\"" << W << "\" height=\"" << H
        << "\" role=\"img\" aria-label=\"" << html(s.name) << " per frame\">"
        << "<line class=\"axis\" x1=\"" << x0 << "\" y1=\"" << y1 << "\" x2=\"" << x1 << "\" y2=\"" << y1 << "\"/>"
        << "<line class=\"axis\" x1=\"" << x0 << "\" y1=\"" << y0 << "\" x2=\"" << x0 << "\" y2=\"" << y1 << "\"/>"
        << "<text x=\"" << x0 - 4 << "\" y=\"" << y0 + 4 << "\" text-anchor=\"end\">" << num(hi) << "</text>"
        << "<text x=\"" << x0 - 4 << "\" y=\"" << y1 << "\" text-anchor=\"end\">" << num(lo) << "</text>";
    if (n > 0)
        out << "<text x=\"" << X(0) << "\" y=\"" << H - 12 << "\" text-anchor=\"middle\">" << records.front().frame
            << "</text><text x=\"" << X(n - 1) << "\" y=\"" << H - 12 << "\" text-anchor=\"middle\">"
            << records.back().frame << "</text><text x=\"" << 0.5 * (x0 + x1) << "\" y=\"" << H - 1
            << "\" text-anchor=\"middle\">frame</text>";
    if (s.active)
        out << "<line class=\"threshold\" x1=\"" << x0 << "\" y1=\"" << fixed(Y(s.threshold), 2) << "\" x2=\"" << x1
            << "\" y2=\"" << fixed(Y(s.threshold), 2) << "\"><title>threshold " << num(s.threshold)
            << "</title></line>";
    std::string d;
    bool pen = false;
    for (size_t i = 0; i < n; ++i) {
        if (!records[i].compared) {
            pen = false;  // a gap where a frame was not compared
            continue;
        }
        d += (pen ? "L" : "M") + fixed(X(i), 2) + "," + fixed(Y(s.get(records[i].metrics)), 2);
        pen = true;
    }
    out << "<path class=\"series\" d=\"" << d << "\"/>";
    for (size_t i = 0; i < n; ++i) {
        if (!records[i].compared) continue;
        const double v = s.get(records[i].metrics);
        out << "<circle class=\"" << (records[i].failures.empty() ? "ok" : "bad") << "\" data-index=\"" << i
            << "\" cx=\"" << fixed(X(i), 2) << "\" cy=\"" << fixed(Y(v), 2) << "\" r=\"3.5\"><title>frame "
            << records[i].frame << ": " << num(v) << "</title></circle>";
    }
    out << "</svg>";
    return out.str();
}

/// A side's name in the report: "A: preview (OpenGL)", or "A" without a label.
std::string sideName(const char* side, const std::string& label) {
    return label.empty() ? std::string(side) : cat(side, ": ", label);
}

std::string panel(const std::string& uri, const std::string& caption, const std::string& cls,
                  const std::string& captionData = "") {
    std::ostringstream out;
    out << "<figure" << captionData << ">";
    if (uri.empty()) out << "<div class=\"missing\">not available</div>";
    else out << "<img class=\"" << cls << "\" alt=\"" << html(caption) << "\" src=\"" << uri << "\">";
    out << "<figcaption>" << html(caption) << "</figcaption></figure>";
    return out.str();
}

std::string metricsLine(const FrameRecord& r) {
    if (!r.compared) return "<span class=\"bad\">" + html(r.error) + "</span>";
    std::ostringstream out;
    out << "FLIP " << num(r.metrics.flip) << " · SSIM " << num(r.metrics.ssim) << " · PSNR " << num(r.metrics.psnr)
        << " dB · RMSE " << num(r.metrics.rmse) << " · " << r.metrics.pixels << " px";
    for (const std::string& f : r.failures) out << " · <span class=\"bad\">" << html(f) << "</span>";
    return out.str();
}

const char* kStyle = R"(body{font:14px/1.4 system-ui,sans-serif;margin:1.5em;background:#fafafa;color:#222}
h1 .pass{color:#11772d}h1 .fail,.bad{color:#c62828}table{border-collapse:collapse;margin:.5em 0}
td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}td.l,th.l{text-align:left}
.plots{display:flex;flex-wrap:wrap;gap:12px}.plots figure{margin:0;background:#fff;border:1px solid #ddd;padding:4px}
svg.plot text{font-size:11px;fill:#444}svg.plot .axis{stroke:#888}svg.plot .series{fill:none;stroke:#3949ab;stroke-width:1.5}
svg.plot .threshold{stroke:#c62828;stroke-dasharray:5 4}svg.plot circle.ok{fill:#3949ab;cursor:pointer}
svg.plot circle.bad{fill:#c62828;cursor:pointer}.viewer{background:#222;color:#eee;padding:10px;border-radius:4px}
.panels{display:grid;grid-template-columns:repeat(4,minmax(0,1fr));gap:8px}.panels.five{grid-template-columns:repeat(5,minmax(0,1fr))}.panels figure{margin:0}
.panels img{display:block;width:100%;height:auto}
.panels figcaption{text-align:center;font-size:12px}.missing{aspect-ratio:16/9;display:flex;
align-items:center;justify-content:center;border:1px dashed #888}.controls{margin-bottom:8px}
.controls input[type=range]{width:50%;vertical-align:middle}code{font-size:12px;word-break:break-all})";

// The flip-book and the load-time self-check (see compare_report.h).
const char* kScript = R"((function(){
var frames=[].slice.call(document.querySelectorAll('.frame'));
var slider=document.getElementById('slider'),label=document.getElementById('frame-label');
var cur=0,showB=false,timer=null;
function swap(b){var f=frames[cur];if(!f)return;var img=f.querySelector('img.swap'),bi=f.querySelector('img.b');
if(!img||!bi)return;if(!img.dataset.a)img.dataset.a=img.src;img.src=b?bi.src:img.dataset.a;showB=b;
var g=f.querySelector('figure'),c=g.querySelector('figcaption');if(c)c.textContent=b?g.dataset.b:g.dataset.a;}
function show(i){if(!frames.length)return;swap(false);cur=Math.max(0,Math.min(frames.length-1,i));
frames.forEach(function(f,k){f.hidden=k!==cur;});slider.value=cur;
label.textContent='frame '+frames[cur].dataset.frame+' ('+(cur+1)+'/'+frames.length+')';}
if(slider){slider.addEventListener('input',function(){show(+slider.value);});
document.getElementById('toggle').addEventListener('click',function(){swap(!showB);});
document.getElementById('play').addEventListener('click',function(e){if(timer){clearInterval(timer);timer=null;
e.target.textContent='play';}else{timer=setInterval(function(){show((cur+1)%frames.length);},400);e.target.textContent='stop';}});
document.addEventListener('keydown',function(e){if(e.key==='ArrowRight')show(cur+1);else if(e.key==='ArrowLeft')show(cur-1);
else if(e.key===' '){e.preventDefault();swap(!showB);}});
[].forEach.call(document.querySelectorAll('svg.plot circle'),function(c){c.addEventListener('click',function(){
show(+c.getAttribute('data-index'));document.getElementById('viewer').scrollIntoView();});});show(0);}
window.addEventListener('load',function(){var imgs=[].slice.call(document.images);
var broken=imgs.filter(function(i){return !(i.complete&&i.naturalWidth>0);});
var plots=[].slice.call(document.querySelectorAll('svg.plot'));
var drawn=plots.filter(function(s){var p=s.querySelector('path.series');return p&&p.getTotalLength()>=0&&
p.getAttribute('d').length>0&&s.querySelectorAll('circle').length>0;});
var b=document.body;b.setAttribute('data-images',imgs.length);b.setAttribute('data-broken',broken.length);
b.setAttribute('data-plots',plots.length);b.setAttribute('data-plots-drawn',drawn.length);
b.setAttribute('data-status',broken.length===0&&drawn.length===plots.length?'ok':'error');});})();)";

}  // namespace

std::string compareReportHtml(const CompareJob& job, const std::vector<FrameRecord>& records) {
    std::vector<FrameImages> images(records.size());
    tbb::parallel_for(size_t(0), records.size(), [&](size_t i) { images[i] = loadImages(job, records[i]); });
    const CompareSummary s = summarize(records);
    const std::vector<Series> series = seriesOf(job.thresholds);
    const char* verdict = s.pass() ? "PASS" : "FAIL";

    std::ostringstream out;
    out << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
        << "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; img-src data:; "
           "style-src 'unsafe-inline'; script-src 'unsafe-inline'\">\n"
        << "<title>hairpipe compare: " << verdict << "</title>\n<style>" << kStyle << "</style></head>\n"
        << "<body data-status=\"loading\">\n<h1>hairpipe compare: <span class=\"" << (s.pass() ? "pass" : "fail")
        << "\">" << verdict << "</span></h1>\n";
    if (!job.pair.empty()) out << "<p class=\"pair\">" << html(job.pair) << "</p>\n";
    out
        << "<table><tr><th class=\"l\">" << html(sideName("A", job.aLabel)) << "</th><td class=\"l\"><code>"
        << html(job.a) << "</code></td></tr>"
        << "<tr><th class=\"l\">" << html(sideName("B", job.bLabel)) << "</th><td class=\"l\"><code>"
        << html(job.b) << "</code></td></tr>";
    if (!job.beside.empty())
        out << "<tr><th class=\"l\">" << html(sideName("beside", job.besideLabel))
            << "</th><td class=\"l\">shown, not measured: <code>" << html(job.beside) << "</code></td></tr>";
    out << "<tr><th class=\"l\">measured pair</th><td class=\"l\">" << html(sideName("A", job.aLabel)) << " against "
        << html(sideName("B", job.bLabel))
        << ": every metric, plot and threshold below is this pair (A is FLIP's reference side)</td></tr>"
        << "<tr><th class=\"l\">frames</th><td class=\"l\">" << s.frames << " (" << s.compared << " compared, "
        << s.failed << " failing)</td></tr><tr><th class=\"l\">settings</th><td class=\"l\">mask "
        << (job.settings.mask == MaskMode::Hair ? "hair (alpha &gt; 0 in A or B)" : "none (whole frame)")
        << "; FLIP at " << num(job.settings.flip.pixelsPerDegree) << " pixels per degree</td></tr></table>\n";

    out << "<h2>Summary</h2>\n<table><tr><th class=\"l\">metric</th><th>better</th><th>threshold</th><th>mean</th>"
           "<th>min</th><th>max</th><th>frames failing</th></tr>\n";
    const MetricSummary* sums[] = {&s.flip, &s.ssim, &s.psnr, &s.rmse};
    const char* keys[] = {"FLIP", "SSIM", "PSNR", "RMSE"};
    for (size_t k = 0; k < series.size(); ++k) {
        int failing = 0;
        for (const FrameRecord& r : records)
            for (const std::string& f : r.failures) failing += f.rfind(keys[k], 0) == 0;
        const MetricSummary& m = *sums[k];
        out << "<tr><th class=\"l\">" << series[k].name << "</th><td>" << series[k].better << "</td><td>"
            << (series[k].active ? num(series[k].threshold) : "—") << "</td><td>" << (m.count ? num(m.mean) : "—")
            << "</td><td>" << (m.count ? num(m.min) : "—") << "</td><td>" << (m.count ? num(m.max) : "—")
            << "</td><td" << (failing ? " class=\"bad\"" : "") << ">" << failing << "</td></tr>\n";
    }
    out << "</table>\n";
    if (s.compared > 0) {
        out << "<h2>Metrics over frames</h2>\n<div class=\"plots\">";
        for (const Series& se : series)
            out << "<figure>" << plotSvg(se, records) << "<figcaption>" << html(se.name) << " (" << se.better
                << " is better)</figcaption></figure>";
        out << "</div>\n";
    }

    out << "<h2>Frames</h2>\n<div class=\"viewer\" id=\"viewer\">";
    if (!records.empty())
        out << "<div class=\"controls\"><input type=\"range\" id=\"slider\" min=\"0\" max=\"" << records.size() - 1
            << "\" value=\"0\" aria-label=\"frame\"> <span id=\"frame-label\"></span> "
               "<button id=\"toggle\">A ⇄ B</button> <button id=\"play\">play</button></div>\n";
    for (size_t i = 0; i < records.size(); ++i) {
        const FrameRecord& r = records[i];
        const std::string a = sideName("A", job.aLabel), b = sideName("B", job.bLabel);
        out << "<div class=\"frame\" data-frame=\"" << r.frame << "\"" << (i ? " hidden" : "") << "><div class=\"panels"
            << (job.beside.empty() ? "" : " five") << "\">"
            << panel(images[i].a, a + " (toggle: space)", "a swap",
                     " data-a=\"" + html(a + " (toggle: space)") + "\" data-b=\"" + html(b + " (toggled: space)") + "\"");
        // The unmeasured sequence (the physical reference) right beside A (the preview).
        if (!job.beside.empty()) out << panel(images[i].beside, sideName("beside", job.besideLabel), "beside");
        out << panel(images[i].b, b, "b")
            << panel(images[i].flip, "FLIP error (magma, 0 black → 1 yellow)", "flip")
            << panel(images[i].diff, "|A − B|", "diff") << "</div><p>frame " << r.frame << ": " << metricsLine(r)
            << "</p></div>\n";
    }
    out << "</div>\n<h2>Per-frame table</h2>\n<table><tr><th>frame</th><th>FLIP</th><th>SSIM</th><th>PSNR</th>"
           "<th>RMSE</th><th>max |A−B|</th><th>pixels</th><th class=\"l\">result</th><th class=\"l\">A</th>"
           "<th class=\"l\">B</th></tr>\n";
    for (const FrameRecord& r : records) {
        out << "<tr><td>" << r.frame << "</td>";
        if (r.compared)
            out << "<td>" << num(r.metrics.flip) << "</td><td>" << num(r.metrics.ssim) << "</td><td>"
                << num(r.metrics.psnr) << "</td><td>" << num(r.metrics.rmse) << "</td><td>" << num(r.metrics.maxError)
                << "</td><td>" << r.metrics.pixels << "</td>";
        else
            out << "<td colspan=\"6\"></td>";
        std::string result = r.compared ? (r.failures.empty() ? "pass" : "fail: ") : "error: " + r.error;
        for (size_t k = 0; k < r.failures.size(); ++k) result += (k ? ", " : "") + r.failures[k];
        out << "<td class=\"l" << (r.compared && r.failures.empty() ? "" : " bad") << "\">" << html(result)
            << "</td><td class=\"l\"><code>" << html(r.a) << "</code></td><td class=\"l\"><code>" << html(r.b)
            << "</code></td></tr>\n";
    }
    out << "</table>\n<script>" << kScript << "</script>\n</body></html>\n";
    return out.str();
}

}  // namespace hp
