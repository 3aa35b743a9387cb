#include "pipeline/batch/path_template.h"

#include "core/errors.h"

#include <cctype>
#include <cstdio>

namespace hp {

namespace {

struct Token {
    size_t pos = std::string::npos;
    size_t length = 0;
    int padding = 0;
};

/// Finds frame tokens; returns how many there are and the first one.
int findTokens(const std::string& p, Token* first) {
    int count = 0;
    for (size_t i = 0; i < p.size();) {
        Token t;
        if (p[i] == '#') {
            size_t j = i;
            while (j < p.size() && p[j] == '#') ++j;
            t = {i, j - i, int(j - i)};
        } else if (p[i] == '%') {
            // %d, %4d, %04d
            size_t j = i + 1;
            while (j < p.size() && std::isdigit(static_cast<unsigned char>(p[j]))) ++j;
            if (j < p.size() && p[j] == 'd') {
                const std::string digits = p.substr(i + 1, j - i - 1);
                t = {i, j - i + 1, digits.empty() ? 0 : std::stoi(digits)};
            }
        }
        if (t.pos != std::string::npos) {
            if (count++ == 0 && first) *first = t;
            i = t.pos + t.length;
        } else {
            ++i;
        }
    }
    return count;
}

}  // namespace

bool hasFrameToken(const std::string& pattern) { return findTokens(pattern, nullptr) > 0; }

std::string expandFrame(const std::string& pattern, int frame) {
    Token t;
    const int n = findTokens(pattern, &t);
    if (n == 0) throw UsageError("path template '" + pattern + "' has no frame number (use #### or %04d)");
    if (n > 1) throw UsageError("path template '" + pattern + "' has more than one frame number");
    if (t.padding > 32) throw UsageError("path template '" + pattern + "' pads to more than 32 digits");
    char digits[48];
    std::snprintf(digits, sizeof digits, "%0*d", t.padding + (frame < 0 ? 1 : 0), frame);
    return pattern.substr(0, t.pos) + digits + pattern.substr(t.pos + t.length);
}

bool matchFrame(const std::string& pattern, const std::string& fileName, int* frame) {
    Token t;
    if (findTokens(pattern, &t) != 1) return false;
    const std::string prefix = pattern.substr(0, t.pos), suffix = pattern.substr(t.pos + t.length);
    if (fileName.size() <= prefix.size() + suffix.size() || fileName.compare(0, prefix.size(), prefix) != 0 ||
        fileName.compare(fileName.size() - suffix.size(), suffix.size(), suffix) != 0)
        return false;
    const std::string digits = fileName.substr(prefix.size(), fileName.size() - prefix.size() - suffix.size());
    const size_t start = digits[0] == '-' ? 1 : 0;
    if (digits.size() <= start || digits.size() - start > 9) return false;
    for (size_t i = start; i < digits.size(); ++i)
        if (!std::isdigit(static_cast<unsigned char>(digits[i]))) return false;
    // expandFrame pads to at least the token's width: "0012" matches ####, "12" does not.
    if (int(digits.size()) < t.padding + int(start)) return false;
    const int value = std::stoi(digits);
    if (expandFrame(pattern, value) != fileName) return false;
    *frame = value;
    return true;
}

}  // namespace hp
