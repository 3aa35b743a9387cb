// Pure kernels of the curly/wet strand model (sim/curly/curly_kernels.h,
// sim/curly/wet_forces.h, sim/curly/curly_dynamics.h): each checked against its equation,
// a closed form or a brute-force reference, without a physics world.
#include "sim/curly/curly_dynamics.h"
#include "sim/curly/curly_kernels.h"
#include "sim/curly/wet_forces.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <functional>
#include <random>
#include <vector>

namespace hp::curly {
namespace {

constexpr float kPi = float(M_PI);

std::vector<Vec3f> helix(float r, float pitch, float segment, size_t n) {
    std::vector<Vec3f> p(n);
    helixPoints(r, pitch, segment, n, p.data());
    return p;
}

float angleDeg(const Vec3f& a, const Vec3f& b) {
    return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.f / kPi;
}

// ---- IIR smoothing (Kim 2023 eq. 2-3) ----------------------------------------------

TEST(CurlyKernels, BetaFromSmoothingLength) {
    EXPECT_FLOAT_EQ(smoothingBeta(0.01f, 0.f), 1.f);
    EXPECT_FLOAT_EQ(smoothingBeta(0.01f, 0.05f), 1.f - std::exp(-0.2f));
    EXPECT_GT(smoothingBeta(0.01f, 0.01f), smoothingBeta(0.01f, 0.1f));  // more smoothing, smaller β
}

TEST(CurlyKernels, BetaOneReproducesTheInput) {
    const std::vector<Vec3f> p = helix(0.01f, 0.04f, 0.011f, 24);
    std::vector<Vec3f> d(23), curve(24);
    smoothEdges(p.data(), p.size(), 1.f, d.data());
    for (size_t i = 0; i < d.size(); ++i) EXPECT_LT((d[i] - (p[i + 1] - p[i])).norm(), 1e-7f) << i;
    smoothedCurve(p.data(), p.size(), 1.f, curve.data());
    for (size_t i = 0; i < p.size(); ++i) EXPECT_LT((curve[i] - p[i]).norm(), 1e-6f) << i;
}

TEST(CurlyKernels, FirstSmoothedEdgeIsTheFirstEdgeAndLinesPassUnchanged) {
    // d_0 = λ_1 - λ_0 for any β (Kim 2023's initialisation), and the filter's
    // gain at zero frequency is 1: a straight, evenly sampled line is a fixed point.
    std::vector<Vec3f> line(30), d(29);
    for (size_t i = 0; i < line.size(); ++i) line[i] = Vec3f(0.1f, 0.2f, -0.3f) + float(i) * Vec3f(0.003f, 0.01f, 0.f);
    for (float beta : {0.05f, 0.3f, 0.9f}) {
        smoothEdges(line.data(), line.size(), beta, d.data());
        for (const Vec3f& di : d) EXPECT_LT((di - (line[1] - line[0])).norm(), 1e-6f) << beta;
    }
    const std::vector<Vec3f> p = helix(0.01f, 0.04f, 0.011f, 10);
    smoothEdges(p.data(), p.size(), 0.2f, d.data());
    EXPECT_LT((d[0] - (p[1] - p[0])).norm(), 1e-7f);
}

TEST(CurlyKernels, SmoothingAHelixGivesItsAxis) {
    // A long helix along +Z, 7 edges per turn, smoothed over ~10 edges: after
    // the start-up transient the smoothed tangents point along the axis and
    // the smoothed curve is a straight line parallel to it.
    const float r = 0.01f, pitch = 0.04f, seg = 0.011f;
    const size_t n = 200;
    const std::vector<Vec3f> p = helix(r, pitch, seg, n);
    const float beta = smoothingBeta(seg, 0.1f);
    std::vector<Vec3f> d(n - 1), curve(n);
    smoothEdges(p.data(), n, beta, d.data());
    smoothedCurve(p.data(), n, beta, curve.data());
    const size_t settle = 60;
    for (size_t i = settle; i < n - 1; ++i) EXPECT_LT(angleDeg(d[i], Vec3f::UnitZ()), 3.f) << i;
    // The input wanders r around the axis; the smoothed curve stays within a
    // small fraction of that of a straight line along Z.
    Vec3f mean = Vec3f::Zero();
    for (size_t i = settle; i < n; ++i) mean += curve[i];
    mean /= float(n - settle);
    float wobble = 0.f, inputWobble = 0.f;
    for (size_t i = settle; i < n; ++i) {
        wobble = std::max(wobble, Eigen::Vector2f(curve[i].x() - mean.x(), curve[i].y() - mean.y()).norm());
        inputWobble = std::max(inputWobble, Eigen::Vector2f(p[i].x() + r, p[i].y()).norm());
    }
    EXPECT_NEAR(inputWobble, r, 1e-4f);
    EXPECT_LT(wobble, 0.15f * r);
}

TEST(CurlyKernels, TransportedFramesAreRotationsThatFollowTheCurve) {
    const std::vector<Vec3f> p = helix(0.01f, 0.04f, 0.011f, 24);
    std::vector<Vec3f> d(23);
    smoothEdges(p.data(), p.size(), 0.3f, d.data());
    // Root frame with the hair direction (column 1) along +Z.
    Mat3f root;
    root.col(0) = Vec3f::UnitX();
    root.col(1) = Vec3f::UnitZ();
    root.col(2) = Vec3f::UnitX().cross(Vec3f::UnitZ());
    std::vector<Mat3f> F(23);
    transportFrames(d.data(), d.size(), root, F.data());
    for (size_t i = 0; i < F.size(); ++i) {
        EXPECT_LT((F[i].transpose() * F[i] - Mat3f::Identity()).norm(), 1e-5f) << i;
        EXPECT_NEAR(F[i].determinant(), 1.f, 1e-5f);
        EXPECT_LT(angleDeg(F[i].col(1), d[i]), 0.01f) << i;  // the frame's hair axis is the smoothed tangent
    }
    // Turning the curve and the root frame together turns the frames: the
    // targets F_i t̄_i are attached to the strand, not to the world.
    const Mat3f Q = Eigen::AngleAxisf(0.7f, Vec3f(1.f, 2.f, 3.f).normalized()).toRotationMatrix();
    std::vector<Vec3f> dq(23);
    std::vector<Mat3f> Fq(23);
    for (size_t i = 0; i < d.size(); ++i) dq[i] = Q * d[i];
    transportFrames(dq.data(), dq.size(), Q * root, Fq.data());
    for (size_t i = 0; i < F.size(); ++i) EXPECT_LT((Fq[i] - Q * F[i]).norm(), 1e-4f) << i;
}

// ---- Springs (Kim 2023 eq. 1, 4, 5) -------------------------------------------------

Mat3f numericJacobian(const std::function<Vec3f(const Vec3f&)>& f, const Vec3f& x) {
    Mat3f J;
    const float eps = 1e-4f;
    for (int c = 0; c < 3; ++c) {
        Vec3f a = x, b = x;
        a[c] -= eps;
        b[c] += eps;
        J.col(c) = (f(b) - f(a)) / (2.f * eps);
    }
    return J;
}

TEST(CurlyKernels, StretchSpringForceAndJacobian) {
    const Vec3f e(0.006f, 0.008f, 0.f);  // |e| = 0.01
    const Vec3f dv(0.1f, -0.2f, 0.3f);
    const PairForce p = stretchSpring(e, dv, 0.008f, 100.f, 0.5f);
    const Vec3f u = e.normalized();
    EXPECT_LT((p.force - (100.f * 0.002f * u + 0.5f * dv.dot(u) * u)).norm(), 1e-6f);
    const Mat3f J = numericJacobian([&](const Vec3f& x) { return stretchSpring(x, Vec3f::Zero(), 0.008f, 100.f, 0.f).force; }, e);
    EXPECT_LT((J - p.K).norm(), 1e-2f * p.K.norm());
    EXPECT_LT((p.C - 0.5f * u * u.transpose()).norm(), 1e-6f);
    // Under compression the transverse part is dropped (K stays positive semi-definite).
    const PairForce c = stretchSpring(e, dv, 0.012f, 100.f, 0.f);
    EXPECT_GE(Eigen::SelfAdjointEigenSolver<Mat3f>(c.K).eigenvalues().minCoeff(), -1e-4f);
}

TEST(CurlyKernels, BendingAndCoreSprings) {
    const Vec3f e(0.f, 0.01f, 0.f), t(0.002f, 0.0098f, 0.f), dv(0.3f, 0.1f, -0.2f);
    const PairForce b = bendingSpring(e, dv, t, 20.f, 0.1f);
    // f = kb(e - t) + cb(Δv - (Δv·ê)ê): the damping is across the edge only.
    EXPECT_LT((b.force - (20.f * (e - t) + 0.1f * Vec3f(0.3f, 0.f, -0.2f))).norm(), 1e-6f);
    EXPECT_LT((b.K - 20.f * Mat3f::Identity()).norm(), 1e-6f);
    const Vec3f bb(0.f, 0.006f, 0.f), nu(0.f, 0.5f, 1.f);
    const PairForce c = coreSpring(bb, 0.005f, nu, 30.f, 0.2f, 0.25f);
    EXPECT_LT((c.force - Vec3f(0.f, 30.f * 0.001f + 0.2f * 0.5f, 0.f)).norm(), 1e-6f);
    EXPECT_NEAR(c.K(1, 1), 30.f * 0.25f, 1e-5f);
    EXPECT_NEAR(c.K(0, 0), 0.f, 1e-7f);
}

// ---- The implicit step ----------------------------------------------------------

TEST(CurlyKernels, BlockTridiagonalSolveMatchesDenseSolve) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    const size_t n = 12;
    std::vector<Mat3f> diag(n), upper(n);
    std::vector<Vec3f> rhs(n);
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(3 * n, 3 * n);
    for (size_t i = 0; i < n; ++i) {
        Mat3f R = Mat3f::NullaryExpr([&] { return u(rng); });
        diag[i] = R * R.transpose() + 8.f * Mat3f::Identity();  // diagonally dominant: SPD
        upper[i] = Mat3f::NullaryExpr([&] { return u(rng); });
        rhs[i] = Vec3f::NullaryExpr([&] { return u(rng); });
        A.block<3, 3>(3 * i, 3 * i) = diag[i].cast<double>();
        if (i + 1 < n) {
            A.block<3, 3>(3 * i, 3 * i + 3) = upper[i].cast<double>();
            A.block<3, 3>(3 * i + 3, 3 * i) = upper[i].transpose().cast<double>();
        }
    }
    Eigen::VectorXd b(3 * n);
    for (size_t i = 0; i < n; ++i) b.segment<3>(3 * i) = rhs[i].cast<double>();
    const Eigen::VectorXd x = A.ldlt().solve(b);
    solveBlockTridiagonal(diag.data(), upper.data(), rhs.data(), n);
    for (size_t i = 0; i < n; ++i) EXPECT_LT((rhs[i].cast<double>() - x.segment<3>(3 * i)).norm(), 1e-4) << i;
}

TEST(CurlyKernels, ImplicitStepIsBackwardEulerForOneSpring) {
    // One free particle on a stretch spring to a fixed root, no gravity:
    //   (m + hc + h²k) Δv = h(f - h k v) along the edge.
    const float m = 0.002f, k = 50.f, c = 0.1f, h = 0.02f, rest = 0.01f;
    const Vec3f x[2] = {Vec3f::Zero(), Vec3f(0.f, 0.012f, 0.f)};
    const Vec3f v[2] = {Vec3f::Zero(), Vec3f(0.f, 0.3f, 0.f)};
    const float mass[2] = {0.f, m};
    const float edge[1] = {rest};
    const Vec3f target[1] = {Vec3f(0.f, 0.012f, 0.f)};  // the bending spring is at its target
    const float core[1] = {0.f};
    StrandRest r;
    r.edgeLength = edge;
    r.bendTarget = target;
    r.coreLength = core;
    r.mass = mass;
    StrandCoefficients kc;
    kc.ks = k;
    kc.cs = c;
    kc.gravity = Vec3f::Zero();
    Mat3f root;
    root.col(0) = Vec3f::UnitX();
    root.col(1) = Vec3f::UnitY();
    root.col(2) = Vec3f::UnitX().cross(Vec3f::UnitY());
    StrandScratch s;
    Vec3f dv[2];
    ASSERT_TRUE(implicitStep(x, v, 2, root, Vec3f::Zero(), r, kc, StrandLoads{}, h, s, dv));
    const float f = -k * 0.002f - c * 0.3f;  // force on the particle along +Y
    const float expected = h * (f - h * k * 0.3f) / (m + h * c + h * h * k);
    EXPECT_NEAR(dv[1].y(), expected, 1e-4f * std::abs(expected));
    EXPECT_NEAR(dv[1].x(), 0.f, 1e-6f);
}

TEST(CurlyKernels, PreloadedRestShapeIsAnEquilibrium) {
    // A curly strand standing on a root, gravity on: with the pre-load, the
    // implicit step from rest gives Δv = 0 (gravity included).
    const size_t n = 24;
    const std::vector<Vec3f> hz = helix(0.01f, 0.04f, 0.25f / 23.f, n);
    std::vector<Vec3f> p(n), v(n, Vec3f::Zero()), dv(n);
    for (size_t i = 0; i < n; ++i) p[i] = Vec3f(hz[i].x(), hz[i].z(), -hz[i].y());  // along +Y
    std::vector<float> mass(n, 0.005f * 0.25f / 23.f), edge(n - 1), core(n - 1);
    std::vector<Vec3f> target(n - 1);
    StrandCoefficients k;
    k.ks = 5000.f;
    k.kb = 20.f;
    k.kc = 20.f;
    k.cs = k.cb = k.cc = 0.02f;
    k.betaBend = k.betaCore = smoothingBeta(0.25f / 23.f, 0.05f);
    const Mat3f root = Mat3f::Identity();  // hair direction (column 1) = +Y
    restData(p.data(), n, root, k, mass.data(), true, edge.data(), target.data(), core.data());
    StrandRest r{edge.data(), target.data(), core.data(), hz.data(), mass.data()};
    StrandScratch s;
    ASSERT_TRUE(implicitStep(p.data(), v.data(), n, root, Vec3f::Zero(), r, k, StrandLoads{}, 0.02f, s, dv.data()));
    for (size_t i = 1; i < n; ++i) EXPECT_LT(dv[i].norm(), 1e-4f) << i;  // vs h·g = 0.196 m/s
    // Without the pre-load the same strand sags: Δv points down.
    restData(p.data(), n, root, k, mass.data(), false, edge.data(), target.data(), core.data());
    ASSERT_TRUE(implicitStep(p.data(), v.data(), n, root, Vec3f::Zero(), r, k, StrandLoads{}, 0.02f, s, dv.data()));
    EXPECT_LT(dv[n - 1].y(), -1e-3f);
}

// ---- Limits and contacts ---------------------------------------------------------

TEST(CurlyKernels, StrainAndVelocityLimits) {
    EXPECT_FLOAT_EQ(strainLimited(0.0105f, 0.01f, 0.02f), 0.0102f);
    EXPECT_FLOAT_EQ(strainLimited(0.0095f, 0.01f, 0.02f), 0.0098f);
    EXPECT_FLOAT_EQ(strainLimited(0.0101f, 0.01f, 0.02f), 0.0101f);
    std::vector<Vec3f> v = {Vec3f::Zero(), Vec3f(3.f, 0.f, 0.f), Vec3f(1.5f, 0.f, 0.f), Vec3f(0.f, 4.f, 0.f)};
    EXPECT_EQ(limitRelativeVelocity(v.data(), v.size(), 1.f), 2u);
    EXPECT_LT((v[1] - Vec3f(1.f, 0.f, 0.f)).norm(), 1e-6f);   // pulled back to the limit
    EXPECT_LT((v[2] - Vec3f(1.5f, 0.f, 0.f)).norm(), 1e-6f);  // within 1 of its (limited) parent: kept
    EXPECT_NEAR((v[3] - v[2]).norm(), 1.f, 1e-5f);
    // Per-step factors compose: two half steps equal one step.
    const float f = perStepFactor(0.9999f, 0.02f, 1e-4f);
    EXPECT_NEAR(perStepFactor(0.9999f, 0.01f, 1e-4f) * perStepFactor(0.9999f, 0.01f, 1e-4f), f, 1e-6f);
    EXPECT_NEAR(f, std::pow(0.9999f, 200.f), 1e-5f);
    EXPECT_EQ(perStepFactor(1.f, 0.02f, 1e-4f), 1.f);
}

TEST(CurlyKernels, PlaceParticleKeepsLengthAndClearsTheHead) {
    SphereCollider sphere(Vec3f::Zero(), 0.1f);
    ObstacleQuery head;
    head.collider = &sphere;
    const Vec3f parent(0.f, 0.102f, 0.f);
    Vec3f child(0.01f, 0.095f, 0.f);  // inside the sphere
    const Contact c = placeParticle(parent, child, 0.01f, head, 0.001f);
    EXPECT_TRUE(c.active);
    EXPECT_NEAR((child - parent).norm(), 0.01f, 1e-6f);
    EXPECT_GE(sphere.signedDistance(child), 0.001f - 1e-6f);
    EXPECT_GT(c.push, 0.f);
    Vec3f free(0.f, 0.2f, 0.f);
    EXPECT_FALSE(placeParticle(parent, free, 0.01f, head, 0.001f).active);
    EXPECT_NEAR((free - parent).norm(), 0.01f, 1e-6f);
}

TEST(CurlyKernels, ContactFrictionStopsSlowSlidingAndNeverBounces) {
    Contact c;
    c.active = true;
    c.normal = Vec3f::UnitY();
    c.push = 0.001f;
    const float h = 0.02f;
    // The particle ran 1 mm into the head (0.05 m/s) and the push took it back
    // out: friction μ·0.05 exceeds the 0.005 m/s slide, so it sticks.
    const Vec3f v = contactFriction(Vec3f(0.005f, 0.f, 0.f), Vec3f::Zero(), c, 0.2f, h);
    EXPECT_LT(v.norm(), 1e-6f);
    // A fast slide keeps going, slowed by μ times the removed normal speed.
    const Vec3f w = contactFriction(Vec3f(1.f, 0.f, 0.f), Vec3f::Zero(), c, 0.2f, h);
    EXPECT_NEAR(w.x(), 1.f - 0.2f * 0.05f, 1e-5f);
    EXPECT_NEAR(w.y(), 0.f, 1e-6f);
}

// ---- Helices -----------------------------------------------------------------------

TEST(CurlyKernels, HelixPointsAndFitRecoverRadiusAndPitch) {
    const std::vector<Vec3f> p = helix(0.01f, 0.04f, 0.011f, 24);
    EXPECT_LT(p[0].norm(), 1e-9f);
    const float chord = (p[1] - p[0]).norm();
    for (size_t i = 1; i + 1 < p.size(); ++i) EXPECT_NEAR((p[i + 1] - p[i]).norm(), chord, 1e-6f);
    // Any rigid placement: the fit is local and frame-free.
    const Eigen::Isometry3f T = Eigen::Translation3f(0.3f, -0.1f, 0.2f) * Eigen::AngleAxisf(1.1f, Vec3f(1, -2, 0.5f).normalized());
    std::vector<Vec3f> q(p.size());
    for (size_t i = 0; i < p.size(); ++i) q[i] = T * p[i];
    const HelixFit f = fitHelix(q.data(), q.size());
    EXPECT_EQ(f.samples, 21u);
    EXPECT_NEAR(f.radius, 0.01f, 1e-5f);
    EXPECT_NEAR(f.pitch, 0.04f, 1e-4f);
    // A straight strand has no helix.
    std::vector<Vec3f> line(24);
    for (size_t i = 0; i < line.size(); ++i) line[i] = Vec3f(0.f, 0.01f * float(i), 0.f);
    EXPECT_EQ(fitHelix(line.data(), line.size()).samples, 0u);
}

// ---- Wet effects (Kim 2023 §2-5) -------------------------------------------------------

TEST(WetForces, SaturationProfile) {
    EXPECT_FLOAT_EQ(saturationAt(0.5f, 1.f, 1.f, 0.3f), 0.5f);
    EXPECT_FLOAT_EQ(saturationAt(1.f, 0.2f, 1.f, 0.f), 0.2f);
    EXPECT_FLOAT_EQ(saturationAt(1.f, 0.2f, 1.f, 1.f), 1.f);
    EXPECT_FLOAT_EQ(saturationAt(1.f, 0.2f, 1.f, 0.5f), 0.6f);
    EXPECT_FLOAT_EQ(saturationAt(1.f, 2.f, 2.f, 0.5f), 1.f);  // clamped
    EXPECT_FLOAT_EQ(saturationAt(0.f, 2.f, 2.f, 0.5f), 0.f);
}

TEST(WetForces, AlignRotationIsTheSeedsRodrigues) {
    const Vec3f a = Vec3f(1.f, 2.f, -0.5f).normalized(), b = Vec3f(-0.3f, 0.4f, 1.f).normalized();
    const Mat3f M = alignRotation(a, b);
    EXPECT_LT((M * a - b).norm(), 1e-5f);
    EXPECT_LT((M.transpose() * M - Mat3f::Identity()).norm(), 1e-5f);
    EXPECT_NEAR(M.determinant(), 1.f, 1e-5f);
    // Minimal: the axis a × b is left alone.
    const Vec3f axis = a.cross(b).normalized();
    EXPECT_LT((M * axis - axis).norm(), 1e-5f);
    EXPECT_LT((alignRotation(a, a) - Mat3f::Identity()).norm(), 1e-6f);
    const Mat3f H = alignRotation(a, -a);
    EXPECT_LT((H * a + a).norm(), 1e-5f);
    EXPECT_NEAR(H.determinant(), 1.f, 1e-5f);
}

TEST(WetForces, CurlForcesFollowTheRotatedHelixAndVanishWhenDry) {
    const size_t n = 24;
    const std::vector<Vec3f> h = helix(0.01f, 0.03f, 0.011f, n);
    // The strand: the same helix, turned by Q and moved; its root frame is Q
    // (root-local z, the helix axis, is column 1 after the x,z,-y mapping, so
    // give the strand exactly the helix in root-local coordinates).
    std::vector<Vec3f> local(n), p(n), f(n - 1);
    for (size_t i = 0; i < n; ++i) local[i] = Vec3f(h[i].x(), h[i].z(), -h[i].y());
    const Mat3f Q = Eigen::AngleAxisf(0.8f, Vec3f(0.3f, 1.f, 0.2f).normalized()).toRotationMatrix();
    for (size_t i = 0; i < n; ++i) p[i] = Vec3f(0.1f, 0.2f, 0.f) + Q * local[i];
    std::vector<float> dry(n, 0.f), wet(n, 1.f);
    curlForces(p.data(), n, local.data(), Q, dry.data(), 10.f, f.data());
    for (const Vec3f& fi : f) EXPECT_EQ(fi.squaredNorm(), 0.f);
    curlForces(p.data(), n, local.data(), Q, wet.data(), 10.f, f.data());
    // The strand is the helix: M = R, and each force is w_h times its own edge.
    for (size_t i = 0; i + 1 < n; ++i) EXPECT_LT((f[i] - 10.f * (p[i + 1] - p[i])).norm(), 1e-5f) << i;
}

TEST(WetForces, SpatialGridFindsEveryNeighbourOnce) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-0.05f, 0.05f);
    std::vector<Vec3f> pts(2000);
    for (Vec3f& p : pts) p = Vec3f(u(rng), u(rng), u(rng));
    std::vector<uint32_t> groups(pts.size());
    for (size_t i = 0; i < pts.size(); ++i) groups[i] = uint32_t(i % 7);
    SpatialGrid grid;
    const float r = 0.01f;
    grid.build(pts.data(), groups.data(), pts.size(), r);
    ASSERT_EQ(grid.size(), pts.size());
    for (size_t i = 0; i < pts.size(); i += 37) {
        std::vector<int> seen(pts.size(), 0);
        grid.forEachNear(pts[i], [&](uint32_t j, const Vec3f& p, uint32_t g) {
            ++seen[j];
            EXPECT_EQ(p, pts[j]);
            EXPECT_EQ(g, groups[j]);
        });
        for (size_t j = 0; j < pts.size(); ++j) {
            EXPECT_LE(seen[j], 1);
            if ((pts[j] - pts[i]).norm() < r) {
                EXPECT_EQ(seen[j], 1) << i << " " << j;
            }
        }
    }
}

TEST(WetForces, SpatialGridStaysCorrectWhenSparseOrQueriedOutside) {
    // A few points spread over 10 m: the grid coarsens its cells (memory stays
    // linear) and must still find every neighbour, also for queries outside it.
    std::vector<Vec3f> pts = {Vec3f(0.f, 0.f, 0.f), Vec3f(0.005f, 0.f, 0.f), Vec3f(10.f, 10.f, 10.f),
                              Vec3f(9.995f, 10.f, 10.f), Vec3f(5.f, 0.f, 10.f)};
    std::vector<uint32_t> groups = {0, 1, 2, 3, 4};
    SpatialGrid grid;
    grid.build(pts.data(), groups.data(), pts.size(), 0.01f);
    auto near = [&](const Vec3f& x) {
        std::vector<uint32_t> found;
        grid.forEachNear(x, [&](uint32_t j, const Vec3f& p, uint32_t) {
            if ((p - x).norm() < 0.01f) found.push_back(j);
        });
        return found;
    };
    EXPECT_EQ(near(pts[0]), (std::vector<uint32_t>{0, 1}));
    EXPECT_EQ(near(pts[3]), (std::vector<uint32_t>{2, 3}));
    EXPECT_EQ(near(Vec3f(-0.006f, 0.f, 0.f)), (std::vector<uint32_t>{0}));  // just outside the box
    EXPECT_TRUE(near(Vec3f(-5.f, 0.f, 0.f)).empty());
    EXPECT_TRUE(near(Vec3f(std::nanf(""), 0.f, 0.f)).empty());
}

TEST(WetForces, CohesionPullsTowardWetNeighboursOfOtherStrandsOnly) {
    // Two parallel strands 4 mm apart along X, plus a far third one.
    const size_t n = 10;
    std::vector<Vec3f> pts;
    std::vector<uint32_t> strand;
    for (uint32_t s = 0; s < 3; ++s)
        for (size_t i = 0; i < n; ++i) {
            pts.push_back(Vec3f(s == 2 ? 0.5f : 0.004f * float(s), 0.002f * float(i), 0.f));
            strand.push_back(s);
        }
    SpatialGrid grid;
    const float radius = 0.01f;
    grid.build(pts.data(), strand.data(), pts.size(), radius);
    std::vector<CohesionTarget> out(pts.size());
    std::vector<float> sigma(pts.size(), 0.f);
    cohesionTargets(grid, sigma.data(), 0, pts.size(), radius, 0.85f, out.data());
    for (const CohesionTarget& t : out) {
        EXPECT_EQ(t.offset.squaredNorm(), 0.f);  // dry: nothing
        EXPECT_EQ(t.weight, 0.f);
    }
    std::fill(sigma.begin(), sigma.end(), 1.f);
    cohesionTargets(grid, sigma.data(), 0, pts.size(), radius, 0.85f, out.data());
    for (size_t i = 0; i < n; ++i) {
        EXPECT_GT(out[i].offset.x(), 0.f) << i;        // strand 0 toward strand 1 (+X)
        EXPECT_LT(out[n + i].offset.x(), 0.f) << i;    // strand 1 toward strand 0
        EXPECT_EQ(out[2 * n + i].neighbours, 0u);      // the far strand: alone
        EXPECT_EQ(out[2 * n + i].offset.squaredNorm(), 0.f);
        EXPECT_LT(out[i].offset.norm(), 0.85f * 0.004f);  // never past the neighbours
        EXPECT_GT(out[i].weight, 0.f);
        EXPECT_LT(out[i].weight, 0.85f);
    }
    // Symmetric pair, and the closed form of eq. (10) at the middle particle.
    const size_t mid = n / 2;
    EXPECT_NEAR(out[mid].offset.x(), -out[n + mid].offset.x(), 1e-7f);
    float wSum = 0.f;
    Vec3f sum = Vec3f::Zero();
    for (size_t j = n; j < 2 * n; ++j) {
        const Vec3f d = pts[j] - pts[mid];
        const float w = poly6(d.squaredNorm(), radius);
        sum += w * d;
        wSum += w;
    }
    const Vec3f expected = 0.85f * sum / (poly6(0.f, radius) + wSum);
    EXPECT_LT((out[mid].offset - expected).norm(), 1e-6f * expected.norm() + 1e-9f);
    // Half as wet neighbours pull half as hard.
    std::fill(sigma.begin() + n, sigma.begin() + 2 * n, 0.5f);
    std::vector<CohesionTarget> half(pts.size());
    cohesionTargets(grid, sigma.data(), 0, pts.size(), radius, 0.85f, half.data());
    EXPECT_NEAR(half[mid].offset.x(), 0.5f * out[mid].offset.x(), 1e-6f * out[mid].offset.x());
}

TEST(WetForces, AdhesionKernelShapeAndDirection) {
    const float h = 0.5f;  // cm
    EXPECT_EQ(adhesionKernel(0.2f, h), 0.f);
    EXPECT_EQ(adhesionKernel(0.25f, h), 0.f);
    EXPECT_EQ(adhesionKernel(0.51f, h), 0.f);
    EXPECT_NEAR(adhesionKernel(0.5f, h), 0.f, 1e-7f);
    const float peak = adhesionKernel(0.375f, h);  // 3h/4
    EXPECT_NEAR(peak, 0.007f / std::pow(h, 3.25f) * 0.25f * h, 1e-6f);
    EXPECT_GT(peak, adhesionKernel(0.3f, h));
    EXPECT_GT(peak, adhesionKernel(0.45f, h));
    const Vec3f n = Vec3f(1.f, 2.f, 2.f).normalized();
    const Vec3f a = adhesionAcceleration(0.00375f, n, 1.f, 1300.f, 0.005f);
    EXPECT_LT((a + 1300.f * peak * n).norm(), 1e-3f);  // toward the surface
    EXPECT_GT(a.norm(), 5.f);                          // of the order of gravity (see wet_forces.h)
    EXPECT_LT((adhesionAcceleration(0.00375f, n, 0.5f, 1300.f, 0.005f) - 0.5f * a).norm(), 1e-4f);
    EXPECT_EQ(adhesionAcceleration(0.00375f, n, 0.f, 1300.f, 0.005f).squaredNorm(), 0.f);  // dry
    EXPECT_EQ(adhesionAcceleration(0.006f, n, 1.f, 1300.f, 0.005f).squaredNorm(), 0.f);    // released
    EXPECT_EQ(adhesionAcceleration(-0.001f, n, 1.f, 1300.f, 0.005f).squaredNorm(), 0.f);   // inside
}

TEST(WetForces, WetVelocityFactor) {
    EXPECT_FLOAT_EQ(wetVelocityFactor(0.f, 0.9999f, 1.f), 1.f);
    EXPECT_FLOAT_EQ(wetVelocityFactor(1.f, 0.9999f, 1.f), 0.9999f);
    EXPECT_FLOAT_EQ(wetVelocityFactor(0.5f, 0.9999f, 1.f), 0.99995f);
}

}  // namespace
}  // namespace hp::curly
