// Scene cuts (sim/solver/scene_cut.h): a step whose head or root jump exceeds
// simulation.cut_distance / cut_angle restarts every guide in its rest shape
// on the new pose, placed outside every collider before the frame is
// written; `hairpipe info` lists the cuts of a clip.
#include "batch_support.h"
#include "pipeline/scene/scene.h"
#include "pipeline/stages/shot_simulation.h"
#include "sim/strands/fibonacci.h"
#include "sim/guides/guides.h"
#include "sim/solver/scene_cut.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <cmath>

using namespace hp;
using namespace hp::test;
namespace fs = std::filesystem;

namespace {

/// A sphere head over a floor (the half-space y < 0): the union's signed
/// distance is the smaller of the two, its normal the nearer surface's.
class HeadOverFloor final : public Collider {
  public:
    HeadOverFloor(const Vec3f& centre, float radius) : head_(centre, radius) {}
    float signedDistance(const Vec3f& p, Vec3f* normal) const override {
        Vec3f n;
        const float d = head_.signedDistance(p, &n);
        if (p.y() < d) {
            if (normal) *normal = Vec3f::UnitY();
            return p.y();
        }
        if (normal) *normal = n;
        return d;
    }

  private:
    SphereCollider head_;
};

HeadPose headAt(double time, const Vec3f& centre, float radius) {
    HeadPose p;
    p.time = time;
    p.transform = Eigen::Translation3f(centre) * Eigen::Isometry3f::Identity();
    p.collider = std::make_shared<HeadOverFloor>(centre, radius);
    return p;
}

std::vector<SurfaceFrame> roots(const std::vector<Vec3f>& dirs, float radius, const HeadPose& pose) {
    std::vector<SurfaceFrame> r(dirs.size());
    for (size_t i = 0; i < dirs.size(); ++i) {
        r[i].position = pose.transform * (radius * dirs[i]);
        r[i].normal = dirs[i];
        r[i].tangent = dirs[i].unitOrthogonal();
    }
    return r;
}

/// Deepest free vertex of `frame` inside `collider` (0 when none).
float deepest(const StrandFrame& frame, const Collider& collider) {
    float worst = 0.f;
    for (size_t s = 0; s < frame.strandCount(); ++s)
        for (uint32_t i = frame.first(s) + 1; i < frame.offsets[s + 1]; ++i)
            worst = std::max(worst, -collider.signedDistance(frame.positions[i]));
    return worst;
}

}  // namespace

TEST(SceneCut, JumpTestUsesTheLimits) {
    Eigen::Isometry3f a = Eigen::Isometry3f::Identity(), b = a;
    b.rotate(Eigen::AngleAxisf(float(M_PI) / 3.f, Vec3f::UnitY()));  // 60°
    EXPECT_NEAR(stepJump(a, b, 0.f).headTurn, 60.f, 1e-3f);
    EXPECT_TRUE(isCut(stepJump(a, b, 0.f), 0.1f, 45.f));
    EXPECT_FALSE(isCut(stepJump(a, b, 0.f), 0.1f, 61.f));
    EXPECT_TRUE(isCut(stepJump(a, a, 0.11f), 0.1f, 45.f)) << "a root jump alone is a cut";
}

// Hair hanging from a head 0.5 m above a floor; the clip cuts to the head
// 0.2 m above it, where the rest shape would end 15 cm under the floor.
TEST(SceneCut, NoVertexInsideAnyColliderOnTheCutFrameAndAfter) {
    for (GuideFormulation f : {GuideFormulation::Rope, GuideFormulation::Rigid}) {
        SCOPED_TRACE(formulationName(f));
        GuideSettings s;
        s.formulation = f;
        s.strandsPerWorld = 8;
        GuideSolver solver(s);
        const float radius = 0.1f;
        const std::vector<Vec3f> dirs = fibonacciCap(24, -Vec3f::UnitY(), 0.3f);
        const Vec3f high(0.f, 0.5f, 0.f), low(0.f, 0.2f, 0.f);
        HeadPose pose = headAt(0.0, high, radius);
        solver.initialize(roots(dirs, radius, pose), pose);
        StrandFrame frame;
        for (int k = 1; k <= 30; ++k) {
            pose = headAt(solver.nextTime(), k < 10 ? high : low, radius);
            const StepStats& st = solver.step(roots(dirs, radius, pose), pose);
            ASSERT_EQ(st.reset, k == 10) << "step " << k;
            solver.write(frame);
            const float depth = deepest(frame, *pose.collider);
            if (k == 10) {
                EXPECT_EQ(depth, 0.f) << "the cut frame: every vertex outside the head and the floor";
                EXPECT_LE(st.maxLengthError, 1e-4) << "placed outside without stretching";
            } else if (f == GuideFormulation::Rope) {
                // The finish pass's last projection keeps every vertex the
                // collision radius outside (tests/test_collision_world.cpp).
                EXPECT_EQ(depth, 0.f) << "step " << k;
            } else {
                // Rigid: each segment body is pushed out by its deepest of
                // three points, which bounds but does not zero the others.
                EXPECT_LE(depth, 1e-3f) << "step " << k;
            }
            if (f == GuideFormulation::Rope) {
                // Exact lengths up to float rounding (the finish pass's
                // follow-the-leader, tests/test_collision_world.cpp says how
                // much): coordinates below 0.8 m, segments of 0.25/23 m
                // (3.5e-5; measured 1.4e-6).
                EXPECT_LE(st.maxLengthError, 4.0 * 0.8 * FLT_EPSILON / (0.25 / 23)) << "step " << k;
            }
        }
    }
}

// A 0.5 m jump the head file interpolates linearly over 1/30 s, steps of
// 1/72 s: the steps move 0.208, 0.208 and 0.083 m. The third moves less than
// the cut distance but belongs to the same jump: one cut over three steps,
// each restarting the strands at rest outside the head and the floor at
// their exact lengths, none simulated as motion (no vertex pinned).
TEST(SceneCut, JumpSpreadOverThreeStepsIsOneCut) {
    GuideSettings s;
    s.timeStep = 1.f / 72.f;
    GuideSolver solver(s);
    const float radius = 0.1f;
    const std::vector<Vec3f> dirs = fibonacciCap(24, -Vec3f::UnitY(), 0.3f);
    const double jumpStart = 10.0 / 72.0, jumpEnd = jumpStart + 1.0 / 30.0;
    auto centreAt = [&](double t) {
        const double a = std::clamp((t - jumpStart) / (jumpEnd - jumpStart), 0.0, 1.0);
        return Vec3f(float(0.5 * a), 0.3f, 0.f);
    };
    HeadPose pose = headAt(0.0, centreAt(0.0), radius);
    solver.initialize(roots(dirs, radius, pose), pose);
    size_t cuts = 0;
    StrandFrame frame;
    for (int k = 1; k <= 20; ++k) {
        pose = headAt(solver.nextTime(), centreAt(solver.nextTime()), radius);
        const StepStats& st = solver.step(roots(dirs, radius, pose), pose);
        cuts += st.cuts;
        EXPECT_EQ(st.reset, k >= 11 && k <= 13) << "step " << k;
        EXPECT_EQ(st.pinnedCount, 0u) << "step " << k;
        EXPECT_LE(st.maxLengthError, 1e-4) << "step " << k;
        solver.write(frame);
        if (k >= 11 && k <= 13) EXPECT_EQ(deepest(frame, *pose.collider), 0.f) << "step " << k;
    }
    EXPECT_EQ(cuts, 1u);
}

TEST(SceneCut, InfoListsTheCutsOfTheClip) {
    TempDir dir;
    const fs::path scene = writeSmallScene(dir.path(), "1-12");
    // At 24 fps a 120° yaw between frames 6 and 6.2 happens within one step.
    const ProcessResult r =
        runHairpipe("info " + q(scene) + " --set 'head.animate.yaw=[[1, 0], [6, 0], [6.2, 120]]'");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("cuts:    1 (simulation.cut_distance 0.1 m, cut_angle 45 deg per step)"),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("turned 120.0 deg"), std::string::npos) << r.output;
    const ProcessResult none = runHairpipe("info " + q(scene));
    ASSERT_EQ(none.exitCode, 0) << none.output;
    EXPECT_NE(none.output.find("cuts:    0 "), std::string::npos) << "the default clip has no cut:\n" << none.output;
    const ProcessResult looser =
        runHairpipe("info " + q(scene) + " --set 'head.animate.yaw=[[1, 0], [6, 0], [6.2, 120]]' --set simulation.cut_angle=150 --set simulation.cut_distance=0.2");
    EXPECT_NE(looser.output.find("cuts:    0 "), std::string::npos) << looser.output;
    // The folding head's jump: one cut over three steps.
    const ProcessResult fold = runHairpipe("info " + q(sourcePath("scenes/fold_jump.yaml")));
    ASSERT_EQ(fold.exitCode, 0) << fold.output;
    EXPECT_NE(fold.output.find("cuts:    1 "), std::string::npos) << fold.output;
    EXPECT_NE(fold.output.find("moved 0.500 m over 3 steps"), std::string::npos) << fold.output;
}

// The stress clip's cut at 2 s (frame 50 at 25 fps), hair everywhere, the
// shoulders as a Bullet capsule: the shot restarts at rest on the new pose
// with no guide vertex inside the head or the shoulders on the cut frame,
// and no strand (followers included) more than 1 mm inside.
TEST(SceneCut, StressClipCutFrameHasNoVertexInsideAnyCollider) {
    const Scene scene = Scene::load(sourcePath("scenes/stress.yaml"),
                                    {"frames=48-52", "hair.guides.count=60", "hair.followers.count=600"});
    ShotSimulation sim(scene, scene.number("fps"), 48);
    for (int frame = 49; frame <= 52; ++frame) {
        const StrandFrame& f = sim.advanceTo(frame);
        const StepStats& g = sim.stats().guides;
        EXPECT_EQ(g.reset, frame == 50) << "frame " << frame;
        if (frame == 50) {
            EXPECT_EQ(g.penetrationCount, 0u) << "guide vertices inside a collider on the cut frame";
        }
        float depth = 0.f;
        for (size_t s = 0; s < f.strandCount(); ++s)
            for (uint32_t i = f.first(s) + 1; i < f.offsets[s + 1]; ++i)
                depth = std::max(depth, -sim.pose().collider->signedDistance(f.positions[i]));
        EXPECT_LE(depth, 1e-3f) << "frame " << frame;
    }
}
