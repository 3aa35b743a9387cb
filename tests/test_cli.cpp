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

#include "render/image/image_io.h"

#include <algorithm>

// Every shipped scene renders with the default look (the render keys'
// defaults, pipeline/scene/keys/render.yaml): the preview of its first frame
// is a 560x720 portrait, opaque over the gradient backdrop (lighter at the
// top), with the head and its hair framed tightly by the follow camera. Kept
// small: a two-frame clip of 20 guides and 200 followers, no settling.
TEST(Cli, EveryBundledSceneRendersWithTheDefaultLook) {
    TempDir out;
    size_t count = 0;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(sourcePath("scenes"))) {
        if (entry.path().extension() != ".yaml") continue;
        ++count;
        const std::string name = entry.path().stem().string() + std::to_string(count);
        SCOPED_TRACE(entry.path().string());
        const ProcessResult r = runHairpipe(
            "render --preview '" + entry.path().string() + "' --out '" + (out / name).string() + "'" +
            " --frames 1 --set frames=1-2 --set hair.guides.count=20 --set hair.followers.count=200"
            " --set hair.groom.settle=0");
        ASSERT_EQ(r.exitCode, 0) << r.output;
        const hp::Image png = hp::readImage((out / name / "preview/preview.0001.png").string());
        ASSERT_EQ(png.width, 560);
        ASSERT_EQ(png.height, 720);
        ASSERT_EQ(png.channelCount(), 4);
        float alpha = 1.f;
        for (int y = 0; y < png.height; ++y)
            for (int x = 0; x < png.width; ++x) alpha = std::min(alpha, png.at(x, y, 3));
        EXPECT_EQ(alpha, 1.f) << "the backdrop fills the display image";
        // The EXR keeps coverage in alpha: where the head and hair are.
        const hp::Image exr = hp::readImage((out / name / "preview/preview.0001.exr").string());
        const int a = exr.channelIndex("A");
        ASSERT_GE(a, 0);
        int top = exr.height, bottom = -1, left = exr.width, right = -1;
        for (int y = 0; y < exr.height; ++y)
            for (int x = 0; x < exr.width; ++x)
                if (exr.at(x, y, a) > 0.02f) {
                    top = std::min(top, y), bottom = std::max(bottom, y);
                    left = std::min(left, x), right = std::max(right, x);
                }
        ASSERT_GE(bottom, 0) << "nothing drawn";
        // A background pixel (no coverage) at the top is lighter than one at the bottom.
        if (exr.at(0, 0, a) == 0.f && exr.at(0, exr.height - 1, a) == 0.f) {
            EXPECT_GT(png.at(0, 0, 0), png.at(0, png.height - 1, 0)) << "gradient backdrop";
        }
        // Follow framing fits the head and hair to the frame with a margin of
        // 0.04 of the half-frame on each side: along one axis at least, the
        // drawn bounds span most of the frame (1 - 2 x 0.04 = 0.92 when the
        // fit is centred; 0.85 leaves room for thin, faint strand tips).
        const double span = std::max(double(bottom - top + 1) / exr.height, double(right - left + 1) / exr.width);
        EXPECT_GT(span, 0.85) << "rows " << top << "-" << bottom << ", columns " << left << "-" << right;
    }
    EXPECT_GE(count, 7u) << "default, curly_wet, stress and the Table 5.1 rows";
}
