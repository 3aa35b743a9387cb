// Hair root placement on a scalp (sim/strands/roots.h).
#include "core/errors.h"
#include "sim/strands/fibonacci.h"
#include "sim/collision/mesh_query.h"
#include "sim/strands/roots.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <random>

using namespace hp;

namespace {

const float kRadius = 0.1f;

/// The upper hemisphere (y > 0) of a sphere head as the scalp.
struct SphereScalp {
    TriangleMesh mesh = makeSphereMesh(Vec3f::Zero(), kRadius, 48, 96);
    std::vector<uint8_t> scalp;
    SphereScalp() {
        for (const Tri& t : mesh.triangles) {
            const Vec3f c = (mesh.positions[t[0]] + mesh.positions[t[1]] + mesh.positions[t[2]]) / 3.f;
            scalp.push_back(c.y() > 0.f);
        }
    }
};

std::vector<Vec3f> positions(const TriangleMesh& m, const std::vector<SurfacePoint>& roots) {
    std::vector<Vec3f> p;
    for (const SurfacePoint& r : roots) p.push_back(evaluate(m, r).position);
    return p;
}

float minimumSpacing(const std::vector<Vec3f>& p) {
    float best = std::numeric_limits<float>::infinity();
    for (size_t i = 0; i < p.size(); ++i)
        for (size_t j = i + 1; j < p.size(); ++j) best = std::min(best, (p[i] - p[j]).norm());
    return best;
}

/// The largest distance from a random scalp point to its nearest root: the
/// biggest bald spot.
float largestGap(const SphereScalp& s, const std::vector<Vec3f>& roots) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(-1, 1);
    float worst = 0;
    for (int i = 0; i < 2000; ++i) {
        Vec3f d(u(rng), std::abs(u(rng)) * 0.9f + 0.05f, u(rng));
        const Vec3f p = kRadius * d.normalized();
        float best = std::numeric_limits<float>::infinity();
        for (const Vec3f& r : roots) best = std::min(best, (r - p).norm());
        worst = std::max(worst, best);
    }
    return worst;
}

bool same(const std::vector<SurfacePoint>& a, const std::vector<SurfacePoint>& b) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i)
        if (a[i].triangle != b[i].triangle || a[i].b1 != b[i].b1 || a[i].b2 != b[i].b2) return false;
    return true;
}

}  // namespace

TEST(Roots, FibonacciGivesTheExactCountOnTheScalpOnly) {
    const SphereScalp s;
    for (size_t n : {94u, 845u, 3000u}) {
        RootSettings rs;
        rs.count = n;
        const std::vector<SurfacePoint> roots = placeRoots(s.mesh, s.scalp, rs);
        ASSERT_EQ(roots.size(), n);
        for (const SurfacePoint& r : roots) {
            ASSERT_TRUE(s.scalp[r.triangle]);
            ASSERT_GE(r.b1, 0.f);
            ASSERT_GE(r.b2, 0.f);
            ASSERT_LE(r.b1 + r.b2, 1.f + 1e-6f);
        }
    }
}

TEST(Roots, FibonacciOnASphereMatchesTheSeedLattice) {
    // On a sphere about its centre the projection is radial, so root i is
    // Gomes 2024's Fibonacci cap point i (the lattice size may differ by one
    // where a point falls exactly on the scalp's edge: Δ ≤ 2i/n²).
    const SphereScalp s;
    RootSettings rs;
    rs.count = 845;
    rs.center = Vec3f::Zero();
    rs.axis = Vec3f::UnitY();
    const std::vector<Vec3f> p = positions(s.mesh, placeRoots(s.mesh, s.scalp, rs));
    const std::vector<Vec3f> lattice = fibonacciCap(845);
    ASSERT_EQ(p.size(), lattice.size());
    for (size_t i = 0; i < p.size(); ++i)
        EXPECT_LT((p[i].normalized() - lattice[i]).norm(), 2e-3f) << "root " << i << " is lattice point " << i;
}

TEST(Roots, BlueNoiseIsEvenInAreaAndKeepsRootsApart) {
    const SphereScalp s;
    RootSettings rs;
    rs.method = RootMethod::BlueNoise;
    rs.count = 845;
    const std::vector<Vec3f> p = positions(s.mesh, placeRoots(s.mesh, s.scalp, rs));
    ASSERT_EQ(p.size(), 845u);
    const double area = surfaceArea(s.mesh, s.scalp);
    EXPECT_NEAR(area, 2 * M_PI * kRadius * kRadius, 0.01 * area);
    const double rMax = std::sqrt(area / (2 * std::sqrt(3.0) * 845));
    // Sample elimination keeps roots well apart (2 r_max is the spacing of a
    // hexagonal packing) and leaves smaller bald spots than uniform random
    // roots (its own candidates, ratio 1).
    rs.candidateRatio = 1;
    const std::vector<Vec3f> random = positions(s.mesh, placeRoots(s.mesh, s.scalp, rs));
    EXPECT_GT(minimumSpacing(p), 1.2 * rMax);
    EXPECT_LT(minimumSpacing(random), 0.2 * rMax);
    EXPECT_LT(largestGap(s, p), 2.2 * rMax);
    EXPECT_LT(largestGap(s, p), 0.8 * largestGap(s, random));
    // Even in area: the fraction of roots above y = r/2 is the fraction of area, 1/2.
    const size_t high = std::count_if(p.begin(), p.end(), [](const Vec3f& q) { return q.y() > kRadius / 2; });
    EXPECT_NEAR(double(high) / 845.0, 0.5, 0.03);
}

TEST(Roots, FibonacciCoversTheScalp) {
    const SphereScalp s;
    RootSettings rs;
    rs.count = 845;
    const std::vector<Vec3f> p = positions(s.mesh, placeRoots(s.mesh, s.scalp, rs));
    const double rMax = std::sqrt(surfaceArea(s.mesh, s.scalp) / (2 * std::sqrt(3.0) * 845));
    EXPECT_LT(largestGap(s, p), 1.6 * rMax);
    EXPECT_GT(minimumSpacing(p), 1.2 * rMax);
}

TEST(Roots, DeterministicForASeedWhateverTheThreadCount) {
    const SphereScalp s;
    for (RootMethod method : {RootMethod::Fibonacci, RootMethod::BlueNoise}) {
        RootSettings rs;
        rs.method = method;
        rs.count = 2000;
        rs.seed = 7;
        std::vector<SurfacePoint> one, two;
        tbb::task_arena(1).execute([&] { one = placeRoots(s.mesh, s.scalp, rs); });
        tbb::task_arena(2).execute([&] { two = placeRoots(s.mesh, s.scalp, rs); });
        EXPECT_TRUE(same(one, two)) << int(method);
        EXPECT_TRUE(same(one, placeRoots(s.mesh, s.scalp, rs)));
        rs.seed = 8;
        const bool changed = !same(one, placeRoots(s.mesh, s.scalp, rs));
        EXPECT_EQ(changed, method == RootMethod::BlueNoise) << "only blue noise is random";
    }
}

TEST(Roots, HundredsOfThousandsOfRoots) {
    // The follower counts of the benchmarks (B-follow): must take seconds, not minutes.
    const SphereScalp s;
    RootSettings rs;
    rs.count = 100000;
    EXPECT_EQ(placeRoots(s.mesh, s.scalp, rs).size(), 100000u);
    rs.method = RootMethod::BlueNoise;
    rs.count = 50000;
    EXPECT_EQ(placeRoots(s.mesh, s.scalp, rs).size(), 50000u);
}

TEST(Roots, ScalpOnAnOffCentreHeadAndBadMasks) {
    // A head away from the origin with the scalp on its side: the centre comes
    // from the sphere fit, not the origin.
    SphereScalp s;
    for (Vec3f& p : s.mesh.positions) p += Vec3f(1, 2, 3);
    for (size_t t = 0; t < s.mesh.triangles.size(); ++t)
        s.scalp[t] = s.mesh.positions[s.mesh.triangles[t][0]].x() > 1.05f;
    RootSettings rs;
    rs.count = 300;
    for (const SurfacePoint& r : placeRoots(s.mesh, s.scalp, rs)) EXPECT_TRUE(s.scalp[r.triangle]);
    Vec3f c;
    float radius;
    std::vector<Vec3f> sample;
    for (const Vec3f& p : s.mesh.positions)
        if (p.x() > 1.05f) sample.push_back(p);
    ASSERT_TRUE(fitSphere(sample, c, radius));
    EXPECT_LT((c - Vec3f(1, 2, 3)).norm(), 1e-3f);
    EXPECT_NEAR(radius, kRadius, 1e-3f);

    std::vector<uint8_t> none(s.scalp.size(), 0);
    EXPECT_THROW(placeRoots(s.mesh, none, rs), Error);
    EXPECT_THROW(placeRoots(s.mesh, std::vector<uint8_t>(3, 1), rs), Error);
}
