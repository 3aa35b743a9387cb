// The CLI's commands. Each returns its CommandSpec; commands() (commands.cpp)
// lists them. Shared helpers turn a command line into a scene and run options.
#pragma once

#include "pipeline/cli/cli.h"
#include "pipeline/stages/shot.h"

#include <functional>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace hp {

CommandSpec runCommandSpec();
CommandSpec renderCommandSpec();
CommandSpec simCommandSpec();
CommandSpec vdbCommandSpec();
CommandSpec validateCommandSpec();
CommandSpec infoCommandSpec();
CommandSpec helpCommandSpec();
CommandSpec compareCommandSpec();
CommandSpec viewCommandSpec();  // command_view.cpp
CommandSpec farmCommandSpec();       // command_farm.cpp
CommandSpec exportUsdCommandSpec();  // command_export_usd.cpp

/// A scene loaded from a command line (scene path, --set, --seed) with the
/// run options (--frames, --out, --force) and the --threads limit, which
/// holds while this object lives.
struct CommandContext {
    explicit CommandContext(const CommandLine& cl);
    ~CommandContext();
    Scene scene;
    RunOptions options;

  private:
    std::shared_ptr<void> threads_;  // a tbb::global_control, type-erased to keep TBB out of this header
};

/// @brief The integer value of `option` (--jobs, --threads, --chunk, ...);
/// throws UsageError naming the option and the range unless it is a whole
/// number in [lo, hi].
long integerOption(const CommandLine& cl, const std::string& option, long lo, long hi);

/// Runs the stages named in `only` (all enabled ones if empty) over the
/// shot's frames and reports; returns kExitOk or kExitFrameFailed.
int runShotCommand(const CommandContext& ctx, const std::set<std::string>& only);

/// @brief Which stages a shot command runs, from its loaded scene and its
/// command line; may throw UsageError for a scene the command cannot run.
using StageChoice = std::function<std::set<std::string>(const CommandContext&, const CommandLine&)>;

/// @brief The handler of a command that runs some of a shot's stages (run,
/// render, vdb): loads the scene from the command line, then runShotCommand
/// with the stages `choose` picks.
std::function<int(const CommandLine&)> runStages(StageChoice choose);

/// @brief --jobs N and --chunk N of a command that can run its frames in child
/// processes (parseBatchOptions reads them).
/// @param jobs   help of --jobs: what N child processes do at once
/// @param chunk  help of --chunk
std::vector<OptionSpec> jobOptions(const std::string& jobs, const std::string& chunk = "--jobs: frames per child process");

}  // namespace hp
