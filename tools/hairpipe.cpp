// hairpipe: the command-line entry point. All work happens in the libraries;
// this file only maps errors to exit codes (0 ok, 1 usage/scene/asset error,
// 2 some frame failed).
#include "core/log.h"
#include "pipeline/cli/cli.h"

#include <exception>
#include <string>
#include <vector>

int main(int argc, char** argv) {
    try {
        return hp::runCli(std::vector<std::string>(argv + 1, argv + argc));
    } catch (const hp::Error& e) {
        hp::logError(e.what());
        return hp::kExitUsage;
    } catch (const std::exception& e) {
        hp::logError("internal error: ", e.what());
        return hp::kExitUsage;
    }
}
