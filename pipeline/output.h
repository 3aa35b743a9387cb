// Output files that never exist half-written.
//
// Every frame file is written to a temporary name in the same folder (so the
// rename is atomic on one filesystem) and renamed over the final name once
// complete. An interrupted batch therefore leaves either the finished file or
// a stale ".hairpipe-tmp-*" file that resume logic ignores.
#pragma once

#include <filesystem>
#include <functional>
#include <vector>

namespace hp {

/// Prefix of temporary files; anything starting with it is never an output.
inline constexpr const char* kTemporaryPrefix = ".hairpipe-tmp-";

/// A unique temporary path beside `final` that keeps its extension (image
/// writers choose the format from it).
std::filesystem::path temporaryPath(const std::filesystem::path& final);

/// Creates the parent folder, calls `write(temporary)`, checks the file is
/// there and renames it to `final`. On any failure the temporary is removed
/// and the error re-thrown (IoError for filesystem failures).
void writeAtomically(const std::filesystem::path& final,
                     const std::function<void(const std::filesystem::path&)>& write);

/// @brief Creates `dir` (and its parents) and proves it writable by creating
/// and removing a probe file; throws IoError naming the folder otherwise.
/// Run before the first frame, so an unwritable output folder is one clear
/// error (exit code 1) instead of the same failure on every frame.
void checkOutputDirectory(const std::filesystem::path& dir);

/// True when every path exists as a non-empty regular file.
bool allExist(const std::vector<std::filesystem::path>& paths);

}  // namespace hp
