// Frame lists in the grammar artists know from oiiotool and Nuke:
//   "5"          one frame
//   "1-120"      an inclusive range
//   "1-120x2"    every second frame of a range (1, 3, 5, ...)
//   "3,7,10-20"  comma-separated items of the above
// Frames may be negative ("-5--1"). The result is sorted and unique.
#pragma once

#include <string>
#include <vector>

namespace hp {

/// Parses `text`; throws UsageError with the offending item on bad input.
std::vector<int> parseFrameRange(const std::string& text);

/// Formats a sorted frame list compactly ("1-10,12,20-30x5").
std::string formatFrameRange(const std::vector<int>& frames);

}  // namespace hp
