// The stress clip (scenes/stress.yaml: the default head's "stress" clip, hair
// rooted everywhere, nape and neck included, shoulders as a Bullet capsule):
// after every frame no guide or follower segment is stretched more than 1%
// and no free vertex is more than 1 mm inside any collider, on 1 and 2
// threads, with the same strands on both.
//
// DISABLED until the rod formulation (issue 18) lands: the rope formulation
// stretches nape strands 3.3% where the tipping head pinches them against
// the neck (frames 12-14; depth stays below 0.7 mm). Run it with
//   build/tests/test_stress_clip --gtest_also_run_disabled_tests
#include "pipeline/scene.h"
#include "pipeline/shot_simulation.h"
#include "test_support.h"

#include <tbb/global_control.h>

#include <gtest/gtest.h>

#include <cmath>

using namespace hp;
using namespace hp::test;

namespace {

/// Every frame's strands of the stress clip on `threads` threads, after
/// checking the limits on each.
std::vector<StrandFrame> runStress(int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    const Scene scene = Scene::load(sourcePath("scenes/stress.yaml"), {"hair.followers.count=3000"});
    const std::vector<int>& frames = scene.frames("frames");
    ShotSimulation sim(scene, scene.number("fps"), frames.front());
    std::vector<StrandFrame> out{sim.advanceTo(frames.front())};
    const StrandFrame& rest = out.front();
    for (int frame : frames) {
        if (frame == frames.front()) continue;
        const StrandFrame& f = sim.advanceTo(frame);
        float stretch = 0.f, depth = 0.f;
        for (size_t s = 0; s < f.strandCount(); ++s)
            for (uint32_t i = f.first(s); i + 1 < f.offsets[s + 1]; ++i) {
                const float len = (f.positions[i + 1] - f.positions[i]).norm();
                const float restLen = (rest.positions[i + 1] - rest.positions[i]).norm();
                stretch = std::max(stretch, std::abs(len / restLen - 1.f));
                depth = std::max(depth, -sim.pose().collider->signedDistance(f.positions[i + 1]));
            }
        EXPECT_LE(stretch, 0.01f) << "frame " << frame << ", " << threads << " threads";
        EXPECT_LE(depth, 1e-3f) << "frame " << frame << ", " << threads << " threads";
        out.push_back(f);
    }
    return out;
}

}  // namespace

TEST(StressClip, DISABLED_NoStretchNoPenetrationAfterAnyFrameOnOneAndTwoThreads) {
    const std::vector<StrandFrame> one = runStress(1), two = runStress(2);
    ASSERT_EQ(one.size(), two.size());
    for (size_t k = 0; k < one.size(); ++k) EXPECT_EQ(one[k].positions, two[k].positions) << "frame index " << k;
}
