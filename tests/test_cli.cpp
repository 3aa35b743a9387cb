// The hairpipe executable run as a subprocess: exit codes and messages.
#include "test_support.h"

#include <gtest/gtest.h>

using namespace hp::test;

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
    const ProcessResult a = runHairpipe("frobnicate x.yaml");
    EXPECT_EQ(a.exitCode, 1);
    EXPECT_NE(a.output.find("unknown command 'frobnicate'"), std::string::npos) << a.output;
    const ProcessResult b = runHairpipe("validate --bogus x.yaml");
    EXPECT_EQ(b.exitCode, 1);
    EXPECT_NE(b.output.find("unknown option '--bogus'"), std::string::npos) << b.output;
}

TEST(Cli, ValidateBrokenScenePrintsLocationAndKey) {
    TempDir dir;
    writeFile(dir / "broken.yaml", "frames: 1-3\nfps: 24\nseed: -4\n");
    const ProcessResult r = runHairpipe("validate broken.yaml", dir.path());
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find("broken.yaml:3:7: 'seed': must be in [0, 2147483647]"), std::string::npos) << r.output;
}

TEST(Cli, ValidateGoodSceneAndSetOverride) {
    TempDir dir;
    writeFile(dir / "ok.yaml", "frames: 1-3\n");
    EXPECT_EQ(runHairpipe("validate ok.yaml", dir.path()).exitCode, 0);
    const ProcessResult bad = runHairpipe("validate ok.yaml --set fps=-1", dir.path());
    EXPECT_EQ(bad.exitCode, 1);
    EXPECT_NE(bad.output.find("--set fps=-1: 'fps': must be in"), std::string::npos) << bad.output;
}

TEST(Cli, MissingSceneFileIsNamed) {
    const ProcessResult r = runHairpipe("validate /nonexistent/scene.yaml");
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.output.find("/nonexistent/scene.yaml: scene file not found"), std::string::npos) << r.output;
}

TEST(Cli, BadFramesOption) {
    TempDir dir;
    writeFile(dir / "ok.yaml", "frames: 1-3\n");
    const ProcessResult r = runHairpipe("info ok.yaml --frames 5-1", dir.path());
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.output.find("bad frame range '5-1'"), std::string::npos) << r.output;
}

TEST(Cli, InfoShowsResolvedFramesAndKeys) {
    TempDir dir;
    writeFile(dir / "ok.yaml", "frames: 1-10x3\nfps: 30\n");
    const ProcessResult r = runHairpipe("info ok.yaml --seed 9", dir.path());
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("1-10x3 (4 frames at 30 fps)"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("seed: 9\n"), std::string::npos) << r.output;
}

TEST(Cli, ThreadsMustBePositive) {
    TempDir dir;
    writeFile(dir / "ok.yaml", "frames: 1\n");
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
