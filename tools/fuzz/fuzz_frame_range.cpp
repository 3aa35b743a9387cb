// libFuzzer target: the --frames / <stage>.frames grammar (pipeline/batch/frame_range.h).
// Any input must either parse into a sorted unique list that formats and
// re-parses to itself, or throw UsageError; anything else is a bug.
#include "tools/fuzz/fuzz_target.h"

#include "core/errors.h"
#include "pipeline/batch/frame_range.h"

#include <string>
#include <vector>

HP_FUZZ_TARGET(frame_range)(const uint8_t* data, size_t size) {
    if (size > 4096) return -1;  // a frame list is a command-line argument
    const std::string text(reinterpret_cast<const char*>(data), size);
    std::vector<int> frames;
    try {
        frames = hp::parseFrameRange(text);
    } catch (const hp::UsageError&) {
        return 0;
    }
    HP_FUZZ_CHECK(!frames.empty());
    for (size_t i = 1; i < frames.size(); ++i) HP_FUZZ_CHECK(frames[i - 1] < frames[i]);
    HP_FUZZ_CHECK(hp::parseFrameRange(hp::formatFrameRange(frames)) == frames);
    return 0;
}
