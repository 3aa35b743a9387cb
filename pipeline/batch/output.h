// Output files that never exist half-written.
//
// Every frame file is written to a temporary name in the same folder (so the
// rename is atomic on one filesystem) and renamed over the final name once
// complete. An interrupted batch therefore leaves either the finished file or
// a stale ".hairpipe-tmp-*" file that resume logic ignores and the next run
// on the same host removes (removeStaleTemporaries).
#pragma once

#include <filesystem>
#include <functional>
#include <set>
#include <string>
#include <vector>

namespace hp {

/// Prefix of temporary files; anything starting with it is never an output.
inline constexpr const char* kTemporaryPrefix = ".hairpipe-tmp-";

/// A unique temporary path beside `final` that keeps its extension (image
/// writers choose the format from it): ".hairpipe-tmp-<pid>-<n>@<host>@<name>".
/// The writer's process id and host name let a later run tell a stale file
/// (its writer is gone) from one another process is still writing, also on
/// shared storage that several farm nodes write to.
std::filesystem::path temporaryPath(const std::filesystem::path& final);

/// Creates the parent folder, calls `write(temporary)`, checks the file is
/// there and renames it to `final`. On any failure the temporary is removed
/// and the error re-thrown (IoError for filesystem failures; one that names
/// the temporary is re-thrown naming `final`).
void writeAtomically(const std::filesystem::path& final,
                     const std::function<void(const std::filesystem::path&)>& write);

/// writeAtomically for a text file: writes `text` (and, with `executable`,
/// adds the execute bits), checking the stream after it is closed, when
/// buffered bytes reach the disk.
void writeTextAtomically(const std::filesystem::path& final, const std::string& text, bool executable = false);

/// @brief Creates `dir` (and its parents) and proves it writable by creating
/// and removing a probe file; throws IoError naming the folder otherwise.
/// Run before the first frame, so an unwritable output folder is one clear
/// error (exit code 1) instead of the same failure on every frame.
void checkOutputDirectory(const std::filesystem::path& dir);

/// True when every path exists as a non-empty regular file.
bool allExist(const std::vector<std::filesystem::path>& paths);

/// True when `path`'s file name starts with kTemporaryPrefix.
bool isTemporary(const std::filesystem::path& path);

/// The temporaries (see temporaryPath) directly inside `folders` (missing
/// folders are skipped).
std::vector<std::filesystem::path> findTemporaries(const std::set<std::filesystem::path>& folders);

/// Removes the temporaries in `folders` whose writer is gone: written on this
/// host by a process that no longer runs (a killed run). Temporaries of other
/// hosts, of live processes, and of unknown origin are kept, so concurrent
/// runs on shared storage never lose a file being written. Returns how many
/// were removed.
size_t removeStaleTemporaries(const std::set<std::filesystem::path>& folders);

}  // namespace hp
