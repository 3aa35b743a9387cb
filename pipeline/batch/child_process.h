// Child processes for batch work: the frame-parallel chunks of `--jobs N`,
// the tasks of a local farm plan, and the Slurm client tools.
//
// Processes, not threads, because each chunk owns a GL context, an Embree
// device and its memory: a crash or a leak stays in one chunk, and the
// memory of N chunks is bounded by N processes. Children die with the parent
// (PR_SET_PDEATHSIG), so killing a batch never leaves orphans writing files.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace hp {

/// One command to run.
struct ChildTask {
    std::string label;                 ///< for messages ("frames 1-8")
    std::vector<std::string> argv;     ///< argv[0]: the program's path
    std::vector<std::string> env;      ///< extra or replaced variables, "NAME=value"
    /// Where stdout and stderr go (created, truncated); empty: they are read
    /// line by line and handed to the caller's onLine.
    std::filesystem::path log;
};

/// How a child ended.
struct ChildResult {
    int exitCode = -1;  ///< the exit status; -1 when killed by a signal or not started
    int signal = 0;     ///< the signal that ended it, or 0
    std::string error;  ///< why it could not be started, if so
    bool ok() const { return exitCode == 0; }
    /// "exit code 2", "killed by signal 9 (Killed)", or the start error.
    std::string describe() const;
};

/// Runs `tasks` in list order, at most `parallel` at once. `onLine(i, line)`
/// receives each output line of task i (tasks without a log file);
/// `onDone(i, result)` is called as each one ends. Returns every result.
/// A task that cannot be started fails with ChildResult::error set.
std::vector<ChildResult> runChildren(const std::vector<ChildTask>& tasks, int parallel,
                                     const std::function<void(size_t, const std::string&)>& onLine,
                                     const std::function<void(size_t, const ChildResult&)>& onDone);

/// Runs one command to its end and returns its result; its stdout and stderr
/// together go to `output` (for sbatch, squeue and the like).
ChildResult runCapture(const std::vector<std::string>& argv, std::string& output);

/// The running executable (/proc/self/exe), to start more of itself.
std::filesystem::path currentExecutable();

/// Finds `program` on PATH; empty when absent.
std::filesystem::path findProgram(const std::string& program);

/// Quotes `word` for a POSIX shell (single quotes unless it is plain).
std::string shellQuote(const std::string& word);

}  // namespace hp
