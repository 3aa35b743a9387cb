// Followers caught in a pinch (sim/followers/follower_pinch.h, issue 20): a
// vertex that sliding along the surface cannot bring out is bent about its
// parent, else pinned; never stretched. The kernel against analytic
// answers (a slab gap, a wedge, a closed pocket), then whole followers
// squeezed between a sphere head and a lid that cuts into it, and the
// frame statistics that report them.
#include "follower_support.h"
#include "pipeline/stages/shot_simulation.h"
#include "sim/followers/follower_kernels.h"
#include "sim/followers/follower_pinch.h"
#include "sim/followers/followers.h"
#include "sim/strands/synthetic_groom.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdio>

using namespace hp;

namespace {

constexpr float kPi = 3.14159265f;

/// Solid below y = 0 and above y = gap: free space is the slab between.
class SlabGap final : public Collider {
  public:
    explicit SlabGap(float gap) : gap_(gap) {}
    float signedDistance(const Vec3f& p, Vec3f* normal) const override {
        const float below = p.y(), above = gap_ - p.y();
        if (normal) *normal = below <= above ? Vec3f::UnitY() : Vec3f(-Vec3f::UnitY());
        return std::min(below, above);
    }

  private:
    float gap_;
};

/// Solid everywhere but a ball of radius R about the origin.
class Pocket final : public Collider {
  public:
    explicit Pocket(float radius) : radius_(radius) {}
    float signedDistance(const Vec3f& p, Vec3f* normal) const override {
        if (normal) *normal = p.norm() > 0.f ? Vec3f(-p.normalized()) : Vec3f::UnitY();
        return radius_ - p.norm();
    }

  private:
    float radius_;
};

/// Free space is a wedge of half-angle β opening toward +x from the z axis:
/// solid above y = x tan β and below y = -x tan β.
class Wedge final : public Collider {
  public:
    explicit Wedge(float beta) : s_(std::sin(beta)), c_(std::cos(beta)) {}
    float signedDistance(const Vec3f& p, Vec3f* normal) const override {
        const float upper = p.x() * s_ - p.y() * c_, lower = p.x() * s_ + p.y() * c_;
        if (normal) *normal = upper <= lower ? Vec3f(s_, -c_, 0.f) : Vec3f(s_, c_, 0.f);
        return std::min(upper, lower);
    }

  private:
    float s_, c_;
};

/// The sphere head r = 0.1 m and a lid, the half-space y >= lid, as one
/// collider (a union of solids: the smaller signed distance).
class HeadUnderLid final : public Collider {
  public:
    explicit HeadUnderLid(float lid) : lid_(lid) {}
    float signedDistance(const Vec3f& p, Vec3f* normal) const override {
        const float r = p.norm(), head = r - 0.1f, lid = lid_ - p.y();
        if (normal) *normal = head <= lid ? Vec3f(p / r) : Vec3f(-Vec3f::UnitY());
        return std::min(head, lid);
    }

  private:
    float lid_;
};

float degrees(const Vec3f& a, const Vec3f& b) {
    return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.f / kPi;
}

}  // namespace

TEST(FollowerPinch, BendsByTheLeastAngleIntoAGap) {
    // Parent midway in a 4 mm gap, segment 1 cm, wanted 60° below the
    // horizontal. The directions whose end stays r clear of both faces have
    // |u_y| <= (gap/2 - r)/L; the nearest to the wanted one keeps its
    // horizontal heading and dips by asin((gap/2 - r)/L): a bend of
    // 60° - asin(0.19) = 49.05°.
    const float gap = 0.004f, L = 0.01f, r = 1e-4f;
    const SlabGap slab(gap);
    const Vec3f parent(0.f, gap / 2, 0.f);
    const Vec3f u(std::cos(-kPi / 3), std::sin(-kPi / 3), 0.f);
    const follower::PinchPlace place = follower::placePinched(slab, parent, L, r, parent + L * u, nullptr);
    EXPECT_FALSE(place.pinned);
    EXPECT_NEAR((place.position - parent).norm() / L, 1.f, 1e-6f) << "bent, never stretched";
    EXPECT_GE(slab.signedDistance(place.position, nullptr), r * 0.999f);
    EXPECT_FLOAT_EQ(place.distance, slab.signedDistance(place.position, nullptr));
    const float least = 60.f - std::asin((gap / 2 - r) / L) * 180.f / kPi;
    const float bend = degrees(place.position - parent, u);
    EXPECT_GE(bend, least - 0.01f);
    EXPECT_LE(bend, least + 1.f) << "the lattice and bisection find a bend near the least one";
    std::printf("least bend %.2f°, found %.2f°\n", least, bend);
}

TEST(FollowerPinch, WhereSlidingPushesIntoTheOtherSurfaceTheSegmentBends) {
    // Parent 3 mm from the apex of a 10° wedge, the segment (1 cm) wanting
    // to point back past the apex: sliding off one face runs into the other
    // and ends inside; turned about the parent, the segment has room along
    // the wedge (z) or out of its mouth (+x).
    const Wedge wedge(5.f * kPi / 180.f);
    const Vec3f parent(0.003f, 0.f, 0.f), wanted = parent + 0.01f * Vec3f(-1.f, 0.2f, 0.f).normalized();
    const float L = 0.01f, r = 1e-4f;
    Vec3f normal, slid = wanted;
    const float d = wedge.signedDistance(wanted, &normal);
    EXPECT_LT(follower::projectSegmentOut(wedge, parent, L, r, d, normal, slid), 0.f) << "sliding alone fails here";
    const follower::PinchPlace place = follower::placePinched(wedge, parent, L, r, wanted, nullptr);
    EXPECT_FALSE(place.pinned);
    EXPECT_NEAR((place.position - parent).norm() / L, 1.f, 1e-6f);
    EXPECT_GE(wedge.signedDistance(place.position, nullptr), r * 0.999f);
}

TEST(FollowerPinch, WithNoPlaceOutsideTheVertexIsPinnedAtItsLength) {
    // A free ball of 4 mm about the parent, segment 1 cm: every place at the
    // segment's length is 6 mm deep. Held toward its last place, at its length.
    const Pocket pocket(0.004f);
    const Vec3f parent = Vec3f::Zero(), last(0.f, 0.f, 0.003f);
    const float L = 0.01f;
    follower::PinchPlace place = follower::placePinched(pocket, parent, L, 1e-4f, Vec3f(L, 0.f, 0.f), &last);
    EXPECT_TRUE(place.pinned);
    EXPECT_NEAR(place.position.z(), L, 1e-7f) << "toward its last place";
    EXPECT_NEAR(place.position.norm() / L, 1.f, 1e-6f);
    EXPECT_NEAR(place.distance, -0.006f, 1e-6f) << "the depth is reported, not hidden";
    place = follower::placePinched(pocket, parent, L, 1e-4f, Vec3f(L, 0.f, 0.f), nullptr);
    EXPECT_TRUE(place.pinned);
    EXPECT_NEAR(place.position.norm() / L, 1.f, 1e-6f);
}

TEST(FollowerPinch, FollowersSqueezedUnderALidStayOutsideAtTheirLengths) {
    // A lid 5 mm below the crown cuts into the head; guides lie over the
    // crown, so followers there press into the wedge between the head and
    // the lid, where sliding along one surface pushes into the other.
    const hp::test::SphereScene scene(94, 2000, 0.7);
    const HeadUnderLid head(0.095f);
    const float rest = 0.25f / 23;

    auto run = [&](int threads, StrandFrame& out, FollowerStats* second) {
        tbb::task_arena arena(threads);
        arena.execute([&] {
            Followers followers(scene.groom, {});
            const FollowerStep step{scene.guides, scene.guideRoots, scene.followerRoots, &head};
            const FollowerStats first = followers.update(step, out);
            // Again into the same buffer: pinned vertices are now held toward their last places.
            *second = followers.update({scene.guides, scene.guideRoots, scene.followerRoots, &head, 0.04}, out);
            EXPECT_GT(first.bent, 0u) << "the slide alone leaves vertices inside the wedge";
        });
    };
    StrandFrame one, two;
    FollowerStats stats, stats2;
    run(1, one, &stats);
    run(2, two, &stats2);
    EXPECT_EQ(one.positions, two.positions) << "the same bits on 1 and 2 threads";
    EXPECT_EQ(stats.pinned, stats2.pinned);

    size_t inside = 0, insideFree = 0;
    float deepest = 0.f;
    double stretch = 0;
    for (size_t f = one.guideCount; f < one.strandCount(); ++f) {
        const uint32_t root = one.first(f);
        // A root deeper than a segment can reach has no place outside near it.
        const bool rootCanReach = head.signedDistance(one.positions[root], nullptr) > -1e-4f;
        for (uint32_t v = root + 1; v < one.offsets[f + 1]; ++v) {
            stretch = std::max(stretch, std::abs(double((one.positions[v] - one.positions[v - 1]).norm()) / rest - 1));
            const float d = head.signedDistance(one.positions[v], nullptr);
            if (d < 0.f) {
                ++inside;
                insideFree += rootCanReach;
                deepest = std::max(deepest, -d);
            }
        }
    }
    EXPECT_LT(stretch, 1e-5) << "never stretched";
    EXPECT_EQ(insideFree, 0u) << "followers rooted outside end outside";
    EXPECT_EQ(stats.penetrationCount, inside) << "the statistics count what is inside";
    EXPECT_FLOAT_EQ(stats.maxPenetration, deepest);
    EXPECT_GT(stats.pinned, 0u) << "roots under the lid have no place outside within a segment";
    std::printf("bent %zu, pinned %zu, left inside %zu (%.2f mm), max stretch %.1e\n", stats.bent, stats.pinned,
                inside, deepest * 1e3, stretch);
}

TEST(FollowerPinch, PinsRebuildAFrameWithoutTheFrameBefore) {
    // The strand cache keeps a frame's guides and its pins, not the frame
    // before: a fresh Followers whose buffer holds anything but the pins'
    // places must give the pinned frame's positions again, bit for bit.
    const hp::test::SphereScene scene(94, 2000, 0.7);
    const HeadUnderLid head(0.095f);
    const FollowerStep first{scene.guides, scene.guideRoots, scene.followerRoots, &head};
    const FollowerStep second{scene.guides, scene.guideRoots, scene.followerRoots, &head, 0.04};
    Followers simulated(scene.groom, {});
    StrandFrame out;
    simulated.update(first, out);
    const FollowerStats stats = simulated.update(second, out);
    ASSERT_GT(stats.pinned, 0u) << "the lid pins vertices";
    EXPECT_EQ(stats.pins.size(), stats.pinned) << "every pinned vertex held toward its last place is listed";
    for (size_t i = 1; i < stats.pins.size(); ++i) EXPECT_LT(stats.pins[i - 1].vertex, stats.pins[i].vertex);

    Followers rebuilt(scene.groom, {});
    StrandFrame again;
    rebuilt.update(first, again);
    const size_t guideVertices = again.offsets[again.guideCount];
    for (size_t v = guideVertices; v < again.positions.size(); ++v) again.positions[v] = Vec3f(1.f, 2.f, 3.f);
    rebuilt.adoptPins(again, stats.pins);
    const FollowerStats stats2 = rebuilt.update(second, again);
    EXPECT_TRUE(again.positions == out.positions) << "the pinned frame comes back bit for bit";
    EXPECT_EQ(stats2.pins.size(), stats.pins.size());
}

TEST(FollowerPinch, FrameStatisticsReportBentAndPinnedFollowerVertices) {
    SimFrameStats s;
    s.guides.pinnedCount = 2;
    s.followers.bent = 5;
    s.followers.pinned = 3;
    const std::string j = s.json();
    const size_t followers = j.find("\"followers\": {");
    ASSERT_NE(followers, std::string::npos) << j;
    EXPECT_NE(j.find("\"bent\": 5, \"pinned\": 3}", followers), std::string::npos) << j;
    EXPECT_LT(j.find("\"pinned\": 2"), followers) << "the guides' pinned count stays at the top level";
}
