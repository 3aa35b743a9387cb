// Follower kernels (sim/followers/follower_kernels.h): Algorithm 1's curves, the
// per-segment random values, and the slerp by arc with polynomial sin/cos
// against double-precision references.
#include "sim/followers/follower_kernels.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

using namespace hp;

// ---------------------------------------------------------------------------
// Kernels

TEST(FollowerKernels, FixedOffsetIsZeroAtRootAndTipAndOneInTheMiddle) {
    // Gomes 2024: 23 segments, qs = 23 / 2 = 11 in integer arithmetic = (23 - 1) / 2.
    EXPECT_EQ(follower::fixedOffsetCurve(0, 23), 0.f);
    EXPECT_EQ(follower::fixedOffsetCurve(22, 23), 0.f);  // y = 2 qs, the tip segment
    EXPECT_EQ(follower::fixedOffsetCurve(11, 23), 1.f);
    for (int y = 0; y < 23; ++y) {
        EXPECT_FLOAT_EQ(follower::fixedOffsetCurve(float(y), 23), follower::fixedOffsetCurve(float(22 - y), 23));
        if (y < 11) {
            EXPECT_LT(follower::fixedOffsetCurve(float(y), 23), follower::fixedOffsetCurve(float(y + 1), 23));
        }
    }
    // Even counts stay symmetric: 0 at both ends, the two middle segments equal and maximal.
    EXPECT_EQ(follower::fixedOffsetCurve(0, 24), 0.f);
    EXPECT_EQ(follower::fixedOffsetCurve(23, 24), 0.f);
    EXPECT_FLOAT_EQ(follower::fixedOffsetCurve(11, 24), follower::fixedOffsetCurve(12, 24));
    EXPECT_GT(follower::fixedOffsetCurve(11, 24), follower::fixedOffsetCurve(10, 24));
    EXPECT_EQ(follower::fixedOffsetCurve(0, 1), 0.f);
}

TEST(FollowerKernels, SinCosAndAtanPolynomialsAreFloatAccurate) {
    double worstS = 0, worstC = 0, worstPyth = 0, worstA = 0;
    for (int i = 0; i <= 200000; ++i) {
        const double x = -M_PI / 2 + M_PI * i / 200000.0;
        float s, c;
        follower::sinCos(float(x), s, c);
        worstS = std::max(worstS, std::abs(s - std::sin(double(float(x)))));
        worstC = std::max(worstC, std::abs(c - std::cos(double(float(x)))));
        worstPyth = std::max(worstPyth, std::abs(double(s) * s + double(c) * c - 1.0));
        const float y = float(std::abs(std::sin(x))), z = float(std::cos(x));
        worstA = std::max(worstA, std::abs(follower::atan2Positive(y, z) - std::atan2(double(y), double(z))));
    }
    EXPECT_LT(worstS, 1.2e-7);
    EXPECT_LT(worstC, 1.2e-7);
    EXPECT_LT(worstPyth, 3e-7) << "(sin, cos) stays on the unit circle: segment lengths need no renormalisation";
    EXPECT_LT(worstA, 2.5e-7);
    float s, c;
    follower::sinCos(0.f, s, c);
    EXPECT_EQ(s, 0.f) << "t = 0 must give guide 1's rotation exactly";
    EXPECT_EQ(c, 1.f);
    EXPECT_EQ(follower::atan2Positive(0.f, 0.f), 0.f);
    EXPECT_FLOAT_EQ(follower::atan2Positive(1.f, 0.f), float(M_PI / 2));
    // Range reduction: sin² and cos² repeat every π (q and -q are one rotation).
    for (float x : {2.f, -3.5f, 40.f, -1000.f}) {
        follower::sinCos(follower::reduceHalfTurns(x), s, c);
        EXPECT_NEAR(s * s, std::pow(std::sin(double(x)), 2), 2e-6) << x;
        EXPECT_NEAR(c * s, std::sin(double(x)) * std::cos(double(x)), 2e-6) << x;
    }
}

TEST(FollowerKernels, ArcSlerpMatchesExactSlerp) {
    // slerp(a, b, t) = cos(tθ) a + sin(tθ) e and the rotated direction by (2),
    // against double-precision slerp and rotation, for near and far rotations
    // (down to opposite ones) and t in [-0.5, 1.5] (extrapolation).
    std::mt19937 rng(7);
    std::normal_distribution<double> n;
    std::uniform_real_distribution<double> ut(-0.5, 1.5);
    double worstQ = 0, worstV = 0, worstNear = 0;
    for (int i = 0; i < 20000; ++i) {
        Eigen::Quaterniond a(n(rng), n(rng), n(rng), n(rng)), b(n(rng), n(rng), n(rng), n(rng));
        a.normalize();
        b.normalize();
        if (i % 3 == 1) b = Eigen::Quaterniond(a.coeffs() + 0.3 * b.coeffs()).normalized();   // nearby pairs
        if (i % 3 == 2) b = Eigen::Quaterniond(a.coeffs() + 1e-4 * b.coeffs()).normalized();  // almost equal
        const double t = ut(rng);
        const Eigen::Vector3d f = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
        const follower::Quat af{float(a.w()), float(a.x()), float(a.y()), float(a.z())};
        const follower::Quat bf{float(b.w()), float(b.x()), float(b.y()), float(b.z())};
        // Exact, from the float inputs made unit in double, along the shorter
        // arc; θ = atan2(|b - (a·b) a|, a·b) (acos loses θ near 0).
        const Eigen::Vector4d ad = Eigen::Vector4d(af.w, af.x, af.y, af.z).normalized();
        Eigen::Vector4d bd = Eigen::Vector4d(bf.w, bf.x, bf.y, bf.z).normalized();
        double d = ad.dot(bd);
        if (d < 0) { d = -d; bd = -bd; }
        const double th = std::atan2((bd - d * ad).norm(), d);
        const Eigen::Vector4d exact = th < 1e-12 ? ad : Eigen::Vector4d((std::sin((1 - t) * th) * ad + std::sin(t * th) * bd) / std::sin(th));
        const Eigen::Vector3d exactV = Eigen::Quaterniond(exact[0], exact[1], exact[2], exact[3]).normalized() * f;

        float theta, s, c;
        follower::Quat e;
        follower::slerpArc(af, bf, theta, e);
        follower::sinCos(follower::reduceHalfTurns(float(t) * theta), s, c);
        const Eigen::Vector4d got = double(c) * ad + double(s) * Eigen::Vector4d(e.w, e.x, e.y, e.z);
        const double errQ = std::min((got - exact).norm(), (got + exact).norm());
        Eigen::Vector3f A, BminusA, D;
        follower::slerpedDirection(af, e, f.cast<float>(), A, BminusA, D);
        const Eigen::Vector3f v = A + (s * s) * BminusA + (c * s) * D;
        const double errV = (v.cast<double>() - exactV).norm();
        worstQ = std::max(worstQ, errQ);
        worstV = std::max(worstV, errV);
        if (d >= 0.7) worstNear = std::max(worstNear, errV);
    }
    EXPECT_LT(worstQ, 1e-6);
    EXPECT_LT(worstV, 3e-6);
    EXPECT_LT(worstNear, 2e-6);
    RecordProperty("slerp_worst_quaternion_error", std::to_string(worstQ));
    std::printf("arc slerp: worst |q - exact| %.2e, worst |q f q* - exact| %.2e (%.2e for cos θ >= 0.7)\n", worstQ,
                worstV, worstNear);
}

TEST(FollowerKernels, SegmentRandomIsFixedUniformAndDecorrelated) {
    const uint32_t a = follower::followerHash(1, 10), b = follower::followerHash(2, 10), c = follower::followerHash(1, 11);
    double sum = 0, sum2 = 0;
    int differ = 0;
    float lo = 1, hi = -1;
    for (uint32_t y = 0; y < 20000; ++y) {
        const float r = follower::segmentRandom(a, y);
        EXPECT_EQ(r, follower::segmentRandom(follower::followerHash(1, 10), y));
        lo = std::min(lo, r);
        hi = std::max(hi, r);
        sum += r;
        sum2 += r * r;
        differ += r != follower::segmentRandom(b, y) && r != follower::segmentRandom(c, y);
    }
    EXPECT_GE(lo, -1.f);
    EXPECT_LT(hi, 1.f);
    EXPECT_LT(lo, -0.99f);
    EXPECT_GT(hi, 0.99f);
    EXPECT_NEAR(sum / 20000, 0.0, 0.02);
    EXPECT_NEAR(sum2 / 20000, 1.0 / 3.0, 0.02);  // uniform on [-1, 1]
    EXPECT_GT(differ, 19990);
}

