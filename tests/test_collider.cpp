// Exact mesh queries, the signed distance grid and the head colliders
// (sim/collision/mesh_query.h, sim/collision/level_set.h, sim/collision/mesh_collider.h).
#include "sim/collision/level_set.h"
#include "sim/collision/mesh_collider.h"
#include "sim/collision/mesh_query.h"

#include <gtest/gtest.h>

#include <random>

using namespace hp;

namespace {

Vec3f randomPoint(std::mt19937& rng, float extent) {
    std::uniform_real_distribution<float> u(-extent, extent);
    return Vec3f(u(rng), u(rng), u(rng));
}

/// Brute force: the smallest distance from p to any triangle.
float bruteDistance(const TriangleMesh& m, const Vec3f& p) {
    float best = std::numeric_limits<float>::infinity();
    for (const Tri& t : m.triangles) {
        const TrianglePoint q = closestPointOnTriangle(p, m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]);
        const Vec3f x = (1 - q.b1 - q.b2) * m.positions[t[0]] + q.b1 * m.positions[t[1]] + q.b2 * m.positions[t[2]];
        best = std::min(best, (x - p).norm());
    }
    return best;
}

/// A closed test head: a sphere squashed into an egg, so distances are not
/// those of a sphere.
TriangleMesh egg() {
    TriangleMesh m = makeSphereMesh(Vec3f::Zero(), 0.1f, 48, 96);
    for (Vec3f& p : m.positions) p = Vec3f(0.8f * p.x(), p.y() * (p.y() > 0 ? 1.1f : 0.9f), p.z());
    m.computeNormals();
    return m;
}

/// One grid for the level set tests (building it is the slow part): 2 mm
/// voxels, the pipeline's default, 6 mm bands.
const std::shared_ptr<const LevelSet>& eggGrid() {
    static const std::shared_ptr<const LevelSet> grid = [] {
        LevelSetSettings s;
        s.voxelSize = 0.002f;
        s.exteriorBand = s.interiorBand = 0.006f;
        return std::make_shared<const LevelSet>(egg(), s);
    }();
    return grid;
}

}  // namespace

TEST(ClosestPointOnTriangle, NeverFartherThanAnySampleOfTheTriangle) {
    std::mt19937 rng(3);
    const Vec3f a(0, 0, 0), b(1, 0.2f, 0), c(0.3f, 1, 0.1f);
    std::uniform_real_distribution<float> u(0, 1);
    for (int i = 0; i < 200; ++i) {
        const Vec3f p = randomPoint(rng, 2.f);
        const TrianglePoint q = closestPointOnTriangle(p, a, b, c);
        ASSERT_GE(q.b1, -1e-6f);
        ASSERT_GE(q.b2, -1e-6f);
        ASSERT_LE(q.b1 + q.b2, 1 + 1e-6f);
        const float d = ((1 - q.b1 - q.b2) * a + q.b1 * b + q.b2 * c - p).norm();
        for (int s = 0; s < 300; ++s) {
            float s1 = u(rng), s2 = u(rng);
            if (s1 + s2 > 1) s1 = 1 - s1, s2 = 1 - s2;
            ASSERT_LE(d, ((1 - s1 - s2) * a + s1 * b + s2 * c - p).norm() + 1e-5f);
        }
    }
    EXPECT_EQ(closestPointOnTriangle(Vec3f(-1, -1, 0), a, b, c).feature, TriangleFeature::VertexA);
    EXPECT_EQ(closestPointOnTriangle(Vec3f(0.3f, 0.3f, 0.3f), a, b, c).feature, TriangleFeature::Face);
    EXPECT_EQ(closestPointOnTriangle(Vec3f(0.5f, -1, 0), a, b, c).feature, TriangleFeature::EdgeAB);
    // A degenerate (collinear) triangle still gives a point on it.
    const TrianglePoint d = closestPointOnTriangle(Vec3f(0.5f, 1, 0), a, Vec3f(1, 0, 0), Vec3f(2, 0, 0));
    EXPECT_NEAR(d.b1 * 1 + d.b2 * 2, 0.5f, 1e-5f);
}

TEST(MeshQuery, ClosestMatchesBruteForceAndRayHitsTheSurface) {
    const TriangleMesh m = egg();
    const MeshQuery q(m);
    std::mt19937 rng(5);
    for (int i = 0; i < 100; ++i) {
        const Vec3f p = randomPoint(rng, 0.2f);
        const MeshPoint c = q.closest(p);
        ASSERT_TRUE(c.found());
        EXPECT_NEAR(c.distance, bruteDistance(m, p), 1e-6f);
        EXPECT_NEAR((evaluate(m, c.point).position - c.position).norm(), 0.f, 1e-6f);
    }
    EXPECT_FALSE(q.closest(Vec3f(1, 0, 0), 0.1f).found()) << "nothing within the search radius";
    const RayHit h = q.intersect(Vec3f(0, 0.5f, 0), Vec3f(0, -1, 0));
    ASSERT_TRUE(h.hit());
    EXPECT_NEAR(h.t, 0.5f - 0.11f, 2e-4f) << "the egg's top is at y = 0.11";
    EXPECT_FALSE(q.intersect(Vec3f(0, 0.5f, 0), Vec3f(0, 1, 0)).hit());
}

TEST(MeshQuery, MaskAndRefit) {
    TriangleMesh m = egg();
    std::vector<uint8_t> top(m.triangles.size());
    for (size_t t = 0; t < top.size(); ++t) top[t] = m.positions[m.triangles[t][0]].y() > 0.05f;
    const MeshQuery q(m, top);
    const MeshPoint c = q.closest(Vec3f(0, -0.3f, 0));
    ASSERT_TRUE(c.found());
    EXPECT_TRUE(top[c.point.triangle]) << "only masked triangles are candidates";
    EXPECT_GT(c.position.y(), 0.04f);

    MeshQuery moving(m);
    for (Vec3f& p : m.positions) p += Vec3f(0.05f, 0, 0);
    moving.refit(m.positions);
    const MeshQuery fresh(m);
    std::mt19937 rng(9);
    for (int i = 0; i < 50; ++i) {
        const Vec3f p = randomPoint(rng, 0.2f);
        EXPECT_FLOAT_EQ(moving.closest(p).distance, fresh.closest(p).distance);
    }
}

TEST(MeshQuery, TiesGoToTheLowerTriangle) {
    // Two triangles sharing the edge x = 0; a point right above the edge is
    // equally close to both.
    TriangleMesh m;
    m.positions = {{0, 0, 0}, {0, 0, 1}, {-1, 0, 0.5f}, {1, 0, 0.5f}};
    m.triangles = {{0, 3, 1}, {0, 1, 2}};
    const MeshQuery q(m);
    EXPECT_EQ(q.closest(Vec3f(0, 1, 0.5f)).point.triangle, 0u);
    std::swap(m.triangles[0], m.triangles[1]);
    const MeshQuery swapped(m);
    EXPECT_EQ(swapped.closest(Vec3f(0, 1, 0.5f)).point.triangle, 0u);
}

TEST(MeshCollider, WeldMergesSeamCopies) {
    const TriangleMesh s = makeSphereMesh(Vec3f::Zero(), 1.f, 8, 16);
    const std::vector<uint32_t> weld = weldVertices(s.positions);
    std::set<uint32_t> unique(weld.begin(), weld.end());
    // (rings - 1) rows of `sectors` distinct points plus the two poles.
    EXPECT_EQ(unique.size(), size_t(7 * 16 + 2));
    for (size_t i = 0; i < weld.size(); ++i) EXPECT_LT((s.positions[weld[i]] - s.positions[i]).norm(), 1e-6f);
}

TEST(MeshCollider, SignAndDistanceAreExact) {
    const TriangleMesh m = egg();
    const MeshCollider exact(m);
    std::mt19937 rng(11);
    int inside = 0;
    for (int i = 0; i < 300; ++i) {
        const Vec3f p = randomPoint(rng, 0.15f);
        Vec3f n;
        const float d = exact.signedDistance(p, &n);
        EXPECT_NEAR(std::abs(d), bruteDistance(m, p), 1e-6f);
        // Inside the egg <=> the ray from p along +X crosses the surface an odd number of times.
        int crossings = 0;
        float t0 = 0;
        for (RayHit h; (h = exact.query().intersect(p, Vec3f::UnitX(), t0)).hit(); t0 = h.t + 1e-6f) ++crossings;
        EXPECT_EQ(d < 0, crossings % 2 == 1) << p.transpose() << " d=" << d;
        inside += d < 0;
        EXPECT_NEAR(n.norm(), 1.f, 1e-4f);
        // Moving along the normal by a small step changes d by that step.
        if (std::abs(d) > 2e-3f) {
            EXPECT_NEAR(exact.signedDistance(p + 1e-3f * n), d + 1e-3f, 2e-5f);
        }
    }
    EXPECT_GT(inside, 10);
}

TEST(LevelSet, MatchesTheExactDistanceNearTheSurface) {
    const TriangleMesh m = egg();
    const auto& grid = eggGrid();
    const MeshCollider exact(m);
    std::mt19937 rng(13);
    double worst = 0, worstAngle = 0;
    int tested = 0;
    for (int i = 0; i < 2000 && tested < 400; ++i) {
        const Vec3f p = randomPoint(rng, 0.13f);
        Vec3f ne;
        const float de = exact.signedDistance(p, &ne);
        if (std::abs(de) > 0.004f) continue;
        float dg;
        Vec3f g;
        ASSERT_TRUE(grid->sample(p, dg, &g)) << "inside the band";
        ++tested;
        worst = std::max(worst, double(std::abs(dg - de)));
        if (std::abs(de) > 0.002f) worstAngle = std::max(worstAngle, std::acos(std::clamp(double(g.normalized().dot(ne)), -1.0, 1.0)));
    }
    EXPECT_GE(tested, 100);
    EXPECT_LT(worst, 0.25e-3) << "trilinear error of a 2 mm grid";
    EXPECT_LT(worstAngle * 180 / M_PI, 10.0) << "gradient direction";
    // Deep inside and far outside: outside the band, the right sign.
    float d;
    EXPECT_FALSE(grid->sample(Vec3f(0, 0, 0), d));
    EXPECT_LT(d, 0.f);
    EXPECT_FALSE(grid->sample(Vec3f(0, 0.3f, 0), d));
    EXPECT_GT(d, 0.f);
    EXPECT_GT(grid->activeVoxelCount(), 10000u);
    EXPECT_NEAR(grid->bounds().max().y(), 0.11f + 0.006f, 0.002f) << "band bounds around the egg's top";
}

TEST(LevelSetCollider, FollowsTheRigidTransformAndBoundsFarPoints) {
    const TriangleMesh rest = egg();
    const auto& grid = eggGrid();
    const auto restExact = std::make_shared<const MeshCollider>(rest);
    const Eigen::Isometry3f T = Eigen::Translation3f(0.3f, -0.1f, 0.2f) * Eigen::AngleAxisf(1.1f, Vec3f(1, 2, 3).normalized());
    const LevelSetCollider moved(grid, T, restExact);
    TriangleMesh world = rest;
    for (Vec3f& p : world.positions) p = T * p;
    const MeshCollider worldExact(world);
    std::mt19937 rng(17);
    for (int i = 0; i < 300; ++i) {
        const Vec3f p = T * randomPoint(rng, 0.15f);
        Vec3f n, ne;
        const float d = moved.signedDistance(p, &n);
        const float de = worldExact.signedDistance(p, &ne);
        EXPECT_EQ(d < 0, de < 0) << "sign everywhere (deep inside through the exact fallback)";
        if (std::abs(de) < 0.004f) {
            EXPECT_NEAR(d, de, 0.3e-3f);
            EXPECT_GT(n.dot(ne), 0.97f);
        } else if (de > 0) {
            EXPECT_LE(d, de + 0.3e-3f) << "beyond the band: a lower bound";
            EXPECT_GE(d, std::min(de, 0.006f) - 2.1e-3f) << "at least the band width less a voxel";
        } else {
            EXPECT_NEAR(d, de, 0.3e-3f) << "deep inside: exact";
        }
    }
}
