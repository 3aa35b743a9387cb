#include "pipeline/batch/frame_range.h"

#include "core/errors.h"

#include <algorithm>
#include <cctype>
#include <climits>

namespace hp {

namespace {

// Frame numbers beyond this are certainly a typo, and bounding them keeps a
// range like "1-2000000000" from allocating gigabytes.
constexpr long kMaxFrame = 10000000;
constexpr size_t kMaxFrames = 1000000;

[[noreturn]] void bad(const std::string& text, const std::string& item, const std::string& why) {
    throw UsageError(cat("bad frame range '", text, "': '", item, "' ", why,
                         " (expected e.g. 5, 1-120, 1-120x2 or 3,7,10-20)"));
}

/// Reads an optionally signed integer at `pos`; advances pos.
bool readInt(const std::string& s, size_t& pos, long& out) {
    const size_t start = pos;
    if (pos < s.size() && (s[pos] == '-' || s[pos] == '+')) ++pos;
    const size_t digits = pos;
    while (pos < s.size() && std::isdigit(static_cast<unsigned char>(s[pos]))) ++pos;
    if (pos == digits || pos - digits > 9) {
        pos = start;
        return false;
    }
    out = std::stol(s.substr(start, pos - start));
    return true;
}

std::string trim(const std::string& s) {
    size_t a = 0, b = s.size();
    while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
    while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
    return s.substr(a, b - a);
}

}  // namespace

std::vector<int> parseFrameRange(const std::string& text) {
    std::vector<int> frames;
    if (trim(text).empty()) throw UsageError("bad frame range: empty (expected e.g. 5, 1-120, 1-120x2 or 3,7,10-20)");
    size_t begin = 0;
    while (begin <= text.size()) {
        size_t comma = text.find(',', begin);
        if (comma == std::string::npos) comma = text.size();
        const std::string item = trim(text.substr(begin, comma - begin));
        begin = comma + 1;
        if (item.empty()) bad(text, item, "is empty");
        size_t pos = 0;
        long first = 0, last = 0, step = 1;
        if (!readInt(item, pos, first)) bad(text, item, "does not start with a frame number");
        last = first;
        if (pos < item.size() && item[pos] == '-') {
            ++pos;
            if (!readInt(item, pos, last)) bad(text, item, "has no end frame after '-'");
            if (pos < item.size() && (item[pos] == 'x' || item[pos] == 'X')) {
                ++pos;
                if (!readInt(item, pos, step) || step <= 0) bad(text, item, "needs a positive step after 'x'");
            }
        }
        if (pos != item.size()) bad(text, item, "has unexpected characters");
        if (std::labs(first) > kMaxFrame || std::labs(last) > kMaxFrame) bad(text, item, "is out of range");
        if (last < first) bad(text, item, "ends before it starts");
        if (size_t((last - first) / step + 1) + frames.size() > kMaxFrames) bad(text, item, "has too many frames");
        for (long f = first; f <= last; f += step) frames.push_back(static_cast<int>(f));
        if (comma == text.size()) break;
    }
    std::sort(frames.begin(), frames.end());
    frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
    return frames;
}

std::string formatFrameRange(const std::vector<int>& frames) {
    std::string out;
    size_t i = 0;
    while (i < frames.size()) {
        // Longest run with a constant step starting at i.
        size_t j = i + 1;
        const long step = j < frames.size() ? long(frames[j]) - frames[i] : 1;
        while (j < frames.size() && long(frames[j]) - frames[j - 1] == step) ++j;
        if (!out.empty()) out += ',';
        const size_t n = j - i;
        if (n >= 3 || (n == 2 && step == 1)) {
            out += cat(frames[i], "-", frames[j - 1]);
            if (step != 1) out += cat("x", step);
            i = j;
        } else {
            out += cat(frames[i]);
            ++i;
        }
    }
    return out;
}

}  // namespace hp
