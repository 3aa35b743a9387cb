// The generalized winding number (sim/collision/winding_number.h) and the
// roots it finds buried by their own part's fold (sim/collision/mesh_parts.h
// buriedByOwnPart), on a surface that crosses itself, built here: one
// triangle list of two overlapping closed spheres, A (centre 0, radius 1)
// and B (centre (1.2, 0, 0), radius 1). As one surface it wraps the lens
// A ∩ B twice, A \ B and B \ A once, the rest not at all; that count, from
// the spheres' analytic distances, is the reference. Inside B but outside A
// next to A's buried sheet, the closest triangle is A's, whose outside the
// point is: the closest triangle's sign says outside there, wrongly.
#include "sim/collision/level_set.h"
#include "sim/collision/mesh_collider.h"
#include "sim/collision/mesh_parts.h"
#include "sim/collision/mesh_query.h"
#include "sim/collision/winding_number.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace hp;

namespace {

const Vec3f kA(0.f, 0.f, 0.f), kB(1.2f, 0.f, 0.f);
constexpr float kR = 1.f;

/// A and B as one triangle list (a surface that crosses itself), A first.
TriangleMesh crossedSpheres() {
    TriangleMesh m = makeSphereMesh(kA, kR, 48, 96);
    const TriangleMesh b = makeSphereMesh(kB, kR, 48, 96);
    const uint32_t base = uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), b.positions.begin(), b.positions.end());
    for (const Tri& t : b.triangles) m.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    return m;
}

/// Layers of the surface around p: one per sphere that holds it.
int layers(const Vec3f& p) { return int((p - kA).norm() < kR) + int((p - kB).norm() < kR); }

}  // namespace

TEST(WindingNumber, CountsTheLayersOfASurfaceThatCrossesItself) {
    const TriangleMesh mesh = crossedSpheres();
    const MeshCollider nearest(mesh);
    const MeshQuery query(mesh);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> x(-1.5f, 2.7f), yz(-1.3f, 1.3f);
    int checked = 0, nearestWrong = 0;
    for (int i = 0; i < 400; ++i) {
        const Vec3f p(x(rng), yz(rng), yz(rng));
        // Away from both spheres by more than the tessellation's sagitta
        // (r (1 - cos(π / 48)) ≈ 2 mm), where the count is unambiguous.
        if (std::min(std::abs((p - kA).norm() - kR), std::abs((p - kB).norm() - kR)) < 0.01f) continue;
        ++checked;
        const double w = windingNumber(mesh, p);
        EXPECT_NEAR(w, layers(p), 1e-3) << "at (" << p.transpose() << ")";
        // The ray-certified form agrees, along any direction.
        const Vec3f d = Vec3f(yz(rng), yz(rng), yz(rng)).normalized();
        EXPECT_NEAR(windingNumber(mesh, query, p, d), w, 1e-6) << "at (" << p.transpose() << ")";
        nearestWrong += (nearest.signedDistance(p) < 0.f) != (layers(p) > 0);
    }
    EXPECT_GT(checked, 300);
    // The closest triangle's sign is wrong somewhere (B \ A next to A's
    // sheet, A \ B next to B's): what the winding number is for.
    EXPECT_GT(nearestWrong, 0);
}

TEST(WindingNumber, SolidAngleOfAnOctantTriangleIsAnEighthOfTheSphere) {
    // The triangle (x, y, z unit axes) seen from the origin covers one
    // octant of the unit sphere: 4π / 8, positive from behind its face.
    const float pi = float(M_PI);
    EXPECT_NEAR(solidAngle(Vec3f::Zero(), Vec3f::UnitX(), Vec3f::UnitY(), Vec3f::UnitZ()), pi / 2, 1e-6);
    EXPECT_NEAR(solidAngle(Vec3f::Zero(), Vec3f::UnitX(), Vec3f::UnitZ(), Vec3f::UnitY()), -pi / 2, 1e-6);
}

TEST(WindingNumber, ARootUnderItsOwnSurfacesOtherSheetIsBuried) {
    // Roots on A's sheet: inside B (A's sheet buried by the other layer)
    // they are buried, outside B they are not, as |root - c_B| < r says.
    const TriangleMesh mesh = crossedSpheres();
    const MeshQuery query(mesh);
    const MeshQuery onA(mesh);  // the root's triangle is looked up on the mesh
    const size_t trianglesA = makeSphereMesh(kA, kR, 48, 96).triangles.size();
    int buried = 0, open = 0;
    for (uint32_t t = 0; t < trianglesA; t += 7) {
        const SurfacePoint root{t, 1.f / 3.f, 1.f / 3.f};
        const Vec3f p = evaluate(mesh, root).position;
        const float toB = (p - kB).norm() - kR;
        if (std::abs(toB) < 0.01f) continue;  // on the crossing circle: ambiguous
        const bool expected = toB < 0.f;
        EXPECT_EQ(buriedByOwnPart(mesh, query, mesh, root), expected) << "triangle " << t << ", " << toB << " m from B";
        (expected ? buried : open) += 1;
    }
    EXPECT_GT(buried, 10);
    EXPECT_GT(open, 10);
}

TEST(LevelSetCollider, DeepInsideAFoldTakesTheGridsSideNotTheClosestTriangles) {
    // Beyond the grid's interior band the collider asks the exact mesh for
    // the depth. At p = (1.3, 0, 0), inside B and outside A, the closest
    // sheet is A's (0.3 away; B's is 0.9), whose pseudonormal says outside.
    // The grid's flood fill (OpenVDB) knows p is enclosed: inside, 0.3 deep
    // as far as the closest sheet tells (a lower bound of the depth).
    const TriangleMesh mesh = crossedSpheres();
    LevelSetSettings s;
    s.voxelSize = 0.025f;
    s.exteriorBand = s.interiorBand = 0.1f;
    const auto grid = std::make_shared<const LevelSet>(mesh, s);
    const auto exact = std::make_shared<const MeshCollider>(mesh);
    const LevelSetCollider collider(grid, Eigen::Isometry3f::Identity(), exact);
    const Vec3f p(1.3f, 0.f, 0.f);
    ASSERT_GT(exact->signedDistance(p), 0.f) << "the closest triangle's sign is wrong here, as the test needs";
    Vec3f n;
    const float d = collider.signedDistance(p, &n);
    EXPECT_NEAR(d, -(p - kA).norm() + kR, 3e-3f);
    // The normal points out of the inside the collider reports: toward the
    // closest sheet, here -x (A's sheet lies at x = 1).
    EXPECT_LT(n.x(), -0.99f);
}
