// Frame path templates: "preview.####.png" (one '#' per digit of padding) or
// printf style "preview.%04d.png". Negative frames keep the sign before the
// padded digits ("-001").
#pragma once

#include <string>

namespace hp {

/// True if `pattern` contains a frame token.
bool hasFrameToken(const std::string& pattern);

/// Expands the frame token; throws UsageError if there is none (a sequence
/// would overwrite one file) or more than one.
std::string expandFrame(const std::string& pattern, int frame);

/// If `fileName` is `pattern` with its frame token replaced by a frame number
/// (any number of digits, at least the padding, optionally negative), stores
/// the frame and returns true. Compares names only, not folders.
bool matchFrame(const std::string& pattern, const std::string& fileName, int* frame);

}  // namespace hp
