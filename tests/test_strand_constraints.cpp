// The strand kernels without a physics world: lengths (sim/solver/length_kernels.h),
// head contact (sim/solver/head_contact.h), damping (sim/solver/damping.h),
// the guides' joints (sim/guides/joint_kernels.h) and segment contact
// (sim/guides/segment_contact.h).
#include "sim/guides/joint_kernels.h"
#include "sim/guides/segment_contact.h"
#include "sim/solver/damping.h"
#include "sim/solver/head_contact.h"
#include "sim/solver/length_kernels.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

using namespace hp;
using namespace hp::strand;

namespace {

constexpr float kDeg = float(M_PI / 180.0);

std::vector<Vec3f> randomChain(std::mt19937& rng, int vertices, float length, float jitter) {
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    std::vector<Vec3f> x(vertices);
    x[0] = Vec3f::Zero();
    for (int i = 1; i < vertices; ++i) {
        const Vec3f step = Vec3f(0, length, 0) + jitter * Vec3f(u(rng), u(rng), u(rng));
        x[i] = x[i - 1] + step;
    }
    return x;
}

}  // namespace

TEST(StrandKernels, FollowTheLeaderRestoresEveryLength) {
    std::mt19937 rng(3);
    std::vector<Vec3f> x = randomChain(rng, 24, 0.01f, 0.006f);
    const std::vector<Vec3f> before = x;
    std::vector<float> rest(23, 0.0108f);
    std::vector<Vec3f> corr(24);
    followTheLeader(x.data(), rest.data(), x.size(), corr.data());
    EXPECT_EQ(x[0], before[0]) << "the root never moves";
    for (int i = 0; i < 23; ++i) {
        EXPECT_NEAR((x[i + 1] - x[i]).norm(), rest[i], 1e-6f);
        // Each vertex moves only along its segment's direction from the placed parent.
        EXPECT_LT((x[i + 1] - x[i]).normalized().cross((before[i + 1] - x[i]).normalized()).norm(), 1e-5f);
        EXPECT_LT((corr[i + 1] - (x[i + 1] - before[i + 1])).norm(), 1e-7f);
    }
}

TEST(StrandKernels, RelieveCompressionLeavesStretchedSegments) {
    std::vector<Vec3f> x = {{0, 0, 0}, {0, 0.5f, 0}, {0, 2.5f, 0}, {0, 2.6f, 0}};
    const float rest[3] = {1, 1, 1};
    relieveCompression(x.data(), rest, x.size());
    EXPECT_NEAR(x[1].y(), 1.f, 1e-6f) << "compressed: pushed out to its length";
    // Segment 1 was 2 long; after the push it is 1.5, still stretched: kept.
    EXPECT_NEAR(x[2].y(), 2.5f, 1e-6f);
    EXPECT_NEAR(x[3].y(), 3.5f, 1e-6f) << "compressed again: pushed out";
}

TEST(StrandKernels, ImplicitSpringSagIsStepSizeIndependent) {
    // A joint of inertia I under a constant torque τ and a spring κ, advanced
    // as the solver does: predict freely, then correct by the spring fraction.
    // Its rest angle must be τ/κ whatever the step.
    const float I = 6.4e-9f, kappa = 5e-5f, tau = 2e-7f;
    for (float h : {0.02f, 0.005f}) {
        const float f = springFraction(kappa, I, h);
        ASSERT_GT(f, 0.f);
        ASSERT_LT(f, 1.f);
        float theta = 0.f, omega = 0.f;
        for (int k = 0; k < int(4.0f / h); ++k) {
            const float pred = theta + h * omega + h * h * tau / I;
            const float next = pred + f * (0.f - pred);
            omega = (next - theta) / h * dampingFactor(5.f, h);
            theta = next;
        }
        EXPECT_NEAR(theta, tau / kappa, 0.02f * tau / kappa) << "h = " << h;
    }
}

TEST(StrandKernels, DampingComposesOverSubsteps) {
    const float one = dampingFactor(1.5f, 0.02f);
    float four = 1.f;
    for (int i = 0; i < 4; ++i) four *= dampingFactor(1.5f, 0.005f);
    EXPECT_NEAR(one, four, 1e-6f);
    EXPECT_NEAR(one, std::exp(-0.03f), 1e-6f);
}

TEST(StrandKernels, TransportIsTheMinimalRotation) {
    const Vec3f a = Vec3f(1, 2, 3).normalized(), b = Vec3f(-2, 1, 0.5f).normalized();
    const Quatf q = transport(a, b);
    EXPECT_LT((q * a - b).norm(), 1e-6f);
    EXPECT_LT((q * a.cross(b) - a.cross(b)).norm(), 1e-6f) << "the rotation axis is a × b";
    const Vec3f c = -a;  // antiparallel: still a proper rotation onto c
    EXPECT_LT((transport(a, c) * a - c).norm(), 1e-5f);
}

TEST(StrandKernels, RotateToAngleStaysInThePlane) {
    const Vec3f axis = Vec3f::UnitY();
    const Vec3f outside = Vec3f(std::sin(50 * kDeg), std::cos(50 * kDeg), 0);
    const Vec3f d = rotateToAngle(outside, axis, 35 * kDeg);
    EXPECT_NEAR(angleBetween(d, axis), 35 * kDeg, 1e-5f);
    EXPECT_NEAR(d.z(), 0.f, 1e-6f);
    EXPECT_GT(d.x(), 0.f);
    EXPECT_NEAR(d.norm(), 1.f, 1e-6f);
}

TEST(StrandKernels, HeadProjectionClearsTheRadiusWithExactLength) {
    const SphereCollider sphere(Vec3f::Zero(), 0.1f);
    HeadQuery head;
    head.collider = &sphere;
    const float r = 0.001f, l = 0.0108f;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    for (int k = 0; k < 200; ++k) {
        const Vec3f n = Vec3f(u(rng), u(rng), u(rng)).normalized();
        const Vec3f parent = n * (0.1f + r + 0.002f * (u(rng) + 1.f));
        Vec3f child = parent + Vec3f(u(rng), u(rng), u(rng)).normalized() * 0.015f - 0.02f * n;  // dives in
        const Contact c = placeSegment(parent, child, l, &head, r);
        EXPECT_GE(sphere.signedDistance(child), r - 1e-5f);
        EXPECT_NEAR((child - parent).norm(), l, 1e-5f) << "a parent outside the band always keeps the length";
        if (c.active) {
            EXPECT_GT(c.normal.dot(child.normalized()), 0.99f);
            EXPECT_GE(c.push, 0.f);
        }
    }
}

TEST(StrandKernels, ContactFrictionIsCoulomb) {
    Contact c;
    c.active = true;
    c.normal = Vec3f::UnitY();
    const float h = 0.02f, mu = 0.2f;
    c.push = 0.002f;  // the push added 0.1 m/s outward; it was approaching at 0.1 m/s - 0.1 m/s = 0
    // Pushed out by 2 mm: the push's 0.1 m/s is removed, nothing bounces.
    Vec3f v = contactFriction(Vec3f(0, 0.1f, 0), Vec3f::Zero(), c, mu, h);
    EXPECT_NEAR(v.y(), 0.f, 1e-6f);
    // Approaching at 1 m/s (before the push): μ·1 m/s of sliding is removed.
    v = contactFriction(Vec3f(2.f, -1.f + 0.1f, 0), Vec3f::Zero(), c, mu, h);
    EXPECT_NEAR(v.y(), 0.f, 1e-6f);
    EXPECT_NEAR(v.x(), 2.f - mu * 1.f, 1e-5f);
    // Slow sliding stops (static friction), relative to a moving surface.
    const Vec3f surface(0.5f, 0, 0);
    v = contactFriction(Vec3f(0.55f, -1.f + 0.1f, 0), surface, c, mu, h);
    EXPECT_NEAR(v.x(), 0.5f, 1e-6f);
}

TEST(StrandKernels, PreloadSolveMakesRestAnEquilibrium) {
    // A chain displaced the way one Bullet step displaces a strand at rest:
    // solving for the pre-load and relaxing the same input lands on the rest.
    const int n = 24;
    std::vector<float> len(n - 1, 0.0108f), spring(n - 1, 0.7f), limitSpring(n - 1, 0.9f);
    std::vector<Vec3f> restDir(n - 1), springDir(n - 1);
    for (int j = 0; j < n - 1; ++j) restDir[j] = Vec3f(std::sin(0.02f * j), std::cos(0.02f * j), 0).normalized();
    std::vector<float> restBend(n - 1), most(n - 1), least(n - 1);
    bendBounds(restDir.data(), n - 1, 35 * kDeg, restBend.data(), most.data(), least.data());
    JointParams p{len.data(), restDir.data(), restBend.data(), most.data(), least.data(), springDir.data(),
                  spring.data(), limitSpring.data(), 30 * kDeg, 5 * kDeg};
    const Mat3f R = Eigen::AngleAxisf(0.3f, Vec3f(1, 0, 1).normalized()).toRotationMatrix();
    std::vector<Vec3f> rest(n);
    rest[0] = Vec3f(0.1f, 0.2f, 0.3f);
    for (int j = 0; j < n - 1; ++j) rest[j + 1] = rest[j] + len[j] * (R * restDir[j]);
    std::vector<Vec3f> sagged = rest;
    for (int i = 1; i < n; ++i) sagged[i] += Vec3f(0, -0.0039f, 0) * float(i) / float(n - 1);
    std::vector<Vec3f> x = sagged;
    relaxJoints(JointPass::SolvePreload, x.data(), n, R, p, nullptr, 0.f, nullptr);
    for (int i = 0; i < n; ++i) EXPECT_LT((x[i] - rest[i]).norm(), 2e-6f) << "put back on the rest shape";
    x = sagged;
    relaxJoints(JointPass::Drive, x.data(), n, R, p, nullptr, 0.f, nullptr);
    for (int i = 0; i < n; ++i) EXPECT_LT((x[i] - rest[i]).norm(), 2e-6f) << "vertex " << i;
}

TEST(StrandKernels, DriveJointsMatchesOneStrandAtATimeBitForBit) {
    // Seven strands: a lockstep block of four and three on their own, each
    // with its own rest shape, springs, root frame and displaced input.
    const int n = 24, count = 7;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    std::vector<std::vector<float>> len(count), spring(count), limitSpring(count), restBend(count), most(count),
        least(count);
    std::vector<std::vector<Vec3f>> restDir(count), springDir(count), x(count);
    std::vector<JointParams> p(count);
    std::vector<Mat3f> R(count);
    for (int k = 0; k < count; ++k) {
        len[k].assign(n - 1, 0.01f + 0.001f * float(k));
        spring[k].assign(n - 1, 0.1f * float(k + 1));
        limitSpring[k].assign(n - 1, 0.5f);
        for (int j = 0; j < n - 1; ++j) {
            restDir[k].push_back(Vec3f(0.2f * u(rng), 1.f, 0.2f * u(rng)).normalized());
            springDir[k].push_back(Vec3f(0.3f * u(rng), 1.f, 0.3f * u(rng)).normalized());
        }
        restBend[k].resize(n - 1);
        most[k].resize(n - 1);
        least[k].resize(n - 1);
        bendBounds(restDir[k].data(), n - 1, 35 * kDeg, restBend[k].data(), most[k].data(), least[k].data());
        p[k] = JointParams{len[k].data(),    restDir[k].data(), restBend[k].data(), most[k].data(),
                           least[k].data(),  springDir[k].data(), spring[k].data(), limitSpring[k].data(),
                           30 * kDeg,        5 * kDeg};
        R[k] = Eigen::AngleAxisf(0.4f * float(k), Vec3f(u(rng), u(rng), u(rng)).normalized()).toRotationMatrix();
        x[k] = randomChain(rng, n, len[k][0], 0.004f);
    }
    std::vector<std::vector<Vec3f>> one = x;
    for (int k = 0; k < count; ++k) relaxJoints(JointPass::Drive, one[k].data(), n, R[k], p[k], nullptr, 0.f, nullptr);
    std::vector<Vec3f*> xs;
    for (auto& v : x) xs.push_back(v.data());
    driveJoints(count, xs.data(), n, R.data(), p.data());
    for (int k = 0; k < count; ++k)
        for (int i = 0; i < n; ++i) {
            EXPECT_EQ(x[k][i], one[k][i]) << "strand " << k << " vertex " << i;
            EXPECT_NEAR((x[k][i] - x[k][std::max(i - 1, 0)]).norm(), i ? len[k][i - 1] : 0.f, 1e-5f);
        }
}

TEST(StrandKernels, FinishPassKeepsLengthsAndTheProjectionLimit) {
    const int n = 24;
    std::vector<float> len(n - 1, 0.0108f), spring(n - 1, 0.3f), limitSpring(n - 1, 0.5f);
    std::vector<Vec3f> restDir(n - 1, Vec3f::UnitY()), springDir(n - 1, Vec3f::UnitY());
    std::vector<float> restBend(n - 1), most(n - 1), least(n - 1);
    bendBounds(restDir.data(), n - 1, 35 * kDeg, restBend.data(), most.data(), least.data());
    JointParams p{len.data(), restDir.data(), restBend.data(), most.data(), least.data(), springDir.data(),
                  spring.data(), limitSpring.data(), 30 * kDeg, 5 * kDeg};
    std::mt19937 rng(11);
    for (int trial = 0; trial < 20; ++trial) {
        std::vector<Vec3f> x = randomChain(rng, n, 0.0108f, 0.03f);  // wildly bent and stretched
        relaxJoints(JointPass::Finish, x.data(), n, Mat3f::Identity(), p, nullptr, 0.f, nullptr);
        Vec3f parentDir = Vec3f::UnitY();
        for (int j = 0; j < n - 1; ++j) {
            const Vec3f d = x[j + 1] - x[j];
            EXPECT_NEAR(d.norm(), len[j], 1e-5f);
            // Straight rest: the relative bend is the angle between consecutive segments.
            EXPECT_LE(angleBetween(parentDir, d.normalized()), 35 * kDeg + 1e-3f) << "joint " << j;
            parentDir = d.normalized();
        }
    }
}

TEST(StrandKernels, BendLimitSpansMatchTheAngles) {
    const float len[3] = {0.01f, 0.02f, 0.01f};
    const Vec3f dirs[3] = {Vec3f::UnitY(), Vec3f(std::sin(0.2f), std::cos(0.2f), 0), Vec3f(std::sin(0.2f), std::cos(0.2f), 0)};
    float minSpan[3], maxSpan[3];
    bendLimitSpan(len, dirs, 3, 30 * kDeg, minSpan, maxSpan);
    // Joint 0 (virtual follicle on the root's own direction): rest bend 0.
    EXPECT_TRUE(std::isinf(maxSpan[0])) << "a straight rest may straighten fully: no upper bound";
    EXPECT_NEAR(minSpan[0], (Vec3f(0, 0.01f, 0) + 0.01f * Vec3f(std::sin(30 * kDeg), std::cos(30 * kDeg), 0)).norm(),
                1e-7f);
    // Joint 1: rest bend 0.2 rad between lengths 0.01 and 0.02.
    auto span = [](float a) { return (Vec3f(0, 0.01f, 0) + 0.02f * Vec3f(std::sin(a), std::cos(a), 0)).norm(); };
    EXPECT_NEAR(minSpan[1], span(0.2f + 30 * kDeg), 1e-7f);
    EXPECT_TRUE(std::isinf(maxSpan[1])) << "a rest bend below the limit may straighten fully";
    // A rest bend beyond the limit keeps a bend of at least rest - limit.
    const Vec3f bent[2] = {Vec3f::UnitY(), Vec3f(std::sin(50 * kDeg), std::cos(50 * kDeg), 0)};
    bendLimitSpan(len, bent, 2, 30 * kDeg, minSpan, maxSpan);
    EXPECT_NEAR(maxSpan[1], span(20 * kDeg), 1e-7f);
    // The constraint moves both ends, by their inverse masses.
    Vec3f a(0, 0, 0), b(0.005f, 0, 0);
    limitSpan(a, b, 1.f, 3.f, 0.009f, 0.02f, 1.f);
    EXPECT_NEAR((b - a).norm(), 0.009f, 1e-7f);
    EXPECT_NEAR(-a.x() * 3.f, b.x() - 0.005f, 1e-7f);
    const Vec3f keep = b;
    limitSpan(a, b, 1.f, 3.f, 0.001f, 0.02f, 1.f);
    EXPECT_EQ(b, keep) << "inside the span nothing moves";
}

TEST(StrandKernels, SeparateSegmentsPushesApartByTheDepth) {
    Vec3f a0(-1, 0, 0), a1(1, 0, 0), b0(0, -1, 0.001f), b1(0, 1, 0.001f);
    const float w[4] = {1, 1, 1, 1};
    const Vec3f n(0, 0, -1);  // from B to A
    separateSegments(a0, a1, b0, b1, 0.5f, 0.5f, n, 0.003f, w);
    const float gap = (0.5f * (a0 + a1) - 0.5f * (b0 + b1)).dot(n);
    EXPECT_NEAR(gap, 0.001f + 0.003f, 1e-6f) << "1 mm apart along n before, 3 mm more after";
    // Equal weights: equal and opposite pushes (momentum is kept).
    EXPECT_NEAR((a0 + a1 + b0 + b1).z(), 2 * 0.001f, 1e-6f);
    const float pinned[4] = {0, 1, 1, 1};  // a0 is a root
    Vec3f c0(-1, 0, 0), c1(1, 0, 0);
    separateSegments(c0, c1, b0, b1, 0.5f, 0.5f, n, 0.003f, pinned);
    EXPECT_EQ(c0, Vec3f(-1, 0, 0));
}
