// Heads that fold into themselves (sim/collision/mesh_parts.h): a mesh of
// two overlapping closed spheres, A (centre 0, radius 0.1 m) and B (centre
// (0, -0.12, 0), radius 0.05 m), whose top sits inside A. The references are
// the spheres' analytic distances |p - c| - r: the union's is their minimum.
#include "sim/collision/mesh_collider.h"
#include "sim/collision/mesh_parts.h"
#include "sim/followers/followers.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>

using namespace hp;

namespace {

const Vec3f kA(0.f, 0.f, 0.f), kB(0.f, -0.12f, 0.f);
constexpr float kRA = 0.1f, kRB = 0.05f;

float sphereA(const Vec3f& p) { return (p - kA).norm() - kRA; }
float sphereB(const Vec3f& p) { return (p - kB).norm() - kRB; }

/// A and B in one mesh, A's triangles first.
TriangleMesh twoSpheres() {
    TriangleMesh m = makeSphereMesh(kA, kRA, 64, 128);
    const TriangleMesh b = makeSphereMesh(kB, kRB, 48, 96);
    const uint32_t base = uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), b.positions.begin(), b.positions.end());
    m.normals.insert(m.normals.end(), b.normals.begin(), b.normals.end());
    for (const Tri& t : b.triangles) m.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    return m;
}

/// The two parts' exact colliders as a PartsCollider.
PartsCollider partsOf(const TriangleMesh& mesh, const MeshPartition& parts) {
    std::vector<std::shared_ptr<const Collider>> c;
    for (size_t k = 0; k < parts.count(); ++k)
        c.push_back(std::make_shared<MeshCollider>(parts.part(mesh, k), parts.welds[k]));
    return PartsCollider(std::move(c));
}

}  // namespace

TEST(MeshParts, TwoOverlappingShellsAreTwoParts) {
    const TriangleMesh mesh = twoSpheres();
    const MeshPartition parts = partitionMesh(mesh, weldVertices(mesh.positions));
    ASSERT_EQ(parts.count(), 2u);
    const size_t trianglesA = makeSphereMesh(kA, kRA, 64, 128).triangles.size();
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
        ASSERT_EQ(parts.triangleParts[t], t < trianglesA ? 0u : 1u) << "triangle " << t;
    EXPECT_EQ(parts.triangles[0].size() + parts.triangles[1].size(), mesh.triangles.size());
    // A sphere's seam and pole copies weld into its own part, never across.
    const TriangleMesh a = parts.part(mesh, 0);
    for (const Vec3f& p : a.positions) EXPECT_NEAR(sphereA(p), 0.f, 1e-6f);
}

// The union's signed distance, min(φ_A, φ_B), at random points around and
// inside both spheres, within the tessellation's error (a chord's sagitta:
// r (1 - cos(π / rings)) ≤ 0.12 mm for A). The whole mesh as one collider
// gets the overlap wrong: inside A, next to B's buried cap, its nearest
// surface is B's, whose outside it is.
TEST(MeshParts, PartsColliderIsTheUnionAndIgnoringAPartRemovesIt) {
    const TriangleMesh mesh = twoSpheres();
    const MeshPartition parts = partitionMesh(mesh, weldVertices(mesh.positions));
    const PartsCollider collider = partsOf(mesh, parts);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-0.2f, 0.2f);
    const float tolerance = 2e-4f;
    for (int i = 0; i < 2000; ++i) {
        const Vec3f p(u(rng), u(rng) - 0.05f, u(rng));
        ASSERT_NEAR(collider.signedDistance(p), std::min(sphereA(p), sphereB(p)), tolerance) << p.transpose();
        ASSERT_NEAR(collider.signedDistanceIgnoring(p, nullptr, 1u << 1), sphereA(p), tolerance) << p.transpose();
        ASSERT_NEAR(collider.signedDistanceIgnoring(p, nullptr, 1u << 0), sphereB(p), tolerance) << p.transpose();
    }
    // 5 mm above B's top, 3.5 cm inside A: the union is inside, by A's depth.
    const Vec3f above(0.f, kB.y() + kRB + 0.005f, 0.f);
    Vec3f n;
    EXPECT_NEAR(collider.signedDistance(above, &n), sphereA(above), tolerance);
    EXPECT_GT(n.dot(above - kA), 0.f) << "the normal leads out of A";
    EXPECT_GT(MeshCollider(mesh).signedDistance(above), 0.f)
        << "the whole mesh's nearest surface (B's cap) says outside: why the parts are queried apart";
}

// Roots on B's cap inside A ignore A (bit 0), roots on A's underside inside
// B ignore B (bit 1); every other root ignores nothing.
TEST(MeshParts, RootsInsideAnotherPartIgnoreIt) {
    const TriangleMesh mesh = twoSpheres();
    const MeshPartition parts = partitionMesh(mesh, weldVertices(mesh.positions));
    std::vector<SurfacePoint> roots;
    for (uint32_t t = 0; t < mesh.triangles.size(); t += 7) roots.push_back({t, 1.f / 3.f, 1.f / 3.f});
    const std::vector<uint32_t> masks = partsAroundRoots(parts, mesh, roots);
    ASSERT_EQ(masks.size(), roots.size());
    size_t inside = 0;
    for (size_t r = 0; r < roots.size(); ++r) {
        const Vec3f p = evaluate(mesh, roots[r]).position;
        const bool onB = parts.triangleParts[roots[r].triangle] == 1;
        // Away from the other sphere's surface by more than the tessellation.
        if (std::abs(onB ? sphereA(p) : sphereB(p)) < 1e-3f) continue;
        const uint32_t expected = onB ? (sphereA(p) < 0.f ? 1u : 0u) : (sphereB(p) < 0.f ? 2u : 0u);
        EXPECT_EQ(masks[r], expected) << "root " << r << " at " << p.transpose();
        inside += expected ? 1 : 0;
    }
    EXPECT_GT(inside, 10u) << "the buried caps carry roots";
}

// Followers take the guides' rule (sim/followers/followers.h FollowerStep::
// ignoreParts): hair rooted on B's cap where it lies inside A, standing 2 cm
// along its normal, stays inside A and outside B. Ignoring A (the mask
// partsAroundRoots gives its root), no follower vertex is projected, bent or
// pinned, and every one is exactly where it is without collision: outside
// B, the only part such a strand collides with. Handed no masks, the same
// followers are pushed toward A's outside, which they cannot reach at their
// lengths (the failure the rule removes). Serial and parallel agree.
TEST(MeshParts, FollowersIgnoreThePartsTheirRootsLieInside) {
    const TriangleMesh mesh = twoSpheres();
    const MeshPartition parts = partitionMesh(mesh, weldVertices(mesh.positions));
    const PartsCollider collider = partsOf(mesh, parts);
    // Roots on every 12th of B's triangles at least 5 mm inside A, every
    // 6th of them a guide (few: a follower caught without its mask costs
    // hundreds of queries deep inside A).
    std::vector<SurfacePoint> guideRoots, followerRoots;
    size_t n = 0;
    for (uint32_t t = 0; t < mesh.triangles.size(); t += 12) {
        if (parts.triangleParts[t] != 1) continue;
        const SurfacePoint r{t, 1.f / 3.f, 1.f / 3.f};
        if (sphereA(evaluate(mesh, r).position) > -0.005f) continue;
        (n++ % 6 == 0 ? guideRoots : followerRoots).push_back(r);
    }
    ASSERT_GT(guideRoots.size(), 10u);
    const std::vector<uint32_t> masks = partsAroundRoots(parts, mesh, followerRoots);
    for (uint32_t m : masks) ASSERT_EQ(m, 1u) << "every root lies inside A";

    const int vertices = 6;
    const float length = 0.02f;
    FollowerGroom groom;
    for (const SurfacePoint& r : guideRoots) groom.guideRoots.push_back(evaluate(mesh, r));
    for (const SurfacePoint& r : followerRoots) groom.followerRoots.push_back(evaluate(mesh, r));
    groom.guideShapes = RestShapes::straight(guideRoots.size(), vertices, length);
    groom.followerVertices = {uint32_t(vertices)};
    groom.followerLengths = {length};
    StrandFrame guides;  // at rest: straight along their root normals
    for (size_t g = 0; g < groom.guideRoots.size(); ++g) {
        std::vector<Vec3f> p;
        for (int k = 0; k < vertices; ++k)
            p.push_back(groom.guideRoots[g].position + (length * float(k) / float(vertices - 1)) * groom.guideRoots[g].normal);
        const std::vector<float> radii(p.size(), 6e-5f);
        guides.addStrand(uint32_t(g), p.data(), radii.data(), p.size(), nullptr);
    }
    guides.guideCount = uint32_t(groom.guideRoots.size());

    FollowerSettings loose, serial;
    loose.collide = false;
    serial.parallel = false;
    StrandFrame free, seen, seenSerial, blind;
    Followers(groom, loose).update({guides, groom.guideRoots, groom.followerRoots, &collider}, free);
    const FollowerStats s =
        Followers(groom, {}).update({guides, groom.guideRoots, groom.followerRoots, &collider, 0.0, masks.data()}, seen);
    Followers(groom, serial).update({guides, groom.guideRoots, groom.followerRoots, &collider, 0.0, masks.data()},
                                    seenSerial);
    EXPECT_EQ(s.projected, 0u);
    EXPECT_EQ(s.bent, 0u);
    EXPECT_EQ(s.pinned, 0u);
    EXPECT_TRUE(seen.positions == free.positions) << "no follower vertex moved by the part over its root";
    EXPECT_TRUE(seen.positions == seenSerial.positions) << "serial and parallel differ";
    float deepest = -1.f, deepestInA = 0.f;
    for (size_t k = seen.guideCount; k < seen.strandCount(); ++k)
        for (uint32_t i = seen.first(k) + 1; i < seen.offsets[k + 1]; ++i) {
            deepest = std::max(deepest, -collider.signedDistanceIgnoring(seen.positions[i], nullptr, 1u));
            deepestInA = std::max(deepestInA, -sphereA(seen.positions[i]));
        }
    EXPECT_LE(deepest, 0.f) << "outside B, analytically within the tessellation";
    EXPECT_GT(deepestInA, 0.005f) << "the followers stand inside A, which they ignore";
    const FollowerStats b = Followers(groom, {}).update({guides, groom.guideRoots, groom.followerRoots, &collider}, blind);
    EXPECT_GT(b.projected, 0u) << "without the masks the followers fight A";
    std::printf("%zu guides, %zu followers; without masks %zu projected, %zu bent, %zu pinned\n", guideRoots.size(),
                followerRoots.size(), b.projected, b.bent, b.pinned);
}
