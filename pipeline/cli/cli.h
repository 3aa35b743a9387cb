// The `hairpipe` command line: option parsing and the commands. tools/
// hairpipe.cpp is a thin main that calls runCli and maps errors to exit codes.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace hp {

/// Exit codes of the hairpipe executable.
enum ExitCode { kExitOk = 0, kExitUsage = 1, kExitFrameFailed = 2 };

/// A parsed command line.
struct CommandLine {
    std::string command;
    std::vector<std::string> positional;
    std::map<std::string, std::vector<std::string>> values;  ///< option -> values (repeatable)
    bool has(const std::string& option) const { return values.count(option) > 0; }
    /// The last value of an option, or `fallback`.
    std::string value(const std::string& option, const std::string& fallback = "") const;
};

struct OptionSpec {
    std::string name;      ///< "--frames"
    std::string argument;  ///< "RANGE"; empty for a flag
    std::string help;
};

/// @brief A command: its help text, options and handler. Each command's
/// function (commands.h) writes `CommandSpec c{name, usage, summary};` and
/// sets what else it has.
struct CommandSpec {
    CommandSpec(std::string commandName, std::string usageLine, std::string summaryLine)
        : name(std::move(commandName)), usage(std::move(usageLine)), summary(std::move(summaryLine)) {}
    std::string name;
    std::string usage;     ///< "[options] scene.yaml"
    std::string summary;
    std::string details;   ///< extra text for --help
    std::vector<OptionSpec> options;  ///< besides the common ones
    bool sceneOptions = true;         ///< takes --frames, --set, --out, ...
    std::function<int(const CommandLine&)> run;
};

/// All commands, in help order.
const std::vector<CommandSpec>& commands();

/// Parses argv (without argv[0]) for a command; throws UsageError.
CommandLine parseCommandLine(const std::vector<std::string>& args);

/// Runs a command line; returns the exit code (0 or 2), throws hp::Error on
/// usage/scene/asset errors (exit code 1, mapped by main).
int runCli(const std::vector<std::string>& args);

/// Text of `hairpipe --help` and `hairpipe <command> --help`.
std::string generalHelp();
std::string commandHelp(const CommandSpec& command);

}  // namespace hp
