// Logging to stderr with three verbosity levels (-q, default, -v).
//
// Lines are written whole under a mutex so messages from TBB workers never
// interleave mid-line. The progress bar (pipeline/batch/progress.h) coordinates with
// this through clearProgressLine().
#pragma once

#include "core/errors.h"

#include <functional>
#include <string>

namespace hp {

enum class LogLevel { Quiet = 0, Normal = 1, Verbose = 2 };

void setLogLevel(LogLevel level);
LogLevel logLevel();

/// Writes one line to stderr if `level` is enabled.
void logLine(LogLevel level, const std::string& line);

/// Installs a hook called (under the log mutex) before each log line, used by
/// the progress bar to erase itself; pass nullptr to remove it.
void setLogPreLineHook(std::function<void()> hook);

template <typename... Args>
void logInfo(const Args&... args) { logLine(LogLevel::Normal, cat(args...)); }
template <typename... Args>
void logVerbose(const Args&... args) { logLine(LogLevel::Verbose, cat(args...)); }
/// Warnings and errors are shown even with -q.
template <typename... Args>
void logWarning(const Args&... args) { logLine(LogLevel::Quiet, cat("warning: ", args...)); }
template <typename... Args>
void logError(const Args&... args) { logLine(LogLevel::Quiet, cat("error: ", args...)); }

}  // namespace hp
