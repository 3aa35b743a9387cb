// Follower strands (sim/followers/followers.h): the three modes against shapes
// computed independently (neighbour selection: test_follower_neighbours.cpp), thread and lane independence,
// lengths, velocities and head collision (kernels: test_follower_kernels.cpp).
#include "core/errors.h"
#include "follower_support.h"
#include "sim/followers/follower_kernels.h"
#include "sim/followers/follower_neighbours.h"
#include "sim/followers/followers.h"
#include "sim/strands/synthetic_groom.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numeric>
#include <random>

using namespace hp;
using hp::test::frameAt;
using hp::test::sphereGroom;

namespace {

SurfaceFrame rotated(const SurfaceFrame& f, const Eigen::Quaternionf& q, const Vec3f& position) {
    return frameAt(position, q * f.normal, q * f.tangent);
}

StrandFrame guideFrame(const std::vector<std::vector<Vec3f>>& strands, const Vec3f& velocity = Vec3f::Zero()) {
    StrandFrame f;
    for (size_t s = 0; s < strands.size(); ++s) {
        const std::vector<float> r(strands[s].size(), 1e-4f);
        const std::vector<Vec3f> v(strands[s].size(), velocity);
        f.addStrand(uint32_t(s), strands[s].data(), r.data(), strands[s].size(), v.data());
    }
    f.guideCount = uint32_t(strands.size());
    return f;
}

/// The groom's guides standing straight along their root normals (each
/// vertex at its rest shape's height y), with `velocity` on every vertex when
/// given and no velocities otherwise.
StrandFrame straightGuides(const FollowerGroom& groom, const Vec3f* velocity = nullptr) {
    StrandFrame guides;
    for (size_t g = 0; g < groom.guideRoots.size(); ++g) {
        std::vector<Vec3f> p;
        for (uint32_t k = groom.guideShapes.offsets[g]; k < groom.guideShapes.offsets[g + 1]; ++k)
            p.push_back(groom.guideRoots[g].position + groom.guideShapes.points[k].y() * groom.guideRoots[g].normal);
        const std::vector<float> r(p.size(), 1e-4f);
        const std::vector<Vec3f> v(velocity ? p.size() : 0, velocity ? *velocity : Vec3f::Zero());
        guides.addStrand(uint32_t(g), p.data(), r.data(), p.size(), velocity ? v.data() : nullptr);
    }
    return guides;
}

/// A planar strand from `root`: segment y leaves at angle theta(y) from +Y toward +X.
template <typename Angle>
std::vector<Vec3f> planarStrand(const Vec3f& root, int segments, float length, Angle theta) {
    std::vector<Vec3f> p{root};
    for (int y = 0; y < segments; ++y)
        p.push_back(p.back() + length * Vec3f(std::sin(theta(y)), std::cos(theta(y)), 0.f));
    return p;
}

std::vector<Vec3f> strandOf(const StrandFrame& f, size_t s) {
    return {f.positions.begin() + f.first(s), f.positions.begin() + f.offsets[s + 1]};
}

float maxDistance(const std::vector<Vec3f>& a, const std::vector<Vec3f>& b) {
    EXPECT_EQ(a.size(), b.size());
    float m = 0.f;
    for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) m = std::max(m, (a[i] - b[i]).norm());
    return m;
}

/// One guide with frame `g` and current shape `shape`, one follower with rest frame `fRest`, current `fNow`.
std::vector<Vec3f> singleFollower(const SurfaceFrame& g, const std::vector<Vec3f>& shape, const SurfaceFrame& fRest,
                                  const SurfaceFrame& fNow, FollowerMode mode = FollowerMode::Cluster) {
    FollowerGroom groom;
    groom.guideRoots = {g};
    groom.guideShapes = RestShapes::straight(1, int(shape.size()), 0.25f);
    groom.followerRoots = {fRest};
    groom.followerVertices = {uint32_t(shape.size())};
    groom.followerLengths = {0.25f};
    FollowerSettings settings;
    settings.mode = mode;
    Followers followers(groom, settings);
    const StrandFrame guides = guideFrame({shape});
    StrandFrame out;
    followers.update({guides, {g}, {fNow}}, out);
    return strandOf(out, 1);
}

std::vector<Vec3f> bentShape(const SurfaceFrame& g, int vertices) {
    const float L = 0.25f / float(vertices - 1);
    const Vec3f z = g.tangent.cross(g.normal);
    std::vector<Vec3f> p{g.position};
    for (int y = 0; y + 1 < vertices; ++y) {
        const float a = 0.09f * y, b = 0.3f * std::sin(0.4f * y);
        const Vec3f d = std::sin(a) * std::cos(b) * g.tangent + std::cos(a) * g.normal + std::sin(a) * std::sin(b) * z;
        p.push_back(p.back() + L * d.normalized());
    }
    return p;
}

}  // namespace

// ---------------------------------------------------------------------------
// Modes

TEST(Followers, ClusterIsTheGuideMovedToTheFollowersRoot) {
    const SurfaceFrame g = frameAt(Vec3f(0.01f, 0.1f, 0.f), Vec3f(0.1f, 1.f, 0.f), Vec3f(1.f, 0.f, 0.3f));
    const std::vector<Vec3f> shape = bentShape(g, 24);
    // Same frame, other place: the guide translated.
    const Vec3f offset(0.004f, -0.001f, 0.006f);
    SurfaceFrame f = g;
    f.position += offset;
    std::vector<Vec3f> expected = shape;
    for (Vec3f& p : expected) p += offset;
    EXPECT_LT(maxDistance(singleFollower(g, shape, f, f), expected), 2e-6f);

    // Frame tilted by a rotation about an axis across the normal: the guide rotated.
    const Eigen::Quaternionf tilt(Eigen::AngleAxisf(0.5f, g.normal.cross(Vec3f(0.3f, 0.f, 1.f)).normalized()));
    const SurfaceFrame ft = rotated(g, tilt, g.position + offset);
    for (size_t i = 0; i < shape.size(); ++i) expected[i] = ft.position + tilt * (shape[i] - g.position);
    EXPECT_LT(maxDistance(singleFollower(g, shape, ft, ft), expected), 2e-6f);

    // The follower's frame turning now (rest frames equal): the shape turns with it.
    const Eigen::Quaternionf spin(Eigen::AngleAxisf(0.7f, g.normal));
    const SurfaceFrame fs = rotated(f, spin, f.position);
    for (size_t i = 0; i < shape.size(); ++i) expected[i] = f.position + spin * (shape[i] - g.position);
    EXPECT_LT(maxDistance(singleFollower(g, shape, f, fs), expected), 2e-6f);
}

TEST(Followers, RestTangentsDoNotTwistFollowers) {
    // Mesh tangents follow triangle edges and differ between neighbours; a
    // follower whose rest tangent is turned 45° still copies the guide unturned.
    const SurfaceFrame g = frameAt(Vec3f(0, 0.1f, 0), Vec3f::UnitY(), Vec3f::UnitX());
    const std::vector<Vec3f> shape = bentShape(g, 24);
    const Vec3f offset(0.005f, 0.f, 0.f);
    const Eigen::Quaternionf turn(Eigen::AngleAxisf(float(M_PI / 4), Vec3f::UnitY()));
    const SurfaceFrame f = rotated(g, turn, g.position + offset);
    std::vector<Vec3f> expected = shape;
    for (Vec3f& p : expected) p += offset;
    EXPECT_LT(maxDistance(singleFollower(g, shape, f, f), expected), 2e-6f);
    EXPECT_LT(maxDistance(singleFollower(g, shape, f, f, FollowerMode::Varied), expected), 2e-6f)
        << "one guide: varied slerps the guide with itself";
}

TEST(Followers, FixedOffsetShapeWithStillGuidesAndDistanceWeightWhenInterpolating) {
    // Two guides bent in the XY plane (frames: normal +Y, tangent +X), so every
    // segment rotation is about Z and slerp is a blend of angles:
    // follower angle(y) = (1 - w) θ1(y) + w θ2(y).
    const int S = 23;
    const float L = 0.25f / S;
    auto th1 = [](int y) { return 0.05f * y; };
    auto th2 = [](int y) { return 0.02f * y + 0.3f * std::sin(0.3f * y); };
    const SurfaceFrame g1 = frameAt(Vec3f::Zero(), Vec3f::UnitY(), Vec3f::UnitX());
    const SurfaceFrame g2 = frameAt(Vec3f(0.02f, 0, 0), Vec3f::UnitY(), Vec3f::UnitX());
    const SurfaceFrame f = frameAt(Vec3f(0.005f, 0, 0), Vec3f::UnitY(), Vec3f::UnitX());
    FollowerGroom groom;
    groom.guideRoots = {g1, g2};
    groom.guideShapes = RestShapes::straight(2, S + 1, 0.25f);
    groom.followerRoots = {f};
    const StrandFrame still = guideFrame({planarStrand(g1.position, S, L, th1), planarStrand(g2.position, S, L, th2)});

    for (FollowerMode mode : {FollowerMode::Varied, FollowerMode::Interpolate}) {
        FollowerSettings settings;
        settings.mode = mode;
        Followers followers(groom, settings);
        StrandFrame out;
        followers.update({still, {g1, g2}, {f}}, out);
        auto weight = [&](int y) {
            return mode == FollowerMode::Varied ? 0.2f * follower::fixedOffsetCurve(float(y), S) : 0.005f / 0.02f;
        };
        const std::vector<Vec3f> expected =
            planarStrand(f.position, S, L, [&](int y) { return (1 - weight(y)) * th1(y) + weight(y) * th2(y); });
        EXPECT_LT(maxDistance(strandOf(out, 2), expected), 2e-6f);
        if (mode == FollowerMode::Varied) {
            // d_f = 0 at root and tip: those segments are guide 1's.
            const auto p = strandOf(out, 2);
            EXPECT_LT(((p[1] - p[0]) - (still.positions[1] - still.positions[0])).norm(), 1e-7f);
            EXPECT_LT(((p[S] - p[S - 1]) - (still.positions[S] - still.positions[S - 1])).norm(), 1e-7f);
        }
    }

    // Moving guides: each segment's weight varies by at most d_v = min(|v1|, 0.1) around 0.2 d_f.
    for (float speed : {0.03f, 2.f}) {
        Followers followers(groom, {});
        const StrandFrame moving = guideFrame({planarStrand(g1.position, S, L, th1), planarStrand(g2.position, S, L, th2)},
                                              Vec3f(0, 0, speed));
        StrandFrame out;
        followers.update({moving, {g1, g2}, {f}}, out);
        const auto p = strandOf(out, 2);
        float largest = 0;
        for (int y = 1; y < S; ++y) {
            const Vec3f d = (p[y + 1] - p[y]) / L;
            const float angle = std::atan2(d.x(), d.y());
            const float w = (angle - th1(y)) / (th2(y) - th1(y));
            const float dev = w - 0.2f * follower::fixedOffsetCurve(float(y), S);
            EXPECT_LE(std::abs(dev), std::min(speed, 0.1f) * 1.001f + 1e-4f) << "segment " << y;
            largest = std::max(largest, std::abs(dev));
        }
        EXPECT_GT(largest, 0.5f * std::min(speed, 0.1f)) << "the variation is switched on by guide speed";
    }
}

TEST(Followers, AtRestFollowersKeepTheGroomsShape) {
    FollowerGroom groom = sphereGroom(94, 751);
    // A curved rest style shared by all guides (in each root frame).
    std::vector<Vec3f> style{Vec3f::Zero()};
    for (int y = 0; y < 23; ++y) style.push_back(style.back() + (0.25f / 23) * Vec3f(0.06f * y, 1.f, -0.02f * y).normalized());
    groom.guideShapes = RestShapes();
    for (size_t g = 0; g < groom.guideRoots.size(); ++g) groom.guideShapes.add(style.data(), style.size());
    Followers followers(groom, {});  // varied
    StrandFrame guides;
    for (size_t g = 0; g < groom.guideRoots.size(); ++g) {
        const SurfaceFrame& r = groom.guideRoots[g];
        std::vector<Vec3f> p;
        for (const Vec3f& l : style) p.push_back(r.position + l.x() * r.tangent + l.y() * r.normal + l.z() * r.tangent.cross(r.normal));
        const std::vector<float> radius(p.size(), 1e-4f);
        guides.addStrand(uint32_t(g), p.data(), radius.data(), p.size());
    }
    StrandFrame out;
    followers.update({guides, groom.guideRoots, groom.followerRoots}, out);
    // Expected: the nearest guide carried to the follower's root by the minimal rotation between the normals.
    float worst = 0;
    for (size_t f = 0; f < groom.followerRoots.size(); ++f) {
        const uint32_t g = followers.neighbours(f).guide1;
        const Eigen::Quaternionf carry = Eigen::Quaternionf::FromTwoVectors(groom.guideRoots[g].normal, groom.followerRoots[f].normal);
        std::vector<Vec3f> expected;
        for (size_t k = 0; k < style.size(); ++k)
            expected.push_back(groom.followerRoots[f].position + carry * (guides.positions[guides.first(g) + k] - groom.guideRoots[g].position));
        worst = std::max(worst, maxDistance(strandOf(out, groom.guideRoots.size() + f), expected));
    }
    EXPECT_LT(worst, 2e-6f);
}

TEST(Followers, OwnRestShapesAreKeptAtRestInTheirOwnFrames) {
    // Followers with their own (curly, uneven) rest shapes, given in their own
    // mesh root frames, and guides at rest: every follower is its rest shape.
    FollowerGroom groom = sphereGroom(94, 751);
    for (size_t f = 0; f < groom.followerRoots.size(); ++f) {
        std::vector<Vec3f> p{Vec3f::Zero()};
        for (int y = 0; y < 20; ++y)
            p.push_back(p.back() + (0.004f + 0.0005f * float((y + f) % 3)) *
                                       Vec3f(std::cos(0.9f * y + f), 1.2f, std::sin(0.9f * y + f)).normalized());
        groom.followerShapes.add(p.data(), p.size());
    }
    const StrandFrame guides = straightGuides(groom);
    for (FollowerMode mode : {FollowerMode::Varied, FollowerMode::Interpolate, FollowerMode::Cluster}) {
        FollowerSettings settings;
        settings.mode = mode;
        Followers followers(groom, settings);
        StrandFrame out;
        followers.update({guides, groom.guideRoots, groom.followerRoots}, out);
        float worst = 0;
        for (size_t f = 0; f < groom.followerRoots.size(); ++f) {
            const SurfaceFrame& r = groom.followerRoots[f];
            std::vector<Vec3f> expected;
            for (uint32_t k = groom.followerShapes.offsets[f]; k < groom.followerShapes.offsets[f + 1]; ++k) {
                const Vec3f& l = groom.followerShapes.points[k];
                expected.push_back(r.position + l.x() * r.tangent + l.y() * r.normal + l.z() * r.tangent.cross(r.normal));
            }
            worst = std::max(worst, maxDistance(strandOf(out, groom.guideRoots.size() + f), expected));
        }
        EXPECT_LT(worst, 1e-6f) << "mode " << int(mode);
    }
}

TEST(Followers, RigidMotionOfTheWholeHeadMovesFollowersRigidly) {
    const FollowerGroom groom = sphereGroom(94, 751);
    SyntheticGuideSettings gs;
    gs.degreesPerSecond = 0;
    const SyntheticGuides motion(groom, gs);
    StrandFrame guides;
    std::vector<SurfaceFrame> guideRoots;
    motion.sample(0.4, guides, guideRoots);
    const SphereCollider head(Vec3f::Zero(), 0.1f);
    Followers followers(groom, {});
    StrandFrame a, b;
    followers.update({guides, guideRoots, groom.followerRoots, &head}, a);

    const Eigen::Quaternionf q = Eigen::Quaternionf(Eigen::AngleAxisf(1.1f, Vec3f(0.3f, 1.f, -0.5f).normalized()));
    for (Vec3f& p : guides.positions) p = q * p;
    for (Vec3f& v : guides.velocities) v = q * v;
    std::vector<SurfaceFrame> guideRootsQ, followerRootsQ;
    rotateRoots(guideRoots, q, guideRootsQ);
    rotateRoots(groom.followerRoots, q, followerRootsQ);
    followers.update({guides, guideRootsQ, followerRootsQ, &head}, b);
    float worstP = 0, worstV = 0;
    for (size_t i = a.offsets[a.guideCount]; i < a.vertexCount(); ++i) {
        worstP = std::max(worstP, (q * a.positions[i] - b.positions[i]).norm());
        worstV = std::max(worstV, (q * a.velocities[i] - b.velocities[i]).norm());
    }
    EXPECT_LT(worstP, 1e-5f);
    EXPECT_LT(worstV, 1e-4f);
}

// ---------------------------------------------------------------------------
// Determinism, lengths, velocities, collision, errors

TEST(Followers, SameBitsOnOneAndTwoThreadsAndSerial) {
    const FollowerGroom groom = sphereGroom(200, 6000);
    const SyntheticGuides motion(groom, {});
    const SphereCollider head(Vec3f::Zero(), 0.1f);
    auto run = [&](int threads, bool parallel, FollowerMode mode) {
        FollowerSettings settings;
        settings.parallel = parallel;
        settings.mode = mode;
        Followers followers(groom, settings);
        StrandFrame guides, out;
        std::vector<SurfaceFrame> guideRoots, followerRoots;
        size_t projected = 0;
        tbb::task_arena arena(threads);
        arena.execute([&] {
            for (int step = 0; step < 3; ++step) {
                const double t = 0.3 + 0.02 * step;
                motion.sample(t, guides, guideRoots);
                rotateRoots(groom.followerRoots, motion.headRotation(t), followerRoots);
                projected += followers.update({guides, guideRoots, followerRoots, &head, step ? 0.02 : 0.0}, out).projected;
            }
        });
        return std::make_pair(out, projected);
    };
    for (FollowerMode mode : {FollowerMode::Varied, FollowerMode::Interpolate, FollowerMode::Cluster}) {
        const auto one = run(1, true, mode), two = run(2, true, mode), serial = run(2, false, mode);
        ASSERT_EQ(one.first.positions.size(), two.first.positions.size());
        const size_t bytes = one.first.positions.size() * sizeof(Vec3f);
        EXPECT_EQ(std::memcmp(one.first.positions.data(), two.first.positions.data(), bytes), 0);
        EXPECT_EQ(std::memcmp(one.first.velocities.data(), two.first.velocities.data(), bytes), 0);
        EXPECT_EQ(std::memcmp(one.first.positions.data(), serial.first.positions.data(), bytes), 0);
        EXPECT_EQ(one.second, two.second);
        EXPECT_NO_THROW(two.first.validate());
    }
}

TEST(Followers, AFollowerDoesNotDependOnItsPacketMates) {
    // Followers run 8 to a vector (lanes); dropping the first follower moves
    // every other one to another lane and packet. In interpolate and cluster
    // modes (rand_xy hashes the follower index) the strands stay the same bits.
    const FollowerGroom all = sphereGroom(94, 1003);  // not a multiple of 8: a partial last packet either way
    FollowerGroom rest = all;
    rest.followerRoots.erase(rest.followerRoots.begin());
    const SyntheticGuides motion(all, {});
    StrandFrame guides;
    std::vector<SurfaceFrame> guideRoots, rootsAll, rootsRest;
    motion.sample(0.7, guides, guideRoots);
    rotateRoots(all.followerRoots, motion.headRotation(0.7), rootsAll);
    rootsRest.assign(rootsAll.begin() + 1, rootsAll.end());
    const SphereCollider head(Vec3f::Zero(), 0.1f);
    for (FollowerMode mode : {FollowerMode::Interpolate, FollowerMode::Cluster}) {
        FollowerSettings settings;
        settings.mode = mode;
        Followers a(all, settings), b(rest, settings);
        StrandFrame outA, outB;
        const FollowerStats sa = a.update({guides, guideRoots, rootsAll, &head}, outA);
        b.update({guides, guideRoots, rootsRest, &head}, outB);
        EXPECT_GT(sa.projected, 0u) << "the collision path is exercised";
        const size_t G = guides.strandCount();
        for (size_t f = 1; f < all.followerRoots.size(); ++f) {
            const auto pa = strandOf(outA, G + f), pb = strandOf(outB, G + f - 1);
            ASSERT_EQ(pa.size(), pb.size());
            ASSERT_EQ(std::memcmp(pa.data(), pb.data(), pa.size() * sizeof(Vec3f)), 0) << "follower " << f;
        }
    }
}

TEST(Followers, SegmentLengthsArePreserved) {
    FollowerGroom groom = sphereGroom(60, 900);
    // Three vertex counts (resampled guide tables) and per-follower lengths.
    groom.followerVertices.clear();
    groom.followerLengths.clear();
    for (size_t f = 0; f < groom.followerRoots.size(); ++f) {
        groom.followerVertices.push_back(f % 3 == 0 ? 24 : f % 3 == 1 ? 13 : 40);
        groom.followerLengths.push_back(0.15f + 0.1f * float(f % 7) / 6.f);
    }
    const SyntheticGuides motion(groom, {});
    StrandFrame guides;
    std::vector<SurfaceFrame> guideRoots, followerRoots;
    motion.sample(0.7, guides, guideRoots);
    rotateRoots(groom.followerRoots, motion.headRotation(0.7), followerRoots);
    for (FollowerMode mode : {FollowerMode::Varied, FollowerMode::Interpolate, FollowerMode::Cluster}) {
        FollowerSettings settings;
        settings.mode = mode;
        Followers followers(groom, settings);
        StrandFrame out;
        followers.update({guides, guideRoots, followerRoots}, out);
        double worst = 0;
        for (size_t f = 0; f < groom.followerRoots.size(); ++f) {
            const auto p = strandOf(out, guides.strandCount() + f);
            ASSERT_EQ(p.size(), groom.followerVertices[f]);
            const float L = groom.followerLengths[f] / float(p.size() - 1);
            for (size_t k = 1; k < p.size(); ++k) worst = std::max(worst, std::abs(double((p[k] - p[k - 1]).norm()) / L - 1.0));
        }
        EXPECT_LT(worst, 1e-5) << "mode " << int(mode);
    }
    // Own rest shapes with uneven segments.
    groom.followerShapes = RestShapes();
    std::vector<std::vector<float>> lengths;
    for (size_t f = 0; f < groom.followerRoots.size(); ++f) {
        std::vector<Vec3f> p{Vec3f::Zero()};
        lengths.emplace_back();
        for (int y = 0; y < 17; ++y) {
            lengths.back().push_back(0.005f + 0.001f * float((y * 7 + f) % 5));
            p.push_back(p.back() + lengths.back().back() * Vec3f(0.1f * std::sin(0.5f * y + f), 1.f, 0.f).normalized());
        }
        groom.followerShapes.add(p.data(), p.size());
    }
    Followers followers(groom, {});
    StrandFrame out;
    followers.update({guides, guideRoots, followerRoots}, out);
    double worst = 0;
    for (size_t f = 0; f < groom.followerRoots.size(); ++f) {
        const auto p = strandOf(out, guides.strandCount() + f);
        for (size_t k = 1; k < p.size(); ++k)
            worst = std::max(worst, std::abs(double((p[k] - p[k - 1]).norm()) / lengths[f][k - 1] - 1.0));
    }
    EXPECT_LT(worst, 1e-5);
}

TEST(Followers, VelocitiesAreFiniteDifferencesOrGuideBlends) {
    const FollowerGroom groom = sphereGroom(94, 751);
    // First update: no previous positions, a blend of guide velocities; with
    // every guide moving at u, followers move at u.
    FollowerSettings cluster;
    cluster.mode = FollowerMode::Cluster;
    Followers still(groom, cluster);
    const Vec3f u(0.1f, -0.2f, 0.3f);
    StrandFrame guides = straightGuides(groom, &u);
    StrandFrame out;
    const FollowerStats first = still.update({guides, groom.guideRoots, groom.followerRoots}, out);
    EXPECT_FALSE(first.differenceVelocities);
    EXPECT_TRUE(first.layoutWritten);
    for (size_t i = guides.vertexCount(); i < out.vertexCount(); ++i) EXPECT_EQ(out.velocities[i], u);

    // Later updates into the same frame: (x - x_prev) / dt.
    const SyntheticGuides motion(groom, {});
    Followers followers(groom, {});
    std::vector<SurfaceFrame> guideRoots, followerRoots;
    motion.sample(0.5, guides, guideRoots);
    rotateRoots(groom.followerRoots, motion.headRotation(0.5), followerRoots);
    followers.update({guides, guideRoots, followerRoots}, out);
    const std::vector<Vec3f> before = out.positions;
    motion.sample(0.52, guides, guideRoots);
    rotateRoots(groom.followerRoots, motion.headRotation(0.52), followerRoots);
    const FollowerStats second = followers.update({guides, guideRoots, followerRoots, nullptr, 0.02}, out);
    EXPECT_TRUE(second.differenceVelocities);
    EXPECT_FALSE(second.layoutWritten);
    for (size_t i = guides.vertexCount(); i < out.vertexCount(); ++i)
        ASSERT_LT((out.velocities[i] - (out.positions[i] - before[i]) / 0.02f).norm(), 1e-4f);
    // A different frame object holds no previous positions: back to the blend.
    StrandFrame other;
    EXPECT_FALSE(followers.update({guides, guideRoots, followerRoots, nullptr, 0.02}, other).differenceVelocities);
}

TEST(Followers, InPlaceAppendEqualsSeparateOutput) {
    const FollowerGroom groom = sphereGroom(94, 751);
    const SyntheticGuides motion(groom, {});
    StrandFrame guides, out;
    std::vector<SurfaceFrame> guideRoots, followerRoots;
    motion.sample(0.2, guides, guideRoots);
    rotateRoots(groom.followerRoots, motion.headRotation(0.2), followerRoots);
    Followers followers(groom, {});
    followers.update({guides, guideRoots, followerRoots}, out);
    StrandFrame inPlace = guides;
    followers.update({inPlace, guideRoots, followerRoots}, inPlace);
    EXPECT_EQ(inPlace.positions, out.positions);
    EXPECT_EQ(inPlace.radii, out.radii);
    EXPECT_EQ(inPlace.ids, out.ids);
    EXPECT_EQ(inPlace.offsets, out.offsets);
    EXPECT_EQ(inPlace.guideCount, 94u);
    // Radii taper from root to tip.
    EXPECT_FLOAT_EQ(out.radii[out.first(100)], 0.00004f);
    EXPECT_FLOAT_EQ(out.radii[out.offsets[101] - 1], 0.00001f);
}

TEST(Followers, CollisionLeavesNoVertexInsideTheHead) {
    // Guides lie over the head and differ a lot between neighbours at the
    // crown, so interpolated followers cut into the head (Gomes 2024's Fig. 5.4).
    const hp::test::SphereScene scene(94, 2000, 0.7);
    const FollowerGroom& groom = scene.groom;
    const StrandFrame& guides = scene.guides;
    const std::vector<SurfaceFrame>& guideRoots = scene.guideRoots;
    const std::vector<SurfaceFrame>& followerRoots = scene.followerRoots;
    const SphereCollider head(Vec3f::Zero(), 0.1f);
    auto inside = [&](const StrandFrame& out, double* stretch) {
        size_t count = 0;
        *stretch = 0;
        for (size_t sIdx = out.guideCount; sIdx < out.strandCount(); ++sIdx)
            for (uint32_t v = out.first(sIdx) + 1; v < out.offsets[sIdx + 1]; ++v) {
                count += head.signedDistance(out.positions[v]) < out.radii[v];
                *stretch = std::max(*stretch, std::abs(double((out.positions[v] - out.positions[v - 1]).norm()) / (0.25 / 23) - 1));
            }
        return count;
    };
    FollowerSettings off;
    off.collide = false;
    Followers loose(groom, off), colliding(groom, {});
    StrandFrame a, b;
    double stretchA, stretchB;
    loose.update({guides, guideRoots, followerRoots, &head}, a);
    const size_t before = inside(a, &stretchA);
    EXPECT_GT(before, 100u) << "interpolated followers dip into the head without collision";
    const FollowerStats stats = colliding.update({guides, guideRoots, followerRoots, &head}, b);
    EXPECT_EQ(inside(b, &stretchB), 0u);
    EXPECT_GT(stats.projected, 0u);
    EXPECT_GE(stats.collisionQueries, stats.projected);
    EXPECT_LT(stats.collisionQueries, b.vertexCount()) << "the guide-distance bound skips far vertices";
    EXPECT_LT(stretchB, 1e-4) << "follow-the-leader keeps segment lengths";
    RecordProperty("max_stretch_after_collision", std::to_string(stretchB));
    std::printf("inside before %zu, projected %zu, queries %zu of %zu vertices, max stretch %.2e\n", before,
                stats.projected, stats.collisionQueries, b.vertexCount() - guides.vertexCount(), stretchB);
}

TEST(Followers, BadInputIsReportedWithTheStrand) {
    FollowerGroom groom = sphereGroom(10, 50);
    auto message = [](auto&& f) {
        try { f(); } catch (const Error& e) { return std::string(e.what()); }
        return std::string("no error");
    };
    FollowerGroom bad = groom;
    bad.guideShapes = RestShapes::straight(9, 24, 0.25f);
    EXPECT_NE(message([&] { Followers x(bad, {}); }).find("10 guide roots but 9 guide rest shapes"), std::string::npos);
    bad = groom;
    bad.followerLengths = {0.25f, 0.2f};
    EXPECT_NE(message([&] { Followers x(bad, {}); }).find("followerLengths"), std::string::npos);
    bad = groom;
    bad.followerRoots[7].normal = Vec3f(NAN, 0, 0);
    EXPECT_NE(message([&] { Followers x(bad, {}); }).find("follower 7"), std::string::npos);

    Followers followers(groom, {});
    const SyntheticGuides motion(groom, {});
    StrandFrame guides, out;
    std::vector<SurfaceFrame> guideRoots;
    motion.sample(0, guides, guideRoots);
    std::vector<SurfaceFrame> fewer(groom.followerRoots.begin(), groom.followerRoots.end() - 1);
    EXPECT_NE(message([&] { followers.update({guides, guideRoots, fewer}, out); }).find("49 follower root frames for 50"),
              std::string::npos);
    guides.positions[guides.first(3) + 5].x() = NAN;
    EXPECT_NE(message([&] { followers.update({guides, guideRoots, groom.followerRoots}, out); }).find("guide 3 vertex 5"),
              std::string::npos);
    StrandFrame shortGuides;
    const Vec3f two[2] = {Vec3f::Zero(), Vec3f::UnitY()};
    const float r[2] = {1e-4f, 1e-4f};
    for (int g = 0; g < 10; ++g) shortGuides.addStrand(g, two, r, 2);
    EXPECT_NE(message([&] { followers.update({shortGuides, guideRoots, groom.followerRoots}, out); })
                  .find("guide 0 has 2 vertices in this step but 24 in the groom"),
              std::string::npos);
}
