#include "pipeline/groom/groom_file.h"

#include "core/errors.h"
#include "core/files.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>

namespace fs = std::filesystem;

namespace hp {

void GroomCurves::add(const Vec3f* p, size_t n) {
    points.insert(points.end(), p, p + n);
    offsets.push_back(uint32_t(points.size()));
}

void checkCurves(const GroomCurves& c, const std::string& name) {
    if (c.count() == 0) throw AssetError(name, "the groom has no strands");
    for (size_t s = 0; s < c.count(); ++s) {
        const uint32_t a = c.offsets[s], n = c.size(s);
        if (n < 2) throw AssetError(name, cat("strand ", s, " has ", n, n == 1 ? " point" : " points", " (a strand needs at least 2)"));
        float length = 0.f;
        for (uint32_t i = 0; i < n; ++i) {
            if (!c.points[a + i].allFinite())
                throw AssetError(name, cat("strand ", s, " point ", i, " is not a finite number"));
            if (i > 0) length += (c.points[a + i] - c.points[a + i - 1]).norm();
        }
        if (!(length > 0.f)) throw AssetError(name, cat("strand ", s, " has zero length (all its points coincide)"));
    }
}

// ---- .hair (Cem Yuksel) -------------------------------------------------------

GroomCurves parseHairFile(const std::vector<char>& bytes, const std::string& name) {
    constexpr size_t kHeader = 128;
    if (bytes.empty()) throw AssetError(name, "the .hair file is empty");
    if (bytes.size() < kHeader || std::memcmp(bytes.data(), "HAIR", 4) != 0)
        throw AssetError(name, bytes.size() < 4 || std::memcmp(bytes.data(), "HAIR", 4) != 0
                                   ? "not a .hair file (it does not start with \"HAIR\")"
                                   : cat("truncated .hair header (", bytes.size(), " of 128 bytes)"));
    auto u32 = [&](size_t at) {
        uint32_t v;
        std::memcpy(&v, bytes.data() + at, 4);
        return v;
    };
    const uint64_t strands = u32(4), points = u32(8);
    const uint32_t flags = u32(12), defaultSegments = u32(16);
    const bool hasSegments = flags & 1u, hasPoints = flags & 2u;
    if (!hasPoints) throw AssetError(name, "the .hair file has no points array (flag bit 1 unset)");
    if (strands == 0) throw AssetError(name, "the .hair file declares no strands");
    if (strands > kMaxGroomStrands)
        throw AssetError(name, cat("the .hair file declares ", strands, " strands (at most ", kMaxGroomStrands, ")"));
    if (points > kMaxGroomPoints)
        throw AssetError(name, cat("the .hair file declares ", points, " points (at most ", kMaxGroomPoints, ")"));
    // What the arrays the flags announce need, checked before allocating.
    const uint64_t perPoint = 12 + ((flags & 4u) ? 4 : 0) + ((flags & 8u) ? 4 : 0) + ((flags & 16u) ? 12 : 0);
    const uint64_t need = kHeader + (hasSegments ? 2 * strands : 0) + perPoint * points;
    if (bytes.size() < need)
        throw AssetError(name, cat("truncated .hair file: it declares ", strands, " strands and ", points,
                                   " points, which need ", need, " bytes, but it holds ", bytes.size()));
    size_t at = kHeader;
    std::vector<uint32_t> counts(strands);
    uint64_t total = 0;
    for (uint64_t s = 0; s < strands; ++s) {
        uint16_t segments = uint16_t(std::min<uint32_t>(defaultSegments, 65535u));
        if (hasSegments) std::memcpy(&segments, bytes.data() + at + 2 * s, 2);
        else if (defaultSegments > 65535u)
            throw AssetError(name, cat("the .hair default segment count ", defaultSegments, " is out of range"));
        counts[s] = uint32_t(segments) + 1;
        total += counts[s];
    }
    if (hasSegments) at += 2 * strands;
    if (total != points)
        throw AssetError(name, cat("the .hair strands have ", total, " points in all but the file declares ", points));
    GroomCurves c;
    c.offsets.reserve(strands + 1);
    c.points.resize(points);
    std::memcpy(static_cast<void*>(c.points.data()), bytes.data() + at, 12 * points);
    for (uint64_t s = 0; s < strands; ++s) c.offsets.push_back(c.offsets.back() + counts[s]);
    return c;
}

// ---- .usda (the subset export-usd writes) --------------------------------------

namespace {

std::string trim(const std::string& s) {
    const size_t b = s.find_first_not_of(" \t\r"), e = s.find_last_not_of(" \t\r");
    return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

bool startsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

class UsdaReader {
  public:
    UsdaReader(const std::string& text, const std::string& name) : in_(text), name_(name) {}

    GroomCurves read() {
        std::string line;
        if (!next(line) || line != "#usda 1.0") fail("not a .usda file (the first line is not \"#usda 1.0\")");
        bool prim = false, havePoints = false;
        std::vector<long> counts;
        GroomCurves c;
        while (next(line)) {
            const std::string t = trim(line);
            if (t.empty()) continue;
            if (t == "(" && !prim) {
                layerMetadata();
            } else if (startsWith(t, "def ")) {
                if (prim) fail("a second prim: only the single BasisCurves prim export-usd writes is read");
                if (!startsWith(t, "def BasisCurves "))
                    fail("'" + t + "': only a BasisCurves prim (as export-usd writes) is read");
                prim = true;
                skipTo("{");
            } else if (t == "}" && prim) {
                break;
            } else if (!prim) {
                fail("'" + t + "' outside the BasisCurves prim");
            } else if (t == "uniform token type = \"linear\"" || t == "uniform token wrap = \"nonperiodic\"") {
            } else if (startsWith(t, "uniform token type") || startsWith(t, "uniform token wrap")) {
                fail("'" + t + "': only linear, nonperiodic curves are read");
            } else if (startsWith(t, "int[] curveVertexCounts = ")) {
                counts = numbers<long>(t.substr(t.find('=') + 1));
            } else if (startsWith(t, "point3f[] points = ")) {
                points(t.substr(t.find('=') + 1), c), havePoints = true;
            } else if (t == "point3f[] points.timeSamples = {") {
                // The first sample; the others are skipped.
                if (!next(line)) fail("truncated points.timeSamples");
                const std::string sample = trim(line);
                const size_t colon = sample.find(':');
                if (colon == std::string::npos) fail("a time sample without 'time:'");
                points(sample.substr(colon + 1), c), havePoints = true;
                skipTo("}");
            } else if (startsWith(t, "vector3f[] velocities") || startsWith(t, "float[] widths") ||
                       startsWith(t, "uniform token widths:interpolation") || startsWith(t, "int[] primvars:hairpipe:") ||
                       startsWith(t, "int primvars:hairpipe:") || startsWith(t, "uniform token primvars:hairpipe:")) {
                if (t.back() == '{') skipTo("}");  // time samples of an attribute not needed
            } else {
                fail("'" + t.substr(0, 60) + "': not part of the BasisCurves export-usd writes");
            }
        }
        if (!prim) fail("no BasisCurves prim");
        if (!havePoints) fail("the BasisCurves has no points");
        if (counts.empty()) fail("the BasisCurves has no curveVertexCounts");
        if (counts.size() > kMaxGroomStrands) fail(cat(counts.size(), " curves (at most ", kMaxGroomStrands, ")"));
        std::vector<Vec3f> pts;
        pts.swap(c.points);
        uint64_t total = 0;
        for (long n : counts) {
            if (n < 0) fail("a negative curveVertexCount");
            total += uint64_t(n);
            if (total > pts.size()) break;
            c.offsets.push_back(uint32_t(total));
        }
        if (total != pts.size())
            fail(cat("curveVertexCounts add up to ", total, " points but the BasisCurves has ", pts.size()));
        c.points = std::move(pts);
        return c;
    }

  private:
    bool next(std::string& line) {
        if (!std::getline(in_, line)) return false;
        ++line_;
        return true;
    }
    [[noreturn]] void fail(const std::string& why) const {
        throw AssetError(name_, line_ > 0 ? cat("line ", line_, ": ", why) : why);
    }
    void skipTo(const char* closing) {
        std::string line;
        while (next(line))
            if (trim(line) == closing) return;
        fail(cat("truncated: no closing '", closing, "'"));
    }
    void layerMetadata() {
        std::string line;
        while (next(line)) {
            const std::string t = trim(line);
            if (t == ")") return;
            if (t == "metersPerUnit = 1" || t == "upAxis = \"Y\"" || startsWith(t, "defaultPrim =") ||
                startsWith(t, "timeCodesPerSecond =") || startsWith(t, "startTimeCode =") ||
                startsWith(t, "endTimeCode =") || startsWith(t, "doc ="))
                continue;
            fail("'" + t + "': only the layer metadata export-usd writes is read (metres, Y up)");
        }
        fail("truncated layer metadata");
    }
    /// Numbers of a "[a, b, ...]" list.
    template <typename T>
    std::vector<T> numbers(const std::string& list) {
        std::vector<T> out;
        const char* p = list.c_str();
        while (*p && *p != '[') ++p;
        if (*p != '[') fail("a list without '['");
        ++p;
        while (true) {
            while (*p == ' ' || *p == ',' || *p == '(' || *p == ')') ++p;
            if (*p == ']') return out;
            char* end = nullptr;
            const double v = std::strtod(p, &end);
            if (end == p) fail(cat("not a number in a list: '", std::string(p, std::min<size_t>(std::strlen(p), 20)), "'"));
            out.push_back(T(v));
            p = end;
        }
    }
    void points(const std::string& list, GroomCurves& c) {
        const std::vector<float> v = numbers<float>(list);
        if (v.size() % 3 != 0) fail("a point3f list whose length is not a multiple of 3");
        c.points.clear();
        for (size_t i = 0; i + 2 < v.size(); i += 3) c.points.emplace_back(v[i], v[i + 1], v[i + 2]);
    }

    std::istringstream in_;
    std::string name_;
    size_t line_ = 0;
};

}  // namespace

GroomCurves parseUsdaCurves(const std::string& text, const std::string& name) {
    if (text.empty()) throw AssetError(name, "the .usda file is empty");
    return UsdaReader(text, name).read();
}

GroomCurves readGroomFile(const fs::path& path) {
    const std::string name = path.string();
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw AssetError(name, "groom file not found");
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
    GroomCurves c;
    if (ext == ".hair") {
        c = parseHairFile(readFileBytes(path, "groom file"), name);
    } else if (ext == ".usda") {
        const std::vector<char> bytes = readFileBytes(path, "groom file");
        c = parseUsdaCurves(std::string(bytes.begin(), bytes.end()), name);
    } else if (ext == ".obj") {
        if (fs::file_size(path, ec) == 0) throw AssetError(name, "the .obj file is empty");
        c = readObjCurves(path);
    } else {
        throw AssetError(name, "unknown groom format '" + ext + "' (read: .obj polylines, .hair, .usda BasisCurves)");
    }
    checkCurves(c, name);
    return c;
}

}  // namespace hp
