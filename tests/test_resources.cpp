// Resource bounds (issue 12): a long batch must not grow in memory frame by
// frame. The shot is run in-process one frame at a time through the real
// scheduler (runFrames) with the simulation + strand-cache and VDB stages, and
// the resident set is sampled from /proc/self/statm.
#include "pipeline/scene/scene.h"
#include "pipeline/stages/shot.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <fstream>
#include <unistd.h>

using namespace hp;

namespace {

/// Resident set size of this process, bytes (Linux /proc/self/statm).
double residentBytes() {
    std::ifstream statm("/proc/self/statm");
    long pages = 0, resident = 0;
    statm >> pages >> resident;
    return double(resident) * double(sysconf(_SC_PAGESIZE));
}

}  // namespace

TEST(Resources, ResidentMemoryDoesNotGrowOverThirtyFrames) {
    test::TempDir dir;
    const std::string head = test::sourcePath("scenes/assets/sphere.glb").string();
    // ~5000 strands × 24 vertices: a frame's strands are ~5 MB, so keeping
    // one frame's data per frame (the leak this test exists for) would grow
    // the process by ~100 MB over frames 10-30, far beyond the tolerance.
    const Scene scene = Scene::parse("frames: 1-30\nhead: {file: " + head +
                                         "}\nhair:\n  guides: {count: 100}\n  followers: {count: 5000}\n"
                                         "vdb: {enabled: true, voxel_size: 0.01}\n",
                                     "long.yaml", dir.path());
    RunOptions options;
    options.outputDir = dir / "out";
    ShotSettings shot = resolveShot(scene, options);
    std::vector<StagePtr> stages = makeStages(scene, shot, {"sim", "vdb"});
    ASSERT_EQ(stages.size(), 2u);
    shot.writesCache = true;
    std::unique_ptr<FrameSource> source = makeFrameSource(scene, shot);
    double at10 = 0, at30 = 0;
    for (int frame = 1; frame <= 30; ++frame) {
        ShotSettings one = shot;
        one.frames = {frame};
        const RunReport report = runFrames(*source, stages, one);
        ASSERT_TRUE(report.failures.empty()) << report.failures.front();
        if (frame == 10) at10 = residentBytes();
        if (frame == 30) at30 = residentBytes();
    }
    EXPECT_TRUE(std::filesystem::exists(dir / "out/cache/strands.0030.hpc"));
    // Allocator arenas and TBB's thread-local pools settle in the first
    // frames; after that growth must stay within a few MB.
    const double growth = at30 - at10;
    RecordProperty("rss_frame10_mb", int(at10 / 1e6));
    RecordProperty("rss_frame30_mb", int(at30 / 1e6));
    EXPECT_LT(growth, 16e6) << "resident set grew from " << at10 / 1e6 << " MB at frame 10 to " << at30 / 1e6
                            << " MB at frame 30";
}
