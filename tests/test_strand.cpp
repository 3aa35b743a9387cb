#include "core/errors.h"
#include "sim/strands/head.h"
#include "sim/strands/strand.h"

#include <gtest/gtest.h>

using namespace hp;

TEST(StrandFrame, AddStrandKeepsArraysConsistent) {
    StrandFrame f;
    const Vec3f p[3] = {{0, 0, 0}, {0, 1, 0}, {0, 2, 0}};
    const float r[3] = {1, 0.5f, 0.1f};
    f.addStrand(7, p, r, 3);
    f.addStrand(8, p, r, 2);
    EXPECT_EQ(f.strandCount(), 2u);
    EXPECT_EQ(f.vertexCount(), 5u);
    EXPECT_EQ(f.first(1), 3u);
    EXPECT_EQ(f.vertexCount(1), 2u);
    EXPECT_TRUE(f.velocities.empty());
    EXPECT_NO_THROW(f.validate());
    const Vec3f v[3] = {{1, 0, 0}, {1, 0, 0}, {1, 0, 0}};
    f.addStrand(9, p, r, 3, v);
    EXPECT_EQ(f.velocities.size(), f.positions.size()) << "earlier strands get zero velocity";
    EXPECT_EQ(f.velocities[0], Vec3f::Zero());
    EXPECT_EQ(f.velocities[5], Vec3f(1, 0, 0));
}

TEST(StrandFrame, ValidateCatchesNaNAndMismatch) {
    StrandFrame f;
    const Vec3f p[2] = {{0, 0, 0}, {0, NAN, 0}};
    const float r[2] = {1, 1};
    f.addStrand(0, p, r, 2);
    EXPECT_THROW(f.validate(), Error);
    f.positions[1].y() = 0;
    EXPECT_NO_THROW(f.validate());
    f.radii.pop_back();
    EXPECT_THROW(f.validate(), Error);
}

TEST(Head, SphereMeshFacesPointOutward) {
    const TriangleMesh m = makeSphereMesh(Vec3f(1, 2, 3), 0.5f, 12, 24);
    int outward = 0;
    for (const Tri& t : m.triangles) {
        const Vec3f n = (m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]);
        const Vec3f c = (m.positions[t[0]] + m.positions[t[1]] + m.positions[t[2]]) / 3.f - Vec3f(1, 2, 3);
        outward += n.dot(c) > 0;
    }
    EXPECT_EQ(outward, int(m.triangles.size()));
    for (const Vec3f& p : m.positions) EXPECT_NEAR((p - Vec3f(1, 2, 3)).norm(), 0.5f, 1e-5f);
}

TEST(Head, SurfacePointFollowsDeformation) {
    TriangleMesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 0, -1}};
    m.triangles = {{0, 1, 2}};
    m.computeNormals();
    const SurfacePoint sp{0, 0.25f, 0.25f};
    SurfaceFrame f = evaluate(m, sp);
    EXPECT_TRUE(f.position.isApprox(Vec3f(0.25f, 0, -0.25f)));
    EXPECT_TRUE(f.normal.isApprox(Vec3f(0, 1, 0)));
    EXPECT_TRUE(f.tangent.isApprox(Vec3f(1, 0, 0)));
    // Rotate the triangle 90 degrees about X: the frame rotates with it.
    const Eigen::AngleAxisf rot(float(M_PI / 2), Vec3f::UnitX());
    for (Vec3f& p : m.positions) p = rot * p;
    m.computeNormals();
    f = evaluate(m, sp);
    EXPECT_TRUE(f.normal.isApprox(rot * Vec3f(0, 1, 0), 1e-5f));
    EXPECT_TRUE(f.tangent.isApprox(rot * Vec3f(1, 0, 0), 1e-5f));
}

TEST(Head, SpinningSphereTurnsAtItsRate) {
    const SpinningSphere head(0.1f, 90.f);
    const HeadPose p0 = head.sample(0.0), p1 = head.sample(1.0);
    const Vec3f x = p1.transform * Vec3f(1, 0, 0);
    EXPECT_NEAR(x.z(), -1.f, 1e-5f) << "90 degrees about +Y takes +X to -Z";
    Vec3f n;
    EXPECT_NEAR(p0.collider->signedDistance(Vec3f(0, 0.2f, 0), &n), 0.1f, 1e-6f);
    EXPECT_TRUE(n.isApprox(Vec3f::UnitY()));
    EXPECT_LT(p0.collider->signedDistance(Vec3f(0, 0.05f, 0)), 0.f);
}

#include "sim/strands/fibonacci.h"

TEST(Fibonacci, CapHoldsExactlyCountPointsInside) {
    for (size_t n : {1u, 94u, 845u, 10000u}) {
        const auto pts = fibonacciCap(n);
        ASSERT_EQ(pts.size(), n);
        for (const Vec3f& p : pts) {
            EXPECT_NEAR(p.norm(), 1.f, 1e-5f);
            EXPECT_GE(p.y(), 0.f);
        }
    }
}

TEST(Fibonacci, LatticeIsEven) {
    // Nearest-neighbour distances of a good lattice vary little.
    const auto pts = fibonacciCap(500);
    float lo = 1e9f, hi = 0.f;
    for (size_t i = 0; i < pts.size(); ++i) {
        float best = 1e9f;
        for (size_t j = 0; j < pts.size(); ++j)
            if (i != j) best = std::min(best, (pts[i] - pts[j]).norm());
        lo = std::min(lo, best);
        hi = std::max(hi, best);
    }
    EXPECT_GT(lo, 0.5f * hi) << "min/max nearest-neighbour spacing " << lo << " / " << hi;
}

TEST(Fibonacci, CapAroundAnotherAxis) {
    const auto pts = fibonacciCap(100, Vec3f(0, 0, 1), 0.5f);
    ASSERT_EQ(pts.size(), 100u);
    for (const Vec3f& p : pts) EXPECT_GE(p.z(), 0.5f - 1e-5f);
}

#include "sim/strands/synthetic.h"

TEST(SyntheticHair, StrandsHaveTheRequestedShape) {
    SyntheticHairSettings s;
    s.strands = 200;
    const StrandFrame f = makeSyntheticHair(s);
    ASSERT_EQ(f.strandCount(), 200u);
    EXPECT_NO_THROW(f.validate());
    for (size_t i = 0; i < f.strandCount(); ++i) {
        float length = 0.f;
        for (uint32_t v = f.first(i) + 1; v < f.first(i) + f.vertexCount(i); ++v) {
            length += (f.positions[v] - f.positions[v - 1]).norm();
            EXPECT_GE(f.positions[v].norm(), s.headRadius) << "outside the head";
        }
        EXPECT_NEAR(length, s.length, 0.02f * s.length);
        EXPECT_NEAR(f.positions[f.first(i)].norm(), s.headRadius, 1e-6f);
        EXPECT_FLOAT_EQ(f.radii[f.first(i)], s.rootRadius);
        EXPECT_FLOAT_EQ(f.radii[f.first(i) + f.vertexCount(i) - 1], s.tipRadius);
    }
}
