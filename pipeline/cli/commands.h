// The CLI's commands. Each returns its CommandSpec; commands() (commands.cpp)
// lists them. Shared helpers turn a command line into a scene and run options.
#pragma once

#include "pipeline/cli/cli.h"
#include "pipeline/stages/shot.h"

#include <memory>

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

/// Runs the stages named in `only` (all enabled ones if empty) over the
/// shot's frames and reports; returns kExitOk or kExitFrameFailed.
int runShotCommand(const CommandContext& ctx, const std::set<std::string>& only);

}  // namespace hp
