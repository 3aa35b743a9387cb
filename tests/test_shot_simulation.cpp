// The whole sequential part of a shot on the project's animated head: the
// head clip drives the guide solver, followers are rebuilt every frame.
#include "pipeline/scene/scene.h"
#include "pipeline/stages/shot_simulation.h"
#include "sim/collision/mesh_collider.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

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
    float extent = 0.f;  // largest coordinate magnitude of a guide vertex
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
                extent = std::max(extent, f.positions[v].cwiseAbs().maxCoeff());
                deepest = std::max(deepest, double(-exact.signedDistance(f.positions[v])));
            }
            worstRoot = std::max(worstRoot, double(exact.signedDistance(f.positions[f.first(s)])));
        }
    }
    // The rod places every vertex at its rest length (the goal was 0.1%):
    // what is left is float rounding, a couple of ulps of the coordinates
    // (up to `extent`) over a segment. Measured 2.0e-6; the bound is ~1e-5.
    RecordProperty("worst_length_error_e9", int(worstLength * 1e9));
    EXPECT_LE(worstLength, 2.0 * std::numeric_limits<float>::epsilon() * extent / segment)
        << "segment length error over the clip";
    EXPECT_LE(deepest, 0.001) << "deepest guide vertex inside the head over the default clip (goal: none deeper than 1 mm)";
    EXPECT_LE(worstRoot, 1e-5 * 0.3) << "roots ride the deformed surface";
}

namespace {

/// Guide vertices of `f` in the head's rest frame (the pose's rigid part undone).
std::vector<Vec3f> guidesInHeadFrame(const StrandFrame& f, const HeadPose& pose) {
    const Eigen::Isometry3f toHead = pose.transform.inverse();
    std::vector<Vec3f> out;
    for (size_t s = 0; s < f.guideCount; ++s)
        for (uint32_t v = f.first(s); v < f.first(s) + f.vertexCount(s); ++v) out.push_back(toHead * f.positions[v]);
    return out;
}

float largestDistance(const std::vector<Vec3f>& a, const std::vector<Vec3f>& b) {
    float d = 0.f;
    for (size_t i = 0; i < a.size(); ++i) d = std::max(d, (a[i] - b[i]).norm());
    return d;
}

float meanDistance(const std::vector<Vec3f>& a, const std::vector<Vec3f>& b) {
    double d = 0;
    for (size_t i = 0; i < a.size(); ++i) d += double((a[i] - b[i]).norm());
    return float(d / double(std::max<size_t>(1, a.size())));
}

}  // namespace

TEST(ShotSimulation, HairHangsUnderGravityAndSwingsWithTheHead) {
    const Scene scene = smallDefaultScene({"frames=1-120"});
    const float length = float(scene.number("hair.guides.length"));
    // Hangs: the settled groom, pre-loaded without a bound
    // (simulation.preload_limit 0), is an equilibrium under gravity: on a
    // head held still (clip_speed 0) it stays where it is; without the
    // pre-load the same groom sags, so the test can tell the two apart. The
    // default bound (1.5/ℓ_b per joint) lets the crown strands that the
    // settling left standing fall onto the head and the rest sag part way:
    // the guide vertices' mean motion in 1 s is measured at 7.2 mm against
    // the unloaded groom's 24.9 mm; the test asks for at most half of it, so
    // a bound that held little would fail.
    struct Drift {
        float largest, mean;
    };
    auto drift = [&](std::vector<std::string> sets) {
        sets.push_back("head.clip_speed=0");
        ShotSimulation still(smallDefaultScene(sets), 24.0, 1);
        const std::vector<Vec3f> at1 = guidesInHeadFrame(still.advanceTo(1), still.pose());
        const std::vector<Vec3f> at24 = guidesInHeadFrame(still.advanceTo(24), still.pose());
        return Drift{largestDistance(at1, at24), meanDistance(at1, at24)};
    };
    const Drift exact = drift({"simulation.preload_limit=0"}), bounded = drift({}),
                sagged = drift({"simulation.preload=false"});
    RecordProperty("still_head_drift_um", int(exact.largest * 1e6f));
    RecordProperty("bounded_mean_drift_um", int(bounded.mean * 1e6f));
    RecordProperty("bounded_largest_drift_um", int(bounded.largest * 1e6f));
    RecordProperty("no_preload_sag_um", int(sagged.largest * 1e6f));
    RecordProperty("no_preload_mean_sag_um", int(sagged.mean * 1e6f));
    // Held: less than the clearance the solver keeps from the head
    // (hair.guides.collision_radius, 1 mm; measured 0.06 mm). Sagged: the
    // unbalanced weight bends the groom by centimetres (measured 53 mm).
    const float clearance = float(scene.number("hair.guides.collision_radius"));
    EXPECT_LT(exact.largest, clearance) << "pre-loaded hair on a still head, 1 s";
    EXPECT_GT(sagged.largest, 10.f * clearance) << "without the pre-load the groom sags under gravity";
    EXPECT_LT(bounded.mean, 0.5f * sagged.mean) << "the bounded pre-load no longer holds the groom";
    // And it hangs: the guides' tips are, on average, more than half their
    // length below their roots (measured 0.71 L; a groom standing up or
    // lying flat would be at ≤ 0).
    ShotSimulation sim(scene, 24.0, 1);
    const StrandFrame& first = sim.advanceTo(1);
    const Vec3f down = Vec3f(scene.vec3f("simulation.gravity")).normalized();
    double meanDrop = 0;
    for (size_t s = 0; s < first.guideCount; ++s) {
        const Vec3f rootToTip = first.positions[first.first(s) + first.vertexCount(s) - 1] - first.positions[first.first(s)];
        meanDrop += rootToTip.dot(down) / double(first.guideCount);
    }
    RecordProperty("mean_tip_drop_mm", int(meanDrop * 1e3));
    EXPECT_GT(meanDrop, 0.5 * length) << "the tips hang below the roots";

    // Swings with the head: in the head's frame the hair lags behind the
    // nods, shakes and the turn (a rigid copy of the head would not move
    // there at all): the fast turn (375°/s) sweeps the tips by more than
    // half their length (measured 1.4 L). The clip holds still from 2.85 s
    // (frame 70) on, and the drag (3/s on velocity) damps a free swing as
    // e^(-3t/2): at frame 120, 2.1 s later, e^-3.1 ≈ 4.5% of its speed is
    // left; hair still sliding off the head and shoulders adds to that
    // (measured 6.8%), so the bound is 10%.
    const std::vector<Vec3f> rest = guidesInHeadFrame(first, sim.pose());
    float swing = 0.f, peakSpeed = 0.f;
    auto guideSpeed = [](const StrandFrame& f) {
        float v = 0.f;
        for (uint32_t i = 0; i < f.offsets[f.guideCount]; ++i) v = std::max(v, f.velocities[i].norm());
        return v;
    };
    for (int frame = 2; frame <= 70; ++frame) {
        const StrandFrame& f = sim.advanceTo(frame);
        peakSpeed = std::max(peakSpeed, guideSpeed(f));
        swing = std::max(swing, largestDistance(rest, guidesInHeadFrame(f, sim.pose())));
    }
    const float endSpeed = guideSpeed(sim.advanceTo(120));
    RecordProperty("swing_mm", int(swing * 1e3f));
    RecordProperty("peak_speed_mm_s", int(peakSpeed * 1e3f));
    RecordProperty("end_speed_mm_s", int(endSpeed * 1e3f));
    EXPECT_GT(swing, 0.5f * length) << "the hair swings relative to the head";
    EXPECT_LT(swing, 2.f * length) << "within its own reach, no explosion";
    EXPECT_LT(endSpeed, 0.1f * peakSpeed) << "and comes to rest once the head holds still";
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

namespace {

/// The share of frame f's strands (guides and followers) whose highest vertex
/// stands more than `rise` above its root along world up (+y).
double standingShare(const StrandFrame& f, float rise) {
    size_t standing = 0;
    for (size_t s = 0; s < f.strandCount(); ++s) {
        const uint32_t first = f.first(s), n = f.vertexCount(s);
        float top = f.positions[first].y();
        for (uint32_t i = 1; i < n; ++i) top = std::max(top, f.positions[first + i].y());
        standing += top - f.positions[first].y() > rise ? 1 : 0;
    }
    return f.strandCount() ? double(standing) / double(f.strandCount()) : 0.0;
}

}  // namespace

TEST(ShotSimulation, DefaultShotCrownHairDoesNotStandMidShakeOrTurned) {
    // Issue 29's criterion on the whole default shot (300 guides, 30 000
    // followers, the default pre-load): at most 1% of the strands stand more
    // than 2 cm above their root on frame 36 (mid-shake) and frame 84 (the
    // head turned 75° and held). The standing strands are the crown's hooks
    // (docs/physics.md, "Pre-load"); a groom settled until at rest lets them
    // down (measured 0.68% and 0.43%); cut short at 2 s (the scene's old
    // hair.groom.settle) frame 36 stood 1.15%. Frame 36 moves with where the
    // settling stops (0.55-1.37% over eight stopping points, physics.md), so
    // this guards the shipped scene, with little margin.
    const Scene scene = Scene::load(test::sourcePath("scenes/default.yaml"));
    ShotSimulation sim(scene, scene.number("fps"), 1);
    const double mid = standingShare(sim.advanceTo(36), 0.02f);
    const double turned = standingShare(sim.advanceTo(84), 0.02f);
    RecordProperty("standing_frame36_permille", int(std::lround(mid * 1e3)));
    RecordProperty("standing_frame84_permille", int(std::lround(turned * 1e3)));
    EXPECT_LE(mid, 0.01) << "strands standing more than 2 cm above their root on frame 36";
    EXPECT_LE(turned, 0.01) << "strands standing more than 2 cm above their root on frame 84";
}
