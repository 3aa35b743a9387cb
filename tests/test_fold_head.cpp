// The folding head (pipeline/head/fold_head.h, scenes/assets/fold.glb:
// `make_head --fold`): a sphere head and a cylinder neck overlapping in one
// skinned mesh, hair rooted everywhere, the buried neck top and the sphere's
// underside inside the neck included. On both clips (scenes/fold_tip.yaml:
// the head tips ±70° fast; scenes/fold_jump.yaml: a neck bend, then a 0.5 m
// jump the file interpolates over three steps) and on 1 and 2 threads:
// - no guide or follower segment stretches more than 1% on any frame;
// - no guide or follower vertex lies more than 1 mm inside the head by the
//   definition of docs/colliders.md (the parts its root lies inside
//   ignored);
// - the strands are the same on both thread counts;
// - on both clips the depth hides nothing: no vertex the collider puts
//   outside lies more than 1 mm inside a part by that part's generalized
//   winding number (checked on the 1-thread run).
// On the tip clip, where the sphere folds down onto the neck, strands
// pinched between the two found no place outside at their length that the
// old pin rule (straight out from the surface under the parent) reached: up
// to 14.5 mm inside at 200 guides and 5 000 followers; the pinch search
// (sim/collision/segment_escape.h) places them outside both parts
// (docs/colliders.md, "What the tip clip still leaves inside"). Followers
// ignore the parts their roots lie inside as guides do
// (tests/test_mesh_parts.cpp checks it).
// Counts are cut to 60 guides and 600 followers (the scenes have 200 and
// 5 000); the failures showed at these counts.
#include "pipeline/scene/scene.h"
#include "pipeline/stages/shot_simulation.h"
#include "sim/collision/mesh_collider.h"
#include "sim/collision/mesh_parts.h"
#include "sim/collision/winding_number.h"
#include "test_support.h"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

using namespace hp;
using namespace hp::test;

namespace {

struct Worst {
    float stretch = 0.f, guideDepth = 0.f, followerDepth = 0.f, hidden = 0.f;
    size_t pinned = 0, cuts = 0;
};

/// The definition's cross-check: of the free vertices the pose's collider
/// puts outside every part their strand collides with, the farthest from
/// the surface of a part whose generalized winding number (exact,
/// sim/collision/winding_number.h) puts it inside that part. A collider
/// whose side is wrong in the fold hides such vertices from the depth.
float hiddenInside(const ShotSimulation& sim, const StrandFrame& f) {
    const MeshPartition& partition = sim.head().motion->partition();
    std::vector<TriangleMesh> posed;
    std::vector<std::unique_ptr<MeshCollider>> exact;
    for (size_t k = 0; k < partition.count(); ++k) {
        posed.push_back(partition.part(sim.pose().mesh, k));
        exact.push_back(std::make_unique<MeshCollider>(posed.back(), partition.welds[k]));
    }
    const std::vector<uint32_t>& ignore = sim.ignoredParts();
    std::vector<float> far(f.strandCount(), 0.f);
    tbb::parallel_for(size_t(0), f.strandCount(), [&](size_t s) {
        for (uint32_t i = f.first(s) + 1; i < f.offsets[s + 1]; ++i) {
            const Vec3f& p = f.positions[i];
            if (sim.pose().collider->signedDistanceIgnoring(p, nullptr, ignore[s]) < 0.f) continue;
            for (size_t k = 0; k < posed.size(); ++k)
                if (!((ignore[s] >> k) & 1u) && windingNumber(posed[k], exact[k]->query(), p, Vec3f::UnitY()) > 0.5)
                    far[s] = std::max(far[s], exact[k]->query().closest(p).distance);
        }
    });
    return *std::max_element(far.begin(), far.end());
}

/// Every frame of `scene` on `threads` threads, the worst figures kept.
std::vector<StrandFrame> run(const char* scene, int threads, bool boundDepth, Worst& worst) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    const Scene s = Scene::load(sourcePath(scene), {"hair.guides.count=60", "hair.followers.count=600"});
    const std::vector<int>& frames = s.frames("frames");
    ShotSimulation sim(s, s.number("fps"), frames.front());
    std::vector<StrandFrame> out{sim.advanceTo(frames.front())};
    const StrandFrame rest = out.front();
    const std::vector<uint32_t>& ignore = sim.ignoredParts();
    for (int frame : frames) {
        if (frame == frames.front()) continue;
        const StrandFrame& f = sim.advanceTo(frame);
        worst.pinned = std::max(worst.pinned, sim.stats().guides.pinnedCount);
        worst.cuts += sim.stats().guides.cuts;
        float stretch = 0.f, guideDepth = 0.f, followerDepth = 0.f;
        for (size_t k = 0; k < f.strandCount(); ++k)
            for (uint32_t i = f.first(k); i + 1 < f.offsets[k + 1]; ++i) {
                const float len = (f.positions[i + 1] - f.positions[i]).norm();
                const float restLen = (rest.positions[i + 1] - rest.positions[i]).norm();
                stretch = std::max(stretch, std::abs(len / restLen - 1.f));
                const float depth = -sim.pose().collider->signedDistanceIgnoring(f.positions[i + 1], nullptr, ignore[k]);
                (k < f.guideCount ? guideDepth : followerDepth) =
                    std::max(k < f.guideCount ? guideDepth : followerDepth, depth);
            }
        EXPECT_LE(stretch, 0.01f) << scene << " frame " << frame << ", " << threads << " threads";
        // On both clips, bounded or not: the depth the collider reports
        // hides no vertex more than 1 mm inside by the winding number.
        if (threads == 1) {
            const float hidden = hiddenInside(sim, f);
            EXPECT_LE(hidden, 1e-3f) << scene << " frame " << frame << ": inside by the winding number, outside by the collider";
            worst.hidden = std::max(worst.hidden, hidden);
        }
        if (boundDepth) {
            EXPECT_LE(guideDepth, 1e-3f) << scene << " frame " << frame << ", " << threads << " threads: guides";
            EXPECT_LE(followerDepth, 1e-3f) << scene << " frame " << frame << ", " << threads << " threads: followers";
        }
        worst.stretch = std::max(worst.stretch, stretch);
        worst.guideDepth = std::max(worst.guideDepth, guideDepth);
        worst.followerDepth = std::max(worst.followerDepth, followerDepth);
        out.push_back(f);
    }
    return out;
}

/// Runs `scene` on 1 and 2 threads; the worst figures of both.
Worst checkClip(const char* scene, bool boundDepth) {
    Worst w;
    const std::vector<StrandFrame> one = run(scene, 1, boundDepth, w), two = run(scene, 2, boundDepth, w);
    ::testing::Test::RecordProperty("worst_stretch_e9", int(w.stretch * 1e9f));
    ::testing::Test::RecordProperty("worst_guide_depth_um", int(w.guideDepth * 1e6f));
    ::testing::Test::RecordProperty("worst_follower_depth_um", int(w.followerDepth * 1e6f));
    ::testing::Test::RecordProperty("most_pinned_guide_vertices", int(w.pinned));
    ::testing::Test::RecordProperty("hidden_inside_um", int(w.hidden * 1e6f));
    EXPECT_EQ(one.size(), two.size());
    for (size_t k = 0; k < std::min(one.size(), two.size()); ++k)
        EXPECT_EQ(one[k].positions, two[k].positions) << "frame index " << k;
    std::printf("%s: worst stretch %.2e, depth guides %.3f mm, followers %.3f mm, most pinned guide vertices %zu, "
                "hidden inside %.3f mm\n",
                scene, double(w.stretch), 1e3 * double(w.guideDepth), 1e3 * double(w.followerDepth), w.pinned,
                1e3 * double(w.hidden));
    return w;
}

}  // namespace

TEST(FoldHead, TipClipKeepsLengthsAndClearanceOnOneAndTwoThreads) { checkClip("scenes/fold_tip.yaml", true); }

TEST(FoldHead, JumpClipIsOneCutKeepsLengthsAndClearanceOnOneAndTwoThreads) {
    // The jump the file interpolates over three steps is one cut on each run,
    // and none of its steps is simulated as motion: no vertex pinned (its
    // last step, 8 cm, pinned guide vertices before it joined the cut).
    const Worst w = checkClip("scenes/fold_jump.yaml", true);
    EXPECT_EQ(w.cuts, 2u);
    EXPECT_EQ(w.pinned, 0u);
}
