// Groom modifiers (sim/strands/groom_modifiers.h), the neighbour-angle figure
// (sim/followers/follower_metrics.h) and the followers' statistics: length error and
// penetration when the head pushes a follower (sim/followers/followers.h).
#include "core/errors.h"
#include "follower_support.h"
#include "pipeline/scene/follower_settings.h"
#include "pipeline/stages/shot_simulation.h"
#include "sim/followers/follower_metrics.h"
#include "sim/followers/followers.h"
#include "sim/strands/groom_modifiers.h"
#include "sim/strands/synthetic_groom.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

using namespace hp;
using hp::test::SphereScene;

namespace {

/// Followers on a flat scalp (the plane y = 0, normal +Y, tangent +X) on a
/// jittered grid, straight along +Y: parallel copies, neighbour angle 0.
struct FlatGroom {
    std::vector<SurfaceFrame> roots;
    RestShapes shapes;
};

FlatGroom flatGroom(int side, int vertices, float length) {
    FlatGroom g;
    for (int i = 0; i < side; ++i)
        for (int j = 0; j < side; ++j) {
            SurfaceFrame f;
            const float jitter = 0.3f * std::sin(float(i * 37 + j * 11));
            f.position = Vec3f(0.002f * (float(i) + jitter), 0.f, 0.002f * (float(j) - jitter));
            f.normal = Vec3f::UnitY();
            f.tangent = Vec3f::UnitX();
            g.roots.push_back(f);
        }
    g.shapes = RestShapes::straight(g.roots.size(), vertices, length);
    return g;
}

/// The rest strands in world space: root + [t, n, t × n] p.
StrandFrame worldStrands(const std::vector<SurfaceFrame>& roots, const RestShapes& shapes) {
    StrandFrame frame;
    for (size_t f = 0; f < roots.size(); ++f) {
        const Vec3f t = roots[f].tangent, n = roots[f].normal, z = t.cross(n);
        std::vector<Vec3f> p;
        for (uint32_t k = shapes.offsets[f]; k < shapes.offsets[f + 1]; ++k) {
            const Vec3f& q = shapes.points[k];
            p.push_back(roots[f].position + q.x() * t + q.y() * n + q.z() * z);
        }
        const std::vector<float> r(p.size(), 1e-4f);
        frame.addStrand(uint32_t(f), p.data(), r.data(), p.size());
    }
    return frame;
}

/// Largest |L_k / (λ L⁰_k) - 1| over all segments, λ the strand's own
/// length ratio (1 when lengths are not varied).
double worstLengthRatio(const RestShapes& base, const RestShapes& shapes) {
    double worst = 0;
    for (size_t f = 0; f < base.count(); ++f) {
        const uint32_t a = base.offsets[f], n = base.offsets[f + 1] - a;
        double total = 0, total0 = 0;
        for (uint32_t k = 0; k + 1 < n; ++k) {
            total += (shapes.points[a + k + 1] - shapes.points[a + k]).cast<double>().norm();
            total0 += (base.points[a + k + 1] - base.points[a + k]).cast<double>().norm();
        }
        const double lambda = total / total0;
        for (uint32_t k = 0; k + 1 < n; ++k) {
            const double l = (shapes.points[a + k + 1] - shapes.points[a + k]).cast<double>().norm();
            const double l0 = (base.points[a + k + 1] - base.points[a + k]).cast<double>().norm();
            worst = std::max(worst, std::abs(l / (lambda * l0) - 1.0));
        }
    }
    return worst;
}

}  // namespace

TEST(GroomModifiers, ZeroSettingsGiveTodaysStrandsBitForBit) {
    const SphereScene scene(40, 600, 0.7);
    const FollowerGroom& original = scene.groom;
    FollowerGroom modified = original;
    GroomModifiers none;
    none.clumps = 500;  // a clump count without a clump weight changes nothing
    applyGroomModifiers(modified, none);
    EXPECT_EQ(modified.followerShapes.count(), 0u);
    EXPECT_FALSE(groomModifiers(Scene::parse("", "shot.yaml", ".")).active()) << "the schema's defaults are off";

    StrandFrame a, b;
    Followers(original, {}).update({scene.guides, scene.guideRoots, scene.followerRoots}, a);
    Followers(modified, {}).update({scene.guides, scene.guideRoots, scene.followerRoots}, b);
    ASSERT_EQ(a.positions.size(), b.positions.size());
    EXPECT_EQ(std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Vec3f)), 0);
}

TEST(GroomModifiers, BaseShapesAreTheShapesFollowersTakeFromTheirGuide) {
    // Own rest shapes equal to followerBaseShapes give the followers of a
    // groom without own shapes, in motion too (to float rounding).
    const SphereScene scene(40, 600, 0.9);
    const FollowerGroom& original = scene.groom;
    FollowerGroom own = original;
    own.followerShapes = followerBaseShapes(original);
    ASSERT_EQ(own.followerShapes.count(), original.followerRoots.size());
    StrandFrame a, b;
    Followers(original, {}).update({scene.guides, scene.guideRoots, scene.followerRoots}, a);
    Followers(own, {}).update({scene.guides, scene.guideRoots, scene.followerRoots}, b);
    float worst = 0.f;
    for (size_t v = 0; v < a.positions.size(); ++v) worst = std::max(worst, (a.positions[v] - b.positions[v]).norm());
    EXPECT_LT(worst, 2e-6f) << "m, over strands of 0.25 m";
}

TEST(GroomModifiers, EachModifierMovesTheNeighbourAngleAndKeepsLengths) {
    const FlatGroom g = flatGroom(40, 24, 0.2f);
    const double parallel = medianNeighbourAngle(worldStrands(g.roots, g.shapes), 0);
    EXPECT_NEAR(parallel, 0.0, 1e-3) << "parallel copies";

    struct Case { const char* name; GroomModifiers m; double above; };
    std::vector<Case> cases(5);
    cases[0].name = "length variation";
    cases[0].m.lengthVariation = 0.4f;  // scaled copies: the same tangents, so the figure stays 0
    cases[1].name = "clump";
    cases[1].m.clump = 0.7f;
    cases[1].m.clumps = 40;
    cases[2].name = "wave";
    cases[2].m.wave = 0.004f;
    cases[3].name = "curl";
    cases[3].m.wave = 0.004f;
    cases[3].m.curl = 1.f;
    cases[4].name = "frizz";
    cases[4].m.frizz = 0.004f;
    // Above 0 for each; clumping least at mid-strand (neighbours of one clump
    // lean alike: ≈ clump × spacing / length rad), most at the clump edges.
    for (int i = 0; i < 5; ++i) cases[i].above = i == 0 ? -1.0 : i == 1 ? 0.1 : 1.0;
    for (const Case& c : cases) {
        const RestShapes shapes = modifyFollowerShapes(g.shapes, g.roots, c.m);
        const double angle = medianNeighbourAngle(worldStrands(g.roots, shapes), 0);
        if (c.above >= 0) EXPECT_GT(angle, c.above) << c.name;
        else EXPECT_NEAR(angle, 0.0, 1e-3) << c.name;
        // Float coordinates of 0.2 m hold a 9 mm segment to ~2e-6.
        EXPECT_LT(worstLengthRatio(g.shapes, shapes), 1e-5) << c.name << ": segment lengths";
        std::printf("%-16s median neighbour angle %.2f deg\n", c.name, angle);
    }
    // Length variation: lengths in [(1 - 0.4) L, L], and they do vary.
    const RestShapes varied = modifyFollowerShapes(g.shapes, g.roots, cases[0].m);
    float shortest = 1.f, longest = 0.f;
    for (size_t f = 0; f < varied.count(); ++f) {
        const float tip = varied.points[varied.offsets[f + 1] - 1].norm();
        shortest = std::min(shortest, tip);
        longest = std::max(longest, tip);
    }
    EXPECT_GE(shortest, 0.6f * 0.2f - 1e-6f);
    EXPECT_LE(longest, 0.2f + 1e-6f);
    EXPECT_GT(longest - shortest, 0.05f);

    // Stronger clumping pulls the tips of a clump together.
    GroomModifiers weak, strong;
    weak.clumps = strong.clumps = 40;
    weak.clump = 0.2f;
    strong.clump = 0.9f;
    const StrandFrame w = worldStrands(g.roots, modifyFollowerShapes(g.shapes, g.roots, weak));
    const StrandFrame st = worldStrands(g.roots, modifyFollowerShapes(g.shapes, g.roots, strong));
    EXPECT_GT(medianNeighbourAngle(st, 0), medianNeighbourAngle(w, 0));
}

TEST(GroomModifiers, SeededAndIndependentOfThreads) {
    const FlatGroom g = flatGroom(20, 16, 0.15f);
    GroomModifiers m;
    m.lengthVariation = 0.2f;
    m.clump = 0.5f;
    m.clumps = 10;
    m.wave = 0.003f;
    m.curl = 0.3f;
    m.frizz = 0.002f;
    const RestShapes a = modifyFollowerShapes(g.shapes, g.roots, m);
    const RestShapes b = modifyFollowerShapes(g.shapes, g.roots, m);
    EXPECT_EQ(std::memcmp(a.points.data(), b.points.data(), a.points.size() * sizeof(Vec3f)), 0);
    m.seed = 2;
    const RestShapes c = modifyFollowerShapes(g.shapes, g.roots, m);
    EXPECT_NE(std::memcmp(a.points.data(), c.points.data(), a.points.size() * sizeof(Vec3f)), 0);
    GroomModifiers bad;
    bad.clump = 2.f;
    EXPECT_THROW(modifyFollowerShapes(g.shapes, g.roots, bad), Error);
}

TEST(GroomModifiers, SceneKeys) {
    const GroomModifiers m = groomModifiers(Scene::parse(
        "seed: 7\nhair:\n  followers:\n    length_variation: 0.3\n    clump: 0.5\n    clumps: 100\n"
        "    wave: 0.002\n    curl: 0.5\n    frizz: 0.001\n",
        "shot.yaml", "."));
    EXPECT_FLOAT_EQ(m.lengthVariation, 0.3f);
    EXPECT_FLOAT_EQ(m.clump, 0.5f);
    EXPECT_EQ(m.clumps, 100u);
    EXPECT_FLOAT_EQ(m.wave, 0.002f);
    EXPECT_FLOAT_EQ(m.curl, 0.5f);
    EXPECT_FLOAT_EQ(m.frizz, 0.001f);
    EXPECT_EQ(m.seed, 7u);
    try {
        Scene::parse("hair:\n  followers:\n    clump: 1.5\n", "shot.yaml", ".");
        FAIL() << "clump above 1 must be rejected";
    } catch (const SceneError& e) {
        EXPECT_EQ(e.key(), "hair.followers.clump");
    }
}

// ---------------------------------------------------------------------------
// Follower statistics

TEST(FollowerStats, AFollowerForcedInsideTheHeadStaysAtLengthAndIsCounted) {
    // Sphere head r = 0.1. The guide stands on the top, straight down into
    // the head (cluster mode copies it); one follower's root is 3 cm deep:
    // its first vertex cannot reach the surface at its segment length
    // (1.1 cm), so it must stay inside at length, not stretch to the surface.
    const float R = 0.1f, L = 0.25f / 23.f;
    const SphereCollider head(Vec3f::Zero(), R);
    SurfaceFrame g;
    g.position = Vec3f(0, R, 0);
    g.normal = Vec3f::UnitY();
    g.tangent = Vec3f::UnitX();
    SurfaceFrame deep = g, side = g;
    deep.position = Vec3f(0.f, R - 0.03f, 0.f);
    side.position = Vec3f(0.01f, std::sqrt(R * R - 1e-4f), 0.f);
    side.normal = side.position.normalized();
    FollowerGroom groom;
    groom.guideRoots = {g};
    groom.guideShapes = RestShapes::straight(1, 24, 0.25f);
    groom.followerRoots = {deep, side};
    FollowerSettings settings;
    settings.mode = FollowerMode::Cluster;
    Followers followers(groom, settings);
    StrandFrame guides;
    std::vector<Vec3f> down;
    for (int k = 0; k < 24; ++k) down.push_back(g.position - float(k) * L * Vec3f::UnitY() + Vec3f(1e-3f * k, 0, 0));
    const std::vector<float> r(24, 1e-4f);
    guides.addStrand(0, down.data(), r.data(), 24);
    guides.guideCount = 1;
    StrandFrame out;
    const FollowerStats stats = followers.update({guides, {g}, {deep, side}, &head}, out);

    // Independent measures over the follower vertices (the roots excluded: they are given).
    size_t inside = 0;
    double deepest = 0, worst = 0;
    for (size_t s = 1; s < out.strandCount(); ++s)
        for (uint32_t v = out.first(s) + 1; v < out.offsets[s + 1]; ++v) {
            const double d = head.signedDistance(out.positions[v]);
            if (d < 0) ++inside, deepest = std::max(deepest, -d);
            worst = std::max(worst, std::abs(double((out.positions[v] - out.positions[v - 1]).norm()) / L - 1.0));
        }
    EXPECT_GT(inside, 0u) << "the deep follower's first vertices cannot get out";
    EXPECT_EQ(stats.penetrationCount, inside);
    EXPECT_NEAR(stats.maxPenetration, deepest, 1e-6);
    EXPECT_LT(worst, 1e-5) << "pushed out, never stretched";
    const Followers::LengthError e = followers.lengthError(out);
    EXPECT_NEAR(e.max, worst, 1e-6);
    EXPECT_LE(e.mean, e.max);
    std::printf("inside %zu, deepest %.4f m, max length error %.2e\n", inside, deepest, worst);
}

TEST(FollowerStats, FrameStatisticsNameGuidesAndFollowersSeparately) {
    SimFrameStats s;
    s.guides.maxLengthError = 0.25;
    s.guides.penetrationCount = 3;
    s.followers.maxLengthError = 0.5;
    s.followers.penetrationCount = 7;
    s.followers.maxPenetration = 0.002;
    const std::string j = s.json();
    EXPECT_NE(j.find("\"guides\": {\"max_length_error\": 0.25,"), std::string::npos) << j;
    EXPECT_NE(j.find("\"followers\": {\"max_length_error\": 0.5,"), std::string::npos) << j;
    EXPECT_NE(j.find("\"penetration_count\": 7, \"max_penetration\": 0.002"), std::string::npos) << j;
    EXPECT_LT(j.find("\"max_length_error\": 0.25"), j.find("\"followers\"")) << "the old top-level key stays first";
}
