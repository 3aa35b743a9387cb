// The hairpipe executable run as a subprocess: exit codes and messages.
#include "test_support.h"

#include <gtest/gtest.h>

using namespace hp::test;

namespace {

/// A temporary folder holding one scene file.
struct SceneDir {
    TempDir dir;
    SceneDir(const std::string& name, const std::string& yaml) { writeFile(dir / name, yaml); }
    const std::filesystem::path& path() const { return dir.path(); }
};

/// Runs `hairpipe args` in `cwd` and checks that it fails as a usage or
/// scene error (exit 1) whose output contains `message`.
void expectUsageError(const std::string& args, const std::string& message, const std::filesystem::path& cwd = {}) {
    SCOPED_TRACE("hairpipe " + args);
    const ProcessResult r = runHairpipe(args, cwd);
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << r.output;
}

}  // namespace

TEST(Cli, HelpListsCommands) {
    const ProcessResult r = runHairpipe("--help");
    EXPECT_EQ(r.exitCode, 0) << r.output;
    for (const char* cmd : {"run", "validate", "info"}) EXPECT_NE(r.output.find(cmd), std::string::npos) << cmd;
}

TEST(Cli, EveryCommandHasHelp) {
    for (const char* cmd : {"run", "validate", "info", "help"}) {
        const ProcessResult r = runHairpipe(std::string(cmd) + " --help");
        EXPECT_EQ(r.exitCode, 0) << cmd << ": " << r.output;
        EXPECT_NE(r.output.find("usage: hairpipe " + std::string(cmd)), std::string::npos) << r.output;
    }
}

TEST(Cli, NoArgumentsIsAUsageError) { EXPECT_EQ(runHairpipe("").exitCode, 1); }

TEST(Cli, UnknownCommandAndOption) {
    expectUsageError("frobnicate x.yaml", "unknown command 'frobnicate'");
    expectUsageError("validate --bogus x.yaml", "unknown option '--bogus'");
}

TEST(Cli, ValidateBrokenScenePrintsLocationAndKey) {
    const SceneDir dir("broken.yaml", "frames: 1-3\nfps: 24\nseed: -4\n");
    expectUsageError("validate broken.yaml", "broken.yaml:3:7: 'seed': must be in [0, 2147483647]", dir.path());
}

TEST(Cli, ValidateGoodSceneAndSetOverride) {
    const SceneDir dir("ok.yaml", "frames: 1-3\n");
    EXPECT_EQ(runHairpipe("validate ok.yaml", dir.path()).exitCode, 0);
    expectUsageError("validate ok.yaml --set fps=-1", "--set fps=-1: 'fps': must be in", dir.path());
}

TEST(Cli, MissingSceneFileIsNamed) {
    expectUsageError("validate /nonexistent/scene.yaml", "/nonexistent/scene.yaml: scene file not found");
}

TEST(Cli, BadFramesOption) {
    const SceneDir dir("ok.yaml", "frames: 1-3\n");
    expectUsageError("info ok.yaml --frames 5-1", "bad frame range '5-1'", dir.path());
}

TEST(Cli, InfoShowsResolvedFramesAndKeys) {
    const SceneDir dir("ok.yaml", "frames: 1-10x3\nfps: 30\n");
    const ProcessResult r = runHairpipe("info ok.yaml --seed 9", dir.path());
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("1-10x3 (4 frames at 30 fps)"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("seed: 9\n"), std::string::npos) << r.output;
}

TEST(Cli, ThreadsMustBePositive) {
    const SceneDir dir("ok.yaml", "frames: 1\n");
    EXPECT_EQ(runHairpipe("validate ok.yaml --threads 0", dir.path()).exitCode, 1);
    EXPECT_EQ(runHairpipe("validate ok.yaml --threads 2", dir.path()).exitCode, 0);
}

TEST(Cli, EveryBundledSceneValidates) {
    size_t count = 0;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(sourcePath("scenes"))) {
        if (entry.path().extension() != ".yaml") continue;
        ++count;
        const ProcessResult r = runHairpipe("validate '" + entry.path().string() + "'");
        EXPECT_EQ(r.exitCode, 0) << entry.path() << ":\n" << r.output;
    }
    EXPECT_GE(count, 7u) << "default, curly_wet and the Table 5.1 rows";
}
