// The whole sequential part of a shot on the project's animated head: the
// head clip drives the guide solver, followers are rebuilt every frame.
#include "pipeline/scene/scene.h"
#include "pipeline/stages/shot_simulation.h"
#include "sim/collision/mesh_collider.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cstring>

using namespace hp;
namespace fs = std::filesystem;

namespace {

/// The default scene with a small groom (fast enough for a test).
Scene smallDefaultScene(std::vector<std::string> extra = {}) {
    std::vector<std::string> sets = {"hair.guides.count=60", "hair.followers.count=600", "frames=1-84"};
    sets.insert(sets.end(), extra.begin(), extra.end());
    return Scene::load(test::sourcePath("scenes/default.yaml"), sets);
}

bool sameBits(const StrandFrame& a, const StrandFrame& b) {
    return a.offsets == b.offsets && a.ids == b.ids && a.radii == b.radii && a.positions.size() == b.positions.size() &&
           std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Vec3f)) == 0 &&
           a.velocities.size() == b.velocities.size() &&
           std::memcmp(a.velocities.data(), b.velocities.data(), a.velocities.size() * sizeof(Vec3f)) == 0;
}

}  // namespace

TEST(ShotSimulation, DefaultClipKeepsLengthsRootsAndClearance) {
    const Scene scene = smallDefaultScene();
    ShotSimulation sim(scene, 24.0, 1);
    ASSERT_EQ(sim.guideCount(), 60u);
    ASSERT_EQ(sim.followerCount(), 600u);
    const float segment = float(scene.number("hair.guides.length") / scene.integer("hair.guides.segments"));
    double worstLength = 0, deepest = 0, worstRoot = 0;
    for (int frame = 2; frame <= 84; frame += 2) {
        const StrandFrame& f = sim.advanceTo(frame);
        ASSERT_NO_THROW(f.validate());
        ASSERT_EQ(f.strandCount(), 660u);
        EXPECT_EQ(sim.stats().guides.nanCount, 0u);
        // Exact distance to the deformed head, not the solver's own collider.
        const MeshCollider exact(sim.pose().mesh);
        for (size_t s = 0; s < f.guideCount; ++s) {
            for (uint32_t v = f.first(s) + 1; v < f.first(s) + f.vertexCount(s); ++v) {
                const float len = (f.positions[v] - f.positions[v - 1]).norm();
                worstLength = std::max(worstLength, double(std::abs(len / segment - 1.f)));
                deepest = std::max(deepest, double(-exact.signedDistance(f.positions[v])));
            }
            worstRoot = std::max(worstRoot, double(exact.signedDistance(f.positions[f.first(s)])));
        }
    }
    EXPECT_LE(worstLength, 0.001) << "segment length error over the clip (issue 4: <= 0.1%)";
    EXPECT_LE(deepest, 0.001) << "deepest guide vertex inside the head over the default clip (goal: none deeper than 1 mm)";
    EXPECT_LE(worstRoot, 1e-5 * 0.3) << "roots ride the deformed surface";
}

TEST(ShotSimulation, HairHangsAndMovesWithTheHead) {
    const Scene scene = smallDefaultScene();
    ShotSimulation sim(scene, 24.0, 1);
    const StrandFrame first = sim.advanceTo(1);
    // The combed groom holds still at the first frame (pre-loaded springs).
    const StrandFrame second = sim.advanceTo(2);
    double moved = 0;
    for (size_t v = 0; v < first.positions.size(); ++v)
        moved = std::max(moved, double((first.positions[v] - second.positions[v]).norm()));
    // The clip starts nodding at once, so the hair moves, but by millimetres, not a collapse.
    EXPECT_LT(moved, 0.02) << "largest vertex motion in the first frame";
    // During the clip the strands move with the head.
    double maxSpeed = 0;
    for (int frame = 3; frame <= 84; ++frame)
        for (const Vec3f& v : sim.advanceTo(frame).velocities) maxSpeed = std::max(maxSpeed, double(v.norm()));
    EXPECT_GT(maxSpeed, 0.2) << "strands move with the head";
    EXPECT_LT(maxSpeed, 20.0) << "no explosion";
}

TEST(ShotSimulation, IdenticalForOneAndTwoThreads) {
    const Scene scene = smallDefaultScene();
    StrandFrame one, two;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        ShotSimulation sim(scene, 24.0, 1);
        one = sim.advanceTo(30);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        ShotSimulation sim(scene, 24.0, 1);
        two = sim.advanceTo(30);
    }
    EXPECT_TRUE(sameBits(one, two));
}

TEST(ShotSimulation, CheckpointRestoreContinuesBitForBit) {
    for (const char* model : {"rigid-chain", "curly-wet"}) {
        SCOPED_TRACE(model);
        const Scene scene = smallDefaultScene({std::string("hair.model=") + model});
        test::TempDir dir;
        ShotSimulation a(scene, 24.0, 1);
        const StrandFrame at10 = a.advanceTo(10);
        a.saveCheckpoint(dir / "c.bin");
        const StrandFrame at20 = a.advanceTo(20);

        ShotSimulation b(scene, 24.0, 1);
        b.restoreCheckpoint(dir / "c.bin", at10);
        EXPECT_EQ(b.frame(), 10);
        EXPECT_TRUE(sameBits(b.advanceTo(20), at20));
    }
}

TEST(ShotSimulation, CheckpointMismatchIsAClearError) {
    const Scene scene = smallDefaultScene();
    test::TempDir dir;
    ShotSimulation a(scene, 24.0, 1);
    const StrandFrame at5 = a.advanceTo(5);
    a.saveCheckpoint(dir / "c.bin");
    StrandFrame wrong = at5;
    wrong.frame = 6;
    ShotSimulation b(scene, 24.0, 1);
    EXPECT_THROW(b.restoreCheckpoint(dir / "c.bin", wrong), AssetError);
    test::writeFile(dir / "bad.bin", "garbage");
    EXPECT_THROW(b.restoreCheckpoint(dir / "bad.bin", at5), AssetError);
}

TEST(ShotSimulation, CurlyWetModelRunsThroughTheDriver) {
    const Scene scene = Scene::load(test::sourcePath("scenes/curly_wet.yaml"),
                                    {"hair.guides.count=20", "hair.followers.count=100"});
    ShotSimulation sim(scene, scene.number("fps"), scene.frames("frames").front());
    const StrandFrame& f = sim.advanceTo(13);
    EXPECT_NO_THROW(f.validate());
    EXPECT_EQ(f.guideCount, 20u);
    // The scene's saturation curve is [[1, 0], [24, 0], [40, 1], ...] over
    // frames, times a root-to-tip profile (0.4 at the root, 1 at the tip):
    // the driver must hand the solver σ = curve(frame) · profile.
    EXPECT_EQ(sim.stats().saturation, 0.0) << "dry until frame 24";
    sim.advanceTo(32);
    const double half = sim.stats().saturation;
    sim.advanceTo(40);
    const double soaked = sim.stats().saturation;
    EXPECT_GT(soaked, 0.4) << "the profile is at least 0.4 (the root) everywhere";
    EXPECT_LT(soaked, 1.0) << "and below 1 except at the tip";
    EXPECT_NEAR(half / soaked, 0.5, 0.01) << "frame 32 is halfway up the curve";
}
