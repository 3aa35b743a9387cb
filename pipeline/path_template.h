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

}  // namespace hp
