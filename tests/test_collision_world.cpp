// Colliders beside the head (sim/collision/collision_world.h): Bullet primitives and a
// mesh prop in one collision world, joined to the head's collider; hair
// lies on them. Distances are checked against the geometry computed here.
#include "pipeline/head/head_import.h"
#include "pipeline/head/head_setup.h"
#include "pipeline/scene/scene.h"
#include "sim/collision/collision_world.h"
#include "sim/strands/fibonacci.h"
#include "sim/guides/guides.h"
#include "sim/collision/mesh_collider.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>

using namespace hp;
using namespace hp::test;

namespace {

Eigen::Isometry3f at(const Vec3f& t, float yawDegrees = 0.f) {
    Eigen::Isometry3f p = Eigen::Isometry3f::Identity();
    p.linear() = Eigen::AngleAxisf(yawDegrees * float(M_PI / 180.0), Vec3f::UnitY()).toRotationMatrix();
    p.translation() = t;
    return p;
}

/// The rope with nearly limp joints, 0.2 m long: hair that drapes fully, so
/// a test measures the collider (what lies on it), not stiffness.
GuideSettings limpRope() {
    GuideSettings s;
    s.formulation = GuideFormulation::Rope;
    s.preload = false;
    s.bendStiffness = 1e-7f;
    s.limitStiffness = 1e-7f;
    s.length = 0.2f;
    s.strandsPerWorld = 8;
    return s;
}

ColliderShape box(const Vec3f& half) {
    ColliderShape s;
    s.kind = ColliderShape::Kind::Box;
    s.halfExtents = half;
    return s;
}

/// A cup: a closed solid of revolution about +Y (outer radius R, inner
/// radius Ri, height H, floor thickness B), wound outward, N sectors.
ColliderShape cup(ColliderShape::Kind kind, float R, float Ri, float H, float B, int N) {
    // The profile (r, y), traversed so that its normal faces out of the solid:
    // bottom centre, out, up the outer wall, in across the rim, down the
    // inner wall, in across the floor of the hollow.
    const float profile[][2] = {{0, 0}, {R, 0}, {R, H}, {Ri, H}, {Ri, B}, {0, B}};
    ColliderShape s;
    s.kind = kind;
    for (const auto& p : profile)
        for (int j = 0; j < N; ++j) {
            const float a = 2.f * float(M_PI) * float(j) / float(N);
            s.points.emplace_back(p[0] * std::cos(a), p[1], p[0] * std::sin(a));
        }
    for (uint32_t k = 0; k + 1 < 6; ++k)
        for (uint32_t j = 0; j < uint32_t(N); ++j) {
            const uint32_t a = k * N + j, b = (k + 1) * N + j, c = (k + 1) * N + (j + 1) % N, d = k * N + (j + 1) % N;
            s.triangles.push_back({a, b, c});
            s.triangles.push_back({a, c, d});
        }
    return s;
}

/// Roots on a sphere head along `dirs` (outward normals).
std::vector<SurfaceFrame> sphereRoots(const Vec3f& centre, float radius, const std::vector<Vec3f>& dirs) {
    std::vector<SurfaceFrame> roots(dirs.size());
    for (size_t i = 0; i < dirs.size(); ++i) {
        roots[i].position = centre + radius * dirs[i];
        roots[i].normal = dirs[i];
        roots[i].tangent = dirs[i].unitOrthogonal();
    }
    return roots;
}

}  // namespace

TEST(CollisionWorld, SignedDistancesOfBulletPrimitivesMatchTheGeometry) {
    ColliderShape sphere, capsule;
    sphere.kind = ColliderShape::Kind::Sphere;
    sphere.radius = 0.1f;
    capsule.kind = ColliderShape::Kind::Capsule;
    capsule.radius = 0.05f;
    capsule.length = 0.2f;
    const CollisionWorld world({sphere, box({0.2f, 0.05f, 0.1f}), capsule});
    const auto posed = world.posed({at({1, 0, 0}), at({0, 0, 0}, 30.f), at({-1, 0, 0})}, 1.f);
    Vec3f n;
    // Sphere: |p - c| - r, normal along p - c.
    EXPECT_NEAR(posed->signedDistance({1.3f, 0, 0}, &n), 0.2f, 1e-5f);
    EXPECT_NEAR(posed->signedDistance({1.f, 0.05f, 0}, &n), -0.05f, 1e-4f);
    EXPECT_GT(n.y(), 0.999f) << "inside, the normal points the way out";
    // Box turned 30° about Y: above the top face the distance is the height
    // over it; inside, minus the depth below it (closer than the sides).
    const Vec3f local(0.1f, 0.f, 0.03f);
    const Vec3f onTop = at({0, 0, 0}, 30.f) * local;
    EXPECT_NEAR(posed->signedDistance(onTop + Vec3f(0, 0.08f, 0), &n), 0.03f, 1e-5f);
    EXPECT_GT(n.y(), 0.999f);
    EXPECT_NEAR(posed->signedDistance(onTop + Vec3f(0, 0.04f, 0), &n), -0.01f, 1e-5f);
    EXPECT_GT(n.y(), 0.999f);
    // Beside the rotated box: the distance to the face x = 0.2 (local).
    const Vec3f beside = at({0, 0, 0}, 30.f) * Vec3f(0.25f, 0.f, 0.f);
    EXPECT_NEAR(posed->signedDistance(beside, &n), 0.05f, 1e-5f);
    EXPECT_NEAR(n.dot(at({0, 0, 0}, 30.f).linear() * Vec3f::UnitX()), 1.f, 1e-4f);
    // Capsule along Y: distance to the segment minus the radius.
    EXPECT_NEAR(posed->signedDistance({-0.9f, 0.05f, 0}, &n), 0.05f, 1e-5f);
    EXPECT_NEAR(posed->signedDistance({-1.f, 0.25f, 0}, &n), 0.1f, 1e-5f) << "past the cap centre at y = 0.1";
    // Far from every collider: the query range, a lower bound.
    const auto near = world.posed({at({1, 0, 0}), at({0, 0, 0}, 30.f), at({-1, 0, 0})});
    EXPECT_FLOAT_EQ(near->signedDistance({0, 5, 0}), 0.05f);
    // The union with a head collider: the nearer surface wins.
    const CompositeCollider both(std::make_shared<SphereCollider>(Vec3f(0, 1, 0), 0.1f), posed);
    EXPECT_NEAR(both.signedDistance({0, 0.85f, 0}, &n), 0.05f, 1e-5f);
    EXPECT_LT(n.y(), -0.999f) << "the head above is nearer than the box below";
    EXPECT_NEAR(both.signedDistance({0, 0.07f, 0}, &n), 0.02f, 1e-5f);
}

// Limp guides from the side of a head fall under gravity; shoulders (a box
// just below the head) catch them. Without the box the same hair hangs below
// the box's top; with it, no vertex gets more than 1 mm inside and hair lies
// on the top face.
TEST(CollisionWorld, HairOnAShoulderBoxStaysOnIt) {
    const Vec3f headCentre(0, 0.3f, 0);
    const float headRadius = 0.1f, top = 0.19f;
    const CollisionWorld shoulders({box({0.25f, 0.05f, 0.12f})});
    const std::vector<Vec3f> dirs = fibonacciCap(40, Vec3f::UnitY(), -0.2f);
    auto run = [&](bool withShoulders, size_t& below, size_t& resting, float& worstDepth, double& worstStretch) {
        GuideSolver solver(limpRope());
        HeadPose pose;
        auto posed = shoulders.posed({at({0, top - 0.05f, 0})});
        pose.transform = at(headCentre);
        auto head = std::make_shared<SphereCollider>(headCentre, headRadius);
        pose.collider = withShoulders ? std::shared_ptr<const Collider>(std::make_shared<CompositeCollider>(head, posed))
                                      : std::shared_ptr<const Collider>(head);
        const std::vector<SurfaceFrame> roots = sphereRoots(headCentre, headRadius, dirs);
        solver.initialize(roots, pose);
        worstDepth = 0.f;
        worstStretch = 0.0;
        for (int k = 0; k < 150; ++k) {
            pose.time = solver.nextTime();
            const StepStats& st = solver.step(roots, pose);
            worstStretch = std::max(worstStretch, st.maxLengthError);
            StrandFrame f;
            solver.write(f);
            for (const Vec3f& p : f.positions) worstDepth = std::max(worstDepth, -posed->signedDistance(p));
        }
        StrandFrame f;
        solver.write(f);
        below = resting = 0;
        for (const Vec3f& p : f.positions) {
            const bool over = std::abs(p.x()) < 0.24f && std::abs(p.z()) < 0.11f;
            if (over && p.y() < top - 0.01f) ++below;
            if (over && std::abs(p.y() - top) < 0.004f) ++resting;
        }
    };
    size_t below = 0, resting = 0;
    float depth = 0.f;
    double stretch = 0.0;
    run(false, below, resting, depth, stretch);
    ASSERT_GT(below, 50u) << "without shoulders the hair hangs below their top";
    run(true, below, resting, depth, stretch);
    EXPECT_EQ(below, 0u) << "no vertex falls through the shoulders";
    EXPECT_GT(resting, 50u) << "hair lies on the top face";
    // The rope's finish pass places each vertex last by projecting it out of
    // the collider it is given, the head and box together, to the collision
    // radius (sim/solver/head_contact.h placeOutside): no vertex is ever
    // inside the box, not even by rounding (the radius is far above it).
    EXPECT_EQ(depth, 0.f) << "deepest vertex inside the box, every step";
    // The rope's finish pass puts every vertex at exactly its rest length
    // from its parent (follow-the-leader; the head's last projection wins
    // over the length only for a parent inside, which never happens here),
    // so what is left is float rounding: each coordinate is rounded to
    // FLT_EPSILON/2 of its magnitude (here |x| < 0.6 m), at both ends of a
    // segment, and the measurement rounds again: within 4·0.6·FLT_EPSILON/l
    // of the rest length l = 0.2/23 m (3.3e-5; measured 3.8e-6). Bullet's
    // link passes alone leave errors orders of magnitude larger.
    const double rounding = 4.0 * 0.6 * FLT_EPSILON / (0.2 / 23);
    EXPECT_LE(stretch, rounding) << "lying on the box does not stretch the strands";
}

// A prop from a second file, placed and keyed by head.colliders[] keys.
TEST(CollisionWorld, PropColliderFromASecondFile) {
    TempDir dir;
    // A 10 cm cube, in centimetres.
    writeFile(dir / "prop.obj", "v -5 -5 -5\nv 5 -5 -5\nv 5 5 -5\nv -5 5 -5\nv -5 -5 5\nv 5 -5 5\nv 5 5 5\nv -5 5 5\n"
                                "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 4 8 7\nf 4 7 3\n"
                                "f 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n");
    writeFile(dir / "s.yaml", "fps: 25\nhead:\n  file: " + sourcePath("scenes/assets/head.glb").string() +
                                  "\n  clip: none\n  colliders:\n"
                                  "    - {type: mesh, file: prop.obj, unit_scale: 0.01, translate: [0.5, 0, 0],\n"
                                  "       move_y: [[0, 0], [25, 0.2]]}\n");
    const Scene scene = Scene::load(dir / "s.yaml");
    const HeadSetup head = loadHead(scene);
    Vec3f n;
    const HeadPose start = head.motion->sample(0.0);
    EXPECT_NEAR(start.collider->signedDistance({0.5f, 0.f, 0.f}, &n), -0.05f, 1e-4f) << "the cube's centre";
    EXPECT_NEAR(start.collider->signedDistance({0.556f, 0.f, 0.f}, &n), 0.006f, 1e-4f);
    EXPECT_GT(n.x(), 0.999f);
    const HeadPose later = head.motion->sample(1.0);  // frame 25: moved up 0.2 m
    EXPECT_NEAR(later.collider->signedDistance({0.5f, 0.2f, 0.f}), -0.05f, 1e-4f);
    EXPECT_NEAR(later.collider->signedDistance({0.5f, 0.256f, 0.f}), 0.006f, 1e-4f);
    // Farther than the colliders' 1 cm range: a lower bound (the head's own grid does the same 6 mm out).
    EXPECT_NEAR(later.collider->signedDistance({0.5f, 0.28f, 0.f}), 0.01f, 1e-6f);
    EXPECT_LT(later.collider->signedDistance({0.f, 0.f, 0.f}), 0.f) << "the head's own collider is still there";
}

// A skinned body (here the head file's own meshes), played by its own clip: at a nodding pose the
// collider's surface is the deformed mesh (posed here independently through
// the same file), not the rest mesh.
TEST(CollisionWorld, SkinnedBodyColliderFollowsItsSkin) {
    TempDir dir;
    const std::string glb = sourcePath("scenes/assets/head.glb").string();
    writeFile(dir / "s.yaml", "fps: 25\nhead:\n  file: " + glb +
                                  "\n  clip: none\n  collider: {method: none}\n  colliders:\n"
                                  "    - {type: skinned, clip: nod_shake_turn}\n");  // the head's own file
    try {
        loadHead(Scene::load(dir / "s.yaml", {"head.colliders[0].meshes=Tail"}));
        ADD_FAILURE() << "a mesh the file does not have is an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("head.colliders[0].meshes"), std::string::npos) << e.what();
    }
    const Scene scene = Scene::load(dir / "s.yaml");
    const HeadSetup head = loadHead(scene);
    HeadImportSettings import;
    import.file = glb;
    auto rig = std::make_shared<const HeadRig>(importHead(import));
    HeadAnimationSettings play;
    play.clip = 0;
    play.collider = ColliderMethod::None;
    const AnimatedHead body(rig, play);
    TriangleMesh rest = body.rest();
    rest.computeNormals();
    // Each pose's skin refits a tree of its own (built once on the rest
    // pose): two poses alive at once (the nod down, then up), then a third
    // once they are gone, which refits a tree the others used.
    auto check = [&](double t, const std::shared_ptr<const Collider>& collider) {
        TriangleMesh skin = body.sample(t).mesh;
        skin.computeNormals();
        // Reference: the exact closest-triangle distance of the deformed mesh
        // (Embree BVH, angle-weighted pseudonormals; sim/collision/mesh_collider.h).
        const MeshCollider exact(skin);
        float worst = 0.f;
        size_t moved = 0, checked = 0, sides = 0;
        for (size_t v = 0; v < skin.positions.size(); v += 23) {
            const Vec3f& p = skin.positions[v];
            const Vec3f& n = skin.normals[v];
            for (float offset : {0.003f, 0.001f, -0.001f, -0.002f}) {
                const Vec3f q = p + offset * n;
                const float d = collider->signedDistance(q);
                worst = std::max(worst, std::abs(d - exact.signedDistance(q)));
                sides += (d > 0.f) == (offset > 0.f);  // just outside the moved skin is outside, just inside inside
            }
            // The same offset from the rest pose is off the skin where the nod moved it.
            const Vec3f r = rest.positions[v] + 0.003f * rest.normals[v];
            if (std::abs(collider->signedDistance(r) - exact.signedDistance(r)) < 1e-4f &&
                std::abs(exact.signedDistance(r) - 0.003f) > 0.002f)
                ++moved;
            ++checked;
        }
        EXPECT_LE(worst, 1e-4f) << "t = " << t << ": within 3 mm of the deformed skin, inside and out, Bullet's "
                                   "distance is the exact one";
        EXPECT_EQ(sides, 4 * checked) << "t = " << t;
        // Deep inside, beyond the 1 cm the colliders measure near a surface:
        // ray parity says inside, and the search goes on to the exact depth.
        const Vec3f centre = body.sample(t).transform * Vec3f(0.f, 0.02f, -0.01f);
        EXPECT_LT(exact.signedDistance(centre), -0.05f) << "the skull's centre";
        EXPECT_NEAR(collider->signedDistance(centre), exact.signedDistance(centre), 1e-4f) << "t = " << t;
        EXPECT_GT(moved, checked / 4) << "t = " << t << ": the collider is the deformed mesh, not the rest mesh";
    };
    {
        const auto down = head.motion->sample(0.375).collider;  // the first nod at its deepest: 20° down
        const auto up = head.motion->sample(0.625).collider;    // and 20° up, while the first pose is alive
        check(0.375, down);
        check(0.625, up);
    }
    check(2.0, head.motion->sample(2.0).collider);  // mid-shake, on a refitted tree
}

// A cup (a non-convex prop) as a GImpact mesh keeps its hollow open; its
// convex hull fills it. Distances against the cup's geometry computed here,
// then limp hair hanging from a head above the cup: into the hollow with
// the mesh, held on the rim's level by the hull.
TEST(CollisionWorld, NonConvexPropKeepsItsHollowWhereAHullFillsIt) {
    const float R = 0.08f, Ri = 0.07f, H = 0.15f, B = 0.01f;
    const int N = 48;
    const CollisionWorld mesh({cup(ColliderShape::Kind::Mesh, R, Ri, H, B, N)});
    const CollisionWorld hull({cup(ColliderShape::Kind::ConvexMesh, R, Ri, H, B, N)});
    const Eigen::Isometry3f place = at({0, 0, 0});
    const auto m = mesh.posed({place}, 0.1f), h = hull.posed({place}, 0.1f);
    // On the axis, in the hollow: the inner wall's apothem away, outside the solid.
    const float apothem = Ri * std::cos(float(M_PI) / N);
    Vec3f n;
    EXPECT_NEAR(m->signedDistance({0, 0.1f, 0}, &n), apothem, 1e-4f);
    EXPECT_NEAR(h->signedDistance({0, 0.1f, 0}), -(H - 0.1f), 1e-4f) << "the hull: inside, 5 cm under its top";
    // In the wall (halfway between the radii) and in the floor: inside both.
    EXPECT_NEAR(m->signedDistance({0.5f * (R + Ri), 0.1f, 0}, &n), -0.5f * (R - Ri), 2e-4f);
    EXPECT_GT(n.x(), 0.99f) << "pushed out through the outer wall (the nearer, by the winding)";
    EXPECT_NEAR(m->signedDistance({0.02f, 0.004f, 0}, &n), -0.004f, 1e-4f);
    EXPECT_LT(n.y(), -0.999f) << "out through the bottom";
    // Just above the hollow's floor: 2 mm outside the solid, pushed up.
    EXPECT_NEAR(m->signedDistance({0.01f, B + 0.002f, 0.01f}, &n), 0.002f, 1e-4f);
    EXPECT_GT(n.y(), 0.999f);

    // Limp guides from the underside of a small head above the cup.
    const Vec3f headCentre(0, 0.3f, 0);
    const float headRadius = 0.05f;
    const std::vector<Vec3f> dirs = fibonacciCap(12, -Vec3f::UnitY(), 0.8f);
    auto hang = [&](const std::shared_ptr<const Collider>& prop, size_t& inHollow, float& worstDepth) {
        GuideSolver solver(limpRope());
        HeadPose pose;
        pose.transform = at(headCentre);
        pose.collider = std::make_shared<CompositeCollider>(std::make_shared<SphereCollider>(headCentre, headRadius), prop);
        const std::vector<SurfaceFrame> roots = sphereRoots(headCentre, headRadius, dirs);
        solver.initialize(roots, pose);
        worstDepth = 0.f;
        StrandFrame f;
        for (int k = 0; k < 50; ++k) {
            pose.time = solver.nextTime();
            solver.step(roots, pose);
            solver.write(f);
            for (const Vec3f& p : f.positions) worstDepth = std::max(worstDepth, -prop->signedDistance(p));
        }
        inHollow = 0;
        for (const Vec3f& p : f.positions)
            inHollow += p.y() < H - 0.01f && Vec2f(p.x(), p.z()).norm() < Ri;
    };
    size_t inMesh = 0, inHull = 0;
    float depthMesh = 0.f, depthHull = 0.f;
    hang(m, inMesh, depthMesh);
    hang(h, inHull, depthHull);
    EXPECT_GT(inMesh, 50u) << "hair hangs into the cup's hollow (a 20 cm strand reaches 9 cm below the rim)";
    EXPECT_EQ(inHull, 0u) << "the hull fills the hollow: hair stops on its top";
    // The rope's last projection keeps every vertex the collision radius
    // outside the collider it is given (HairOnAShoulderBoxStaysOnIt): none
    // inside the cup's walls or its hull.
    EXPECT_EQ(depthMesh, 0.f) << "no vertex inside the cup's walls";
    EXPECT_EQ(depthHull, 0.f);
}
