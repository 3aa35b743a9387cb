// Helpers shared by the test suites: temporary folders, shared assets, and
// running the hairpipe executable as a subprocess.
#pragma once

#include "core/errors.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace hp::test {

/// A fresh empty folder under the system temp dir, removed on destruction.
class TempDir {
  public:
    TempDir();
    ~TempDir();
    const std::filesystem::path& path() const { return path_; }
    std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

  private:
    std::filesystem::path path_;
};

/// Writes `text` to `path` (creating folders).
void writeFile(const std::filesystem::path& path, const std::string& text);
std::string readFile(const std::filesystem::path& path);

/// Path of a file in ../shared/assets, or empty if the folder is absent (a
/// user's clone): callers GTEST_SKIP with assetsMissingMessage().
std::filesystem::path sharedAsset(const std::string& name);
std::string assetsMissingMessage(const std::string& name);

/// Skips the current test unless the shared asset exists; evaluates to its path.
#define HP_REQUIRE_ASSET(var, name)                                                 \
    const std::filesystem::path var = ::hp::test::sharedAsset(name);              \
    if (var.empty()) GTEST_SKIP() << ::hp::test::assetsMissingMessage(name)

struct ProcessResult {
    int exitCode = -1;
    std::string output;  ///< stdout and stderr together
};

/// Runs a shell command; its exit code (-1 if it did not exit) and its
/// stdout and stderr together.
ProcessResult runShell(const std::string& command);

/// Runs the hairpipe executable with `args` (a shell-quoted string) in `cwd`.
ProcessResult runHairpipe(const std::string& args, const std::filesystem::path& cwd = {});

/// Source tree path ("scenes/default.yaml" -> absolute).
std::filesystem::path sourcePath(const std::string& relative);

/// Runs `action`, which should throw a SceneError, and returns the error; a
/// test failure naming `input` (and an empty error) if nothing was thrown.
template <typename Action>
SceneError sceneErrorOf(Action&& action, const std::string& input) {
    try {
        action();
    } catch (const SceneError& e) {
        return e;
    }
    ADD_FAILURE() << "no error for:\n" << input;
    return SceneError({}, "", "");
}

}  // namespace hp::test
