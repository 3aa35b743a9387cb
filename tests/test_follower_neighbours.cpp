// Follower neighbour selection (sim/followers/follower_neighbours.h, sim/followers/followers.h):
// the grid search against brute force, the two nearest guide roots in order,
// and the shape-similarity rule; and the scene keys that choose them
// (pipeline/scene/follower_settings.h).
#include "core/errors.h"
#include "follower_support.h"
#include "pipeline/scene/follower_settings.h"
#include "pipeline/scene/scene.h"
#include "sim/followers/follower_neighbours.h"
#include "sim/followers/followers.h"
#include "sim/strands/synthetic_groom.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

using namespace hp;
using hp::test::frameAt;
using hp::test::sphereGroom;

// ---------------------------------------------------------------------------
// Neighbours

TEST(FollowerNeighbours, GridEqualsBruteForce) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    for (int set = 0; set < 3; ++set) {
        std::vector<Vec3f> pts;
        const int n = set == 0 ? 845 : set == 1 ? 50 : 3000;
        for (int i = 0; i < n; ++i) {
            Vec3f p(u(rng), u(rng), u(rng));
            if (set != 1) p = 0.1f * p.normalized();  // on a sphere, like scalp roots
            pts.push_back(p);
        }
        // Exact duplicates: ties by index. Copy first: push_back(pts[k]) reads a
        // reference the reallocation may free; the index wraps because the
        // 50-point set is shorter than 20 × 7 (both found by ASan).
        for (int i = 0; i < 20; ++i) {
            const Vec3f dup = pts[(size_t(i) * 7) % size_t(n)];
            pts.push_back(dup);
        }
        const PointGrid grid(pts);
        for (int q = 0; q < 2000; ++q) {
            const Vec3f query = q % 10 == 0 ? Vec3f(3.f * u(rng), 3.f * u(rng), 3.f * u(rng))   // outside the grid
                                : q % 10 == 1 ? pts[q % pts.size()]                               // on a point
                                : Vec3f(0.11f * Vec3f(u(rng), u(rng), u(rng)).normalized());
            std::vector<uint32_t> brute(pts.size());
            std::iota(brute.begin(), brute.end(), 0u);
            std::sort(brute.begin(), brute.end(), [&](uint32_t a, uint32_t b) {
                const float da = distance2(query, pts[a]), db = distance2(query, pts[b]);
                return da != db ? da < db : a < b;
            });
            for (int k : {1, 2, 8}) {
                uint32_t idx[8];
                float d2[8];
                ASSERT_EQ(grid.nearest(query, k, idx, d2), k);
                for (int j = 0; j < k; ++j) {
                    ASSERT_EQ(idx[j], brute[j]) << "set " << set << " query " << q << " k " << k << " rank " << j;
                    ASSERT_EQ(d2[j], distance2(query, pts[brute[j]]));
                }
            }
        }
    }
}

TEST(FollowerNeighbours, FollowersUseTheTwoNearestGuideRootsInOrder) {
    const FollowerGroom groom = sphereGroom(94, 751);
    const Followers followers(groom, {});
    for (size_t f = 0; f < groom.followerRoots.size(); ++f) {
        std::vector<std::pair<float, uint32_t>> d;
        for (uint32_t g = 0; g < groom.guideRoots.size(); ++g)
            d.emplace_back(distance2(groom.followerRoots[f].position, groom.guideRoots[g].position), g);
        std::sort(d.begin(), d.end());
        EXPECT_EQ(followers.neighbours(f).guide1, d[0].second);
        EXPECT_EQ(followers.neighbours(f).guide2, d[1].second);
        EXPECT_LE(followers.neighbours(f).distance1, followers.neighbours(f).distance2);
    }
}

TEST(FollowerNeighbours, ShapeSimilarityPicksGuidesOfTheSameStyle) {
    // Guides in a row, styles alternating: even ones comb toward +x, odd toward -x.
    FollowerGroom groom;
    auto combed = [](float side) {
        std::vector<Vec3f> p{Vec3f::Zero()};
        for (int y = 0; y < 11; ++y) p.push_back(p.back() + 0.02f * Vec3f(side * 0.08f * y, 1.f, 0.f).normalized());
        return p;
    };
    for (int g = 0; g < 20; ++g) {
        groom.guideRoots.push_back(frameAt(Vec3f(0.01f * g, 0, 0), Vec3f::UnitY(), Vec3f::UnitX()));
        const auto shape = combed(g % 2 ? -1.f : 1.f);
        groom.guideShapes.add(shape.data(), shape.size());
    }
    // Followers next to even guides but combed like the odd ones.
    for (int f = 0; f < 8; ++f) {
        groom.followerRoots.push_back(frameAt(Vec3f(0.02f * (f + 2) + 0.001f, 0, 0.0005f), Vec3f::UnitY(), Vec3f::UnitX()));
        const auto shape = combed(-1.f);
        groom.followerShapes.add(shape.data(), shape.size());
    }
    FollowerSettings nearest, similar;
    similar.neighbours = NeighbourRule::ShapeSimilarity;
    const Followers a(groom, nearest), b(groom, similar);
    for (size_t f = 0; f < groom.followerRoots.size(); ++f) {
        EXPECT_EQ(a.neighbours(f).guide1 % 2, 0u) << "the nearest root is an even guide";
        EXPECT_EQ(b.neighbours(f).guide1 % 2, 1u);
        EXPECT_EQ(b.neighbours(f).guide2 % 2, 1u);
    }
    // Without own shapes: keep the nearest guide, take the second of its style.
    groom.followerShapes = RestShapes();
    groom.followerVertices = {12};
    groom.followerLengths = {0.22f};
    const Followers c(groom, similar);
    for (size_t f = 0; f < groom.followerRoots.size(); ++f) {
        EXPECT_EQ(c.neighbours(f).guide1, a.neighbours(f).guide1);
        EXPECT_EQ(c.neighbours(f).guide2 % 2, 0u);
        EXPECT_NE(c.neighbours(f).guide2, c.neighbours(f).guide1);
    }
}

TEST(FollowerSettings, SceneKeysMapOntoSettings) {
    const FollowerSettings defaults = followerSettings(Scene::parse("", "shot.yaml", "."));
    EXPECT_EQ(defaults.mode, FollowerMode::Varied);
    EXPECT_EQ(defaults.neighbours, NeighbourRule::Nearest);
    EXPECT_FLOAT_EQ(defaults.fixedOffset, 0.2f);
    EXPECT_FLOAT_EQ(defaults.maxVelocity, 0.1f);
    EXPECT_TRUE(defaults.collide);

    const FollowerSettings s = followerSettings(Scene::parse(
        "seed: 42\nhair:\n  followers:\n    mode: cluster\n    neighbours: shape-similarity\n"
        "    fixed_offset: 0.3\n    max_velocity: 0.05\n    collide: false\n",
        "shot.yaml", ".", {"hair.followers.mode=interpolate"}));
    EXPECT_EQ(s.mode, FollowerMode::Interpolate) << "--set overrides the file";
    EXPECT_EQ(s.neighbours, NeighbourRule::ShapeSimilarity);
    EXPECT_FLOAT_EQ(s.fixedOffset, 0.3f);
    EXPECT_FLOAT_EQ(s.maxVelocity, 0.05f);
    EXPECT_FALSE(s.collide);
    EXPECT_EQ(s.seed, 42u);

    try {
        Scene::parse("hair:\n  followers:\n    mode: clumped\n", "shot.yaml", ".");
        FAIL() << "an unknown mode must be rejected";
    } catch (const SceneError& e) {
        EXPECT_EQ(e.key(), "hair.followers.mode");
        EXPECT_NE(std::string(e.what()).find("varied"), std::string::npos) << e.what();
    }
    EXPECT_THROW(Scene::parse("hair:\n  followers:\n    fixed_offset: 1.5\n", "shot.yaml", "."), SceneError);
}
