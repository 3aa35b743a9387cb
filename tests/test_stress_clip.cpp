// The stress clip (scenes/stress.yaml: the default head's "stress" clip, hair
// rooted everywhere, nape and neck included, shoulders as a Bullet capsule):
// after every frame no guide or follower segment is stretched by more than
// float rounding (4 ulps of the frame's coordinates over the segment; the
// goal was 1%; measured ≤ 1.6 ulps, 9.2e-6) and no free vertex is more than
// 1 mm inside any collider (the pose's composite collider: head and Bullet
// world), on 1 and 2 threads, with the same strands on both.
//
// With the rod formulation every segment keeps its length to float
// rounding on every frame (the rope stretched nape strands 3.3% where the
// tipping head pinches them against the neck, frames 12-14). Follower
// vertices that sliding along the surface cannot bring out of the neck fold
// (frames 29-46, up to 1.74 mm deep before) are bent about their parent or
// pinned at their length (sim/followers/follower_pinch.h), so none ends
// inside.
#include "pipeline/scene/scene.h"
#include "pipeline/stages/shot_simulation.h"
#include "test_support.h"

#include <tbb/global_control.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace hp;
using namespace hp::test;

namespace {

/// Every frame's strands of the stress clip on `threads` threads, after
/// checking the limits on each.
std::vector<StrandFrame> runStress(int threads, float depthLimit, float& worstGuide, float& worstFollower,
                                   float& worstUlps) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    const Scene scene = Scene::load(sourcePath("scenes/stress.yaml"), {"hair.followers.count=3000"});
    const std::vector<int>& frames = scene.frames("frames");
    ShotSimulation sim(scene, scene.number("fps"), frames.front());
    std::vector<StrandFrame> out{sim.advanceTo(frames.front())};
    const StrandFrame rest = out.front();  // a copy: `out` grows below
    for (int frame : frames) {
        if (frame == frames.front()) continue;
        const StrandFrame& f = sim.advanceTo(frame);
        float stretch = 0.f, depth = 0.f, extent = 0.f;
        for (const Vec3f& p : f.positions) extent = std::max(extent, p.cwiseAbs().maxCoeff());
        // Stretch in units of the rounding a segment's length can carry:
        // 4 ulps of a coordinate of size `extent` over the rest length.
        float ulps = 0.f;
        for (size_t s = 0; s < f.strandCount(); ++s)
            for (uint32_t i = f.first(s); i + 1 < f.offsets[s + 1]; ++i) {
                const float len = (f.positions[i + 1] - f.positions[i]).norm();
                const float restLen = (rest.positions[i + 1] - rest.positions[i]).norm();
                stretch = std::max(stretch, std::abs(len / restLen - 1.f));
                float& worst = s < f.guideCount ? worstGuide : worstFollower;
                worst = std::max(worst, std::abs(len / restLen - 1.f));
                ulps = std::max(ulps, std::abs(len / restLen - 1.f) * restLen /
                                          (std::numeric_limits<float>::epsilon() * extent));
                depth = std::max(depth, -sim.pose().collider->signedDistance(f.positions[i + 1]));
            }
        worstUlps = std::max(worstUlps, ulps);
        EXPECT_LE(ulps, 4.f) << "frame " << frame << ", " << threads << " threads: stretch " << stretch;
        EXPECT_LE(depth, depthLimit) << "frame " << frame << ", " << threads << " threads";
        out.push_back(f);
    }
    return out;
}

}  // namespace

TEST(StressClip, NoStretchNorVertexDeeperThanAMillimetreAfterAnyFrameOnOneAndTwoThreads) {
    float guide = 0.f, follower = 0.f, ulps = 0.f;
    const std::vector<StrandFrame> one = runStress(1, 1e-3f, guide, follower, ulps),
                                   two = runStress(2, 1e-3f, guide, follower, ulps);
    RecordProperty("worst_stretch_ulps_e3", int(ulps * 1e3f));
    RecordProperty("worst_guide_stretch_e9", int(guide * 1e9f));
    RecordProperty("worst_follower_stretch_e9", int(follower * 1e9f));
    ASSERT_EQ(one.size(), two.size());
    for (size_t k = 0; k < one.size(); ++k) EXPECT_EQ(one[k].positions, two[k].positions) << "frame index " << k;
}
