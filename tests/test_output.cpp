#include "core/errors.h"
#include "pipeline/batch/output.h"
#include "pipeline/stages/shot.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <fstream>

using namespace hp;
namespace fs = std::filesystem;

TEST(AtomicWrite, WritesThroughATemporaryWithTheSameExtension) {
    test::TempDir dir;
    const fs::path final = dir / "sub/frame.0001.exr";
    fs::path seen;
    writeAtomically(final, [&](const fs::path& tmp) {
        seen = tmp;
        EXPECT_EQ(tmp.extension(), ".exr");
        EXPECT_EQ(tmp.parent_path(), final.parent_path());
        EXPECT_FALSE(fs::exists(final)) << "final name must not exist while writing";
        test::writeFile(tmp, "data");
    });
    EXPECT_EQ(test::readFile(final), "data");
    EXPECT_FALSE(fs::exists(seen));
}

TEST(AtomicWrite, FailureLeavesNothing) {
    test::TempDir dir;
    const fs::path final = dir / "frame.0001.png";
    EXPECT_THROW(writeAtomically(final,
                                 [&](const fs::path& tmp) {
                                     test::writeFile(tmp, "partial");
                                     throw IoError(tmp.string(), "disk full");
                                 }),
                 IoError);
    EXPECT_FALSE(fs::exists(final));
    EXPECT_TRUE(fs::is_empty(dir.path())) << "the temporary file must be removed";
}

TEST(AtomicWrite, WriterThatProducesNothingIsAnError) {
    test::TempDir dir;
    EXPECT_THROW(writeAtomically(dir / "x.png", [](const fs::path&) {}), IoError);
}

TEST(AtomicWrite, UncreatableFolderIsReported) {
    // A regular file where the output folder should be: fails even for root.
    test::TempDir dir;
    test::writeFile(dir / "blocker", "x");
    try {
        writeAtomically(dir / "blocker/sub/x.txt", [](const fs::path& p) { test::writeFile(p, "x"); });
        FAIL() << "no error";
    } catch (const IoError& e) {
        EXPECT_NE(std::string(e.what()).find("cannot create folder"), std::string::npos) << e.what();
    }
}

TEST(AtomicWrite, AllExistIgnoresEmptyAndMissingFiles) {
    test::TempDir dir;
    test::writeFile(dir / "a", "x");
    test::writeFile(dir / "empty", "");
    EXPECT_TRUE(allExist({dir / "a"}));
    EXPECT_FALSE(allExist({dir / "a", dir / "b"}));
    EXPECT_FALSE(allExist({dir / "empty"}));
}

namespace {

/// A stage that writes one text file per frame and counts its runs.
class CountingStage final : public FrameStage {
  public:
    CountingStage(fs::path dir, std::set<int> failOn = {}) : dir_(std::move(dir)), failOn_(std::move(failOn)) {}
    std::string name() const override { return "count"; }
    std::vector<fs::path> outputs(int frame) const override { return {dir_ / ("f." + std::to_string(frame))}; }
    void run(const FrameData& d) override {
        ++runs;
        if (failOn_.count(d.frame)) throw FrameError("boom");
        writeAtomically(outputs(d.frame)[0], [&](const fs::path& p) { test::writeFile(p, std::to_string(d.frame)); });
    }
    int runs = 0;

  private:
    fs::path dir_;
    std::set<int> failOn_;
};

class NullSource final : public FrameSource {
  public:
    FrameData get(int frame) override {
        ++calls;
        FrameData data;
        data.frame = frame;
        data.time = frame / 24.0;
        return data;
    }
    int calls = 0;
};

}  // namespace

TEST(Scheduler, ResumeSkipsExistingFramesAndIgnoresStaleTemporaries) {
    test::TempDir dir;
    test::writeFile(dir / "f.2", "2");                                   // finished earlier
    test::writeFile(dir / (std::string(kTemporaryPrefix) + "999-0-f.3"), "half");  // interrupted
    std::vector<StagePtr> stages;
    stages.push_back(std::make_unique<CountingStage>(dir.path()));
    auto* stage = static_cast<CountingStage*>(stages[0].get());
    ShotSettings shot;
    shot.frames = {1, 2, 3};
    NullSource source;
    const RunReport r = runFrames(source, stages, shot);
    EXPECT_EQ(stage->runs, 2);
    EXPECT_EQ(r.outputsSkipped, 1u);
    EXPECT_EQ(source.calls, 2) << "a fully written frame needs no frame data";
    EXPECT_EQ(test::readFile(dir / "f.3"), "3");

    shot.force = true;
    runFrames(source, stages, shot);
    EXPECT_EQ(stage->runs, 5) << "--force reruns every frame";
}

TEST(Scheduler, AFailedFrameDoesNotStopTheOthers) {
    test::TempDir dir;
    std::vector<StagePtr> stages;
    stages.push_back(std::make_unique<CountingStage>(dir.path(), std::set<int>{2}));
    ShotSettings shot;
    shot.frames = {1, 2, 3};
    NullSource source;
    const RunReport r = runFrames(source, stages, shot);
    ASSERT_EQ(r.failures.size(), 1u);
    EXPECT_NE(r.failures[0].find("frame 2 count: boom"), std::string::npos) << r.failures[0];
    EXPECT_TRUE(fs::exists(dir / "f.1"));
    EXPECT_FALSE(fs::exists(dir / "f.2"));
    EXPECT_TRUE(fs::exists(dir / "f.3"));
}
