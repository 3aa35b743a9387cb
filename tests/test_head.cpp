// Head import through assimp and its animation (pipeline/head/head_import.h,
// pipeline/head/head_rig.h, pipeline/head/animated_head.h) on the shared third-party
// assets and the project's default head.
#include "pipeline/head/animated_head.h"
#include "pipeline/head/default_head.h"
#include "pipeline/head/head_import.h"
#include "render/image/image_io.h"
#include "sim/collision/mesh_query.h"
#include "sim/strands/roots.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <functional>

using namespace hp;
using namespace hp::test;

namespace {

std::shared_ptr<const HeadRig> load(const std::filesystem::path& file, double unitScale = 1.0,
                                    std::vector<std::string> meshes = {}) {
    HeadImportSettings s;
    s.file = file;
    s.unitScale = unitScale;
    s.meshes = std::move(meshes);
    return std::make_shared<const HeadRig>(importHead(s));
}

AnimatedHead animate(std::shared_ptr<const HeadRig> rig, int clip, ColliderMethod collider = ColliderMethod::None) {
    HeadAnimationSettings a;
    a.clip = clip;
    a.collider = collider;
    return AnimatedHead(std::move(rig), a);
}

float maxDistance(const std::vector<Vec3f>& a, const std::vector<Vec3f>& b) {
    float d = 0.f;
    for (size_t i = 0; i < a.size(); ++i) d = std::max(d, (a[i] - b[i]).norm());
    return d;
}

/// The default head's scalp material above where the neck bone's weight
/// fades out: it moves rigidly with the head bone.
std::vector<uint8_t> rigidScalp(const HeadRig& rig, const TriangleMesh& rest) {
    std::vector<uint8_t> scalp(rest.triangleCount(), 0);
    for (size_t t = 0; t < rig.meshes[0].triangles.size(); ++t) {
        const Tri& tri = rest.triangles[t];
        scalp[t] = std::all_of(tri.begin(), tri.end(), [&](uint32_t v) { return rest.positions[v].y() > -0.045f; });
    }
    return scalp;
}

std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const AssetError& e) {
        return e.what();
    }
    return "no AssetError";
}

}  // namespace

TEST(HeadImport, SharedAssetsLoadWithTheirMeshesBonesMorphsAndClips) {
    struct Expect {
        const char* file;
        size_t triangles, bones, morphs, clips;
    };
    // Counts from the assets' README (glTF JSON); RobotExpressive's Head has
    // 3 targets on each of its 3 primitives.
    for (const Expect& e : {Expect{"Fox.glb", 576, 24, 0, 3}, Expect{"RobotExpressive.glb", 3237, 43, 9, 14},
                            Expect{"LeePerrySmith.glb", 17684, 0, 0, 0}, Expect{"CesiumMan.glb", 4672, 19, 0, 1},
                            Expect{"AnimatedMorphCube.glb", 12, 0, 2, 1},
                            Expect{"AnimatedMorphCube/AnimatedMorphCube.gltf", 12, 0, 2, 1},
                            Expect{"Suzanne/Suzanne.gltf", 3936, 0, 0, 0}}) {
        HP_REQUIRE_ASSET(path, e.file);
        const auto rig = load(path);
        EXPECT_EQ(rig->triangleCount(), e.triangles) << e.file;
        EXPECT_EQ(rig->boneCount(), e.bones) << e.file;
        EXPECT_EQ(rig->morphCount(), e.morphs) << e.file;
        EXPECT_EQ(rig->clips.size(), e.clips) << e.file;
        const TriangleMesh rest = rig->restMesh();
        ASSERT_EQ(rest.normals.size(), rest.positions.size()) << e.file;
        for (const Vec3f& n : rest.normals) ASSERT_NEAR(n.norm(), 1.f, 1e-4f) << e.file;
        EXPECT_NE(rig->summary().find("triangles: " + std::to_string(e.triangles)), std::string::npos) << e.file;
    }
}

TEST(HeadImport, ClipsHaveNamesDurationsAndRates) {
    HP_REQUIRE_ASSET(fox, "Fox.glb");
    const auto rig = load(fox);
    ASSERT_EQ(rig->clips.size(), 3u);
    EXPECT_EQ(rig->clips[0].name, "Survey");
    EXPECT_NEAR(rig->clips[0].duration, 3.42, 0.01);
    EXPECT_EQ(rig->clips[1].name, "Walk");
    EXPECT_NEAR(rig->clips[1].duration, 0.71, 0.01);
    EXPECT_NEAR(rig->clips[1].keyRate, 24.0, 0.1);
    EXPECT_EQ(findClip(*rig, "Run"), 2);
    EXPECT_EQ(findClip(*rig, "1"), 1);
    EXPECT_EQ(findClip(*rig, ""), 0);
    EXPECT_EQ(findClip(*rig, "none"), -1);
    try {
        findClip(*rig, "Gallop");
        FAIL() << "unknown clip accepted";
    } catch (const RigSelectionError& e) {
        EXPECT_NE(std::string(e.what()).find("no clip 'Gallop'"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("1: Walk"), std::string::npos) << e.what();
    }
    HP_REQUIRE_ASSET(cesium, "CesiumMan.glb");
    const auto man = load(cesium);
    EXPECT_EQ(man->clips[0].name, "");
    EXPECT_NEAR(man->clips[0].duration, 2.0, 1e-3);
}

TEST(HeadImport, UnitScaleAndUpAxisAtTheBoundary) {
    // Fox is ~79 units tall; at 0.01 m per unit a 0.79 m fox, Y up.
    HP_REQUIRE_ASSET(fox, "Fox.glb");
    const Eigen::AlignedBox3f box = load(fox, 0.01)->restMesh().bounds();
    EXPECT_NEAR(box.sizes().y(), 0.79, 0.02);
    // CesiumMan's own Z_UP root node is applied: the man stands along +Y.
    HP_REQUIRE_ASSET(cesium, "CesiumMan.glb");
    const Eigen::AlignedBox3f man = load(cesium)->restMesh().bounds();
    EXPECT_GT(man.sizes().y(), 1.2f * std::max(man.sizes().x(), man.sizes().z()));
    EXPECT_NEAR(man.min().y(), 0.f, 0.05f) << "feet on the ground";
    // up_axis z turns (x, y, z) into (x, z, -y).
    HP_REQUIRE_ASSET(lee, "LeePerrySmith.glb");
    HeadImportSettings s;
    s.file = lee;
    const TriangleMesh yUp = importHead(s).restMesh();
    s.upAxis = UpAxis::Z;
    s.unitScale = 2.0;
    s.placement = Affine3f(Eigen::Translation3f(1, 2, 3));
    const TriangleMesh zUp = importHead(s).restMesh();
    for (size_t i = 0; i < yUp.positions.size(); i += 97) {
        const Vec3f& p = yUp.positions[i];
        EXPECT_LT((zUp.positions[i] - (Vec3f(2 * p.x(), 2 * p.z(), -2 * p.y()) + Vec3f(1, 2, 3))).norm(), 1e-5f);
    }
}

TEST(HeadImport, MeshSelectionByNameNodeIndexAndPrimitiveSplit) {
    HP_REQUIRE_ASSET(robot, "RobotExpressive.glb");
    const auto head = load(robot, 1.0, {"Head"});
    ASSERT_EQ(head->meshes.size(), 3u) << "'Head' is split into Head-0, Head-1, Head-2";
    EXPECT_EQ(head->triangleCount(), 154u + 460u + 196u);
    EXPECT_EQ(load(robot, 1.0, {"Head-2"})->meshes.size(), 1u);
    EXPECT_EQ(load(robot, 1.0, {"0", "Torso-1"})->meshes.size(), 2u);
    try {
        load(robot, 1.0, {"Tail"});
        FAIL() << "unknown mesh accepted";
    } catch (const RigSelectionError& e) {
        EXPECT_NE(std::string(e.what()).find("no mesh 'Tail'"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("Head-1"), std::string::npos) << "lists what the file has";
    }
}

TEST(HeadImport, BrokenFilesNameTheFileAndTheProblem) {
    HP_REQUIRE_ASSET(fox, "Fox.glb");
    TempDir dir;
    const std::string bytes = readFile(fox);
    writeFile(dir / "truncated.glb", bytes.substr(0, bytes.size() / 2));
    std::string e = errorOf([&] { load(dir / "truncated.glb"); });
    EXPECT_NE(e.find((dir / "truncated.glb").string()), std::string::npos) << e;
    EXPECT_NE(e.find("cannot read"), std::string::npos) << e;

    writeFile(dir / "notes.glb", "these are not the meshes you are looking for\n");
    e = errorOf([&] { load(dir / "notes.glb"); });
    EXPECT_NE(e.find("notes.glb"), std::string::npos) << e;

    Image img(4, 4, {"R", "G", "B", "A"});
    writeImage((dir / "picture.png").string(), img);
    e = errorOf([&] { load(dir / "picture.png"); });
    EXPECT_NE(e.find("picture.png"), std::string::npos) << e;

    // A valid glTF scene that holds no mesh at all (just a node).
    writeFile(dir / "empty.gltf", R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"name": "n"}]})");
    e = errorOf([&] { load(dir / "empty.gltf"); });
    EXPECT_NE(e.find("empty.gltf"), std::string::npos) << e;
    EXPECT_NE(e.find("no triangle mesh"), std::string::npos) << e;

    e = errorOf([&] { load(dir / "missing.glb"); });
    EXPECT_NE(e.find("missing.glb: head file not found"), std::string::npos) << e;
}

TEST(HeadAnimation, SkinnedSurfaceFollowsTheClipAndRepeatsAtEqualTimes) {
    HP_REQUIRE_ASSET(fox, "Fox.glb");
    const auto rig = load(fox, 0.01);
    const AnimatedHead walk = animate(rig, findClip(*rig, "Walk"));
    const HeadPose a = walk.sample(0.1), b = walk.sample(0.4), again = walk.sample(0.1);
    EXPECT_EQ(a.mesh.positions, again.mesh.positions) << "identical at equal times";
    EXPECT_GT(maxDistance(a.mesh.positions, b.mesh.positions), 0.02f) << "legs move between keys";
    EXPECT_FALSE(a.mesh.bounds().isApprox(b.mesh.bounds(), 1e-3f));
    EXPECT_EQ(a.mesh.triangles, rig->restMesh().triangles) << "same topology every time";
    // Held after the clip ends; repeated with loop.
    EXPECT_EQ(walk.sample(5.0).mesh.positions, walk.sample(rig->clips[1].duration).mesh.positions);
    HeadAnimationSettings looping;
    looping.clip = 1;
    looping.loop = true;
    looping.collider = ColliderMethod::None;
    const AnimatedHead loop(rig, looping);
    EXPECT_LT(maxDistance(loop.sample(0.3).mesh.positions, loop.sample(0.3 + rig->clips[1].duration).mesh.positions), 1e-5f);
}

TEST(HeadAnimation, NodeTransformsInterpolateTheKeys) {
    HP_REQUIRE_ASSET(fox, "Fox.glb");
    const auto rig = load(fox);
    const int survey = findClip(*rig, "Survey");
    const RigClip& clip = rig->clips[size_t(survey)];
    // The track with the most translation keys (the hips).
    const NodeTrack* track = &clip.tracks[0];
    for (const NodeTrack& t : clip.tracks)
        if (t.translation.times.size() > track->translation.times.size()) track = &t;
    ASSERT_GE(track->rotation.times.size(), 3u);
    ASSERT_GE(track->translation.times.size(), 3u);
    const int parent = rig->nodes[size_t(track->node)].parent;
    ASSERT_GE(parent, 0);
    auto localAt = [&](double t) {
        const auto world = rig->nodeTransforms(survey, t);
        return Affine3f(world[size_t(parent)].inverse() * world[size_t(track->node)]);
    };
    // At a key: the key's values; halfway: the slerp and lerp of its neighbours.
    const double t0 = track->rotation.times[1], t1 = track->rotation.times[2];
    const Eigen::Quaternionf q0 = track->rotation.values[1], q1 = track->rotation.values[2];
    EXPECT_LT(Eigen::Quaternionf(localAt(t0).rotation()).angularDistance(q0), 1e-4f);
    EXPECT_LT(Eigen::Quaternionf(localAt(0.5 * (t0 + t1)).rotation()).angularDistance(q0.slerp(0.5f, q1)), 1e-4f);
    ASSERT_EQ(track->translation.times[1], t0);
    const Vec3f p0 = track->translation.values[1], p1 = track->translation.values[2];
    EXPECT_LT((localAt(0.5 * (t0 + t1)).translation() - 0.5f * (p0 + p1)).norm(), 1e-3f);
    // Bones move when keys move: the hips' world position at two times.
    const auto early = rig->nodeTransforms(survey, 0.2), late = rig->nodeTransforms(survey, 1.5);
    EXPECT_GT((early[size_t(track->node)].translation() - late[size_t(track->node)].translation()).norm(), 0.1f);
    EXPECT_TRUE(rig->nodeTransforms(survey, 0.7)[size_t(track->node)].isApprox(
        rig->nodeTransforms(survey, 0.7)[size_t(track->node)], 0.f));
}

TEST(HeadAnimation, MorphWeightsChangeTheSurface) {
    HP_REQUIRE_ASSET(cubeFile, "AnimatedMorphCube.glb");
    const auto cube = load(cubeFile);
    const AnimatedHead square = animate(cube, 0);
    const TriangleMesh rest = cube->restMesh();
    EXPECT_LT(maxDistance(square.sample(0.0).mesh.positions, rest.positions), 1e-7f) << "weights 0 at t = 0";
    // At a key time the surface is base + Σ w Δ, moved by the node.
    const MorphTrack& track = cube->clips[0].morphs.at(0);
    const size_t k = track.times.size() / 3;
    const HeadPose p = square.sample(track.times[k]);
    const RigMesh& m = cube->meshes[0];
    const Affine3f node = cube->nodeTransforms(0, track.times[k])[size_t(m.node)];
    float err = 0.f, moved = 0.f;
    for (size_t v = 0; v < m.positions.size(); ++v) {
        Vec3f x = m.positions[v];
        for (size_t t = 0; t < track.weights[k].size(); ++t) x += track.weights[k][t] * m.morphPositions[t][v];
        err = std::max(err, ((node * x) - p.mesh.positions[v]).norm());
        moved = std::max(moved, (p.mesh.positions[v] - rest.positions[v]).norm());
    }
    EXPECT_LT(err, 1e-6f);
    EXPECT_GT(moved, 1e-3f) << "the cube (±0.01) visibly changes";

    // RobotExpressive's clips keep the head morphs at 0; driving 'Surprised'
    // through the mesh weights moves the face.
    HP_REQUIRE_ASSET(robot, "RobotExpressive.glb");
    HeadRig face = *load(robot, 1.0, {"Head"});
    const TriangleMesh before = face.restMesh();
    for (RigMesh& mesh : face.meshes) {
        const auto it = std::find(mesh.morphNames.begin(), mesh.morphNames.end(), "Surprised");
        ASSERT_NE(it, mesh.morphNames.end());
        mesh.morphDefaults[size_t(it - mesh.morphNames.begin())] = 1.f;
    }
    EXPECT_GT(maxDistance(face.restMesh().positions, before.positions), 1e-3f);
}

TEST(HeadAnimation, RigidTransformIsExactForNodeAnimation) {
    // RobotExpressive's Head mesh is rigid, parented to the head bone.
    HP_REQUIRE_ASSET(robot, "RobotExpressive.glb");
    const auto rig = load(robot, 1.0, {"Head"});
    const AnimatedHead yes = animate(rig, findClip(*rig, "Yes"));
    const float scale = yes.rest().bounds().diagonal().norm();
    bool moved = false;
    for (double t : {0.3, 0.7, 1.2}) {
        const HeadPose p = yes.sample(t);
        std::vector<Vec3f> mapped;
        for (const Vec3f& x : yes.rest().positions) mapped.push_back(p.transform * x);
        EXPECT_LT(maxDistance(mapped, p.mesh.positions), 1e-5f * scale) << t;
        moved |= !p.transform.isApprox(Eigen::Isometry3f::Identity(), 1e-3f);
    }
    EXPECT_TRUE(moved) << "the head nods in 'Yes'";
}

TEST(HeadAnimation, RootsRideTheDeformedSurfaceWithTheirFrame) {
    // The default head: scalp vertices follow only the head bone, so the
    // root frames must turn with the pose's rigid transform.
    const auto rig = std::make_shared<const HeadRig>(makeDefaultHead());
    AnimatedHead head = animate(rig, 0);
    const std::vector<uint8_t> scalp = rigidScalp(*rig, head.rest());
    head.setFitTriangles(scalp);
    RootSettings rs;
    rs.count = 500;
    const std::vector<SurfacePoint> roots = placeRoots(head.rest(), scalp, rs);
    const float scale = head.rest().bounds().diagonal().norm();
    for (double t = 0.0; t <= kDefaultHeadClipSeconds; t += 0.25) {
        const HeadPose p = head.sample(t);
        const MeshQuery surface(p.mesh);
        float worstAngle = 0.f;
        for (const SurfacePoint& r : roots) {
            const SurfaceFrame now = evaluate(p.mesh, r), then = evaluate(head.rest(), r);
            ASSERT_LT(surface.closest(now.position).distance, 1e-5f * scale) << "t = " << t;
            EXPECT_LT((now.position - p.transform * then.position).norm(), 1e-4f);
            worstAngle = std::max(worstAngle, std::acos(std::min(1.f, now.normal.dot(p.transform.linear() * then.normal))));
            worstAngle = std::max(worstAngle, std::acos(std::min(1.f, now.tangent.dot(p.transform.linear() * then.tangent))));
        }
        EXPECT_LT(worstAngle, 1e-2f) << "frames turn with the head at t = " << t;
    }
}

TEST(HeadAnimation, RootsStayOnSkinnedAssetsAtEveryFrame) {
    HP_REQUIRE_ASSET(cesium, "CesiumMan.glb");
    const auto rig = load(cesium);
    const AnimatedHead walk = animate(rig, 0);
    RootSettings rs;
    rs.count = 300;
    rs.method = RootMethod::BlueNoise;
    const std::vector<SurfacePoint> roots = placeRoots(walk.rest(), {}, rs);
    const float scale = walk.rest().bounds().diagonal().norm();
    for (int frame = 0; frame <= 48; frame += 4) {
        const HeadPose p = walk.sample(frame / 24.0);
        const MeshQuery surface(p.mesh);
        for (const SurfacePoint& r : roots)
            ASSERT_LT(surface.closest(evaluate(p.mesh, r).position).distance, 1e-5f * scale) << frame;
    }
}

TEST(HeadAnimation, SamplingDoesNotDependOnTheThreadCount) {
    HeadRig big = makeDefaultHead({64, 96, 30});
    const auto rig = std::make_shared<const HeadRig>(std::move(big));
    const AnimatedHead head = animate(rig, 0);
    HeadPose one, two;
    tbb::task_arena(1).execute([&] { one = head.sample(1.7); });
    tbb::task_arena(2).execute([&] { two = head.sample(1.7); });
    EXPECT_EQ(one.mesh.positions, two.mesh.positions);
    EXPECT_EQ(one.mesh.normals, two.mesh.normals);
    EXPECT_TRUE(one.transform.isApprox(two.transform, 0.f));
}

TEST(HeadAnimation, ColliderMatchesTheDeformedHead) {
    const auto rig = std::make_shared<const HeadRig>(makeDefaultHead());
    for (ColliderMethod method : {ColliderMethod::Rigid, ColliderMethod::Exact}) {
        HeadAnimationSettings a;
        a.clip = 0;
        a.collider = method;
        a.levelSet.exteriorBand = a.levelSet.interiorBand = 0.006f;  // 2 mm voxels, the default
        AnimatedHead head(rig, a);
        head.setFitTriangles(rigidScalp(*rig, head.rest()));  // as loadHead does with the scalp
        const HeadPose p = head.sample(2.0);                  // mid-shake
        ASSERT_TRUE(p.collider);
        const MeshCollider exact(p.mesh);
        Vec3f n;
        EXPECT_LT(p.collider->signedDistance(p.transform * Vec3f(0, 0.02f, -0.01f), &n), -0.05f) << "skull centre is inside";
        // Points a few millimetres off the skull (which moves rigidly with
        // the head bone), inside and out, along the normals.
        float scalpError = 0.f, worst = 0.f;
        const TriangleMesh& m = p.mesh;
        const size_t scalpVertices = rig->meshes[0].positions.size();
        for (size_t v = 0; v < m.positions.size(); v += 3) {
            if (head.rest().positions[v].y() < 0.0f) continue;
            for (float off : {-0.004f, -0.001f, 0.002f, 0.0035f, 0.012f}) {
                const Vec3f q = m.positions[v] + off * m.normals[v];
                const float d = p.collider->signedDistance(q, &n), e = exact.signedDistance(q);
                ASSERT_EQ(d < 0.f, e < 0.f) << "sign at offset " << off << ", method " << int(method);
                if (e > 0.004f) {
                    // Beyond the band (6 mm less a voxel) the grid gives a lower bound.
                    ASSERT_LE(d, e + 1e-4f) << "offset " << off << ", method " << int(method);
                    continue;
                }
                worst = std::max(worst, std::abs(d - e));
                if (v < scalpVertices) scalpError = std::max(scalpError, std::abs(d - e));
            }
        }
        EXPECT_LT(scalpError, 0.5e-3f) << int(method) << ": on the smooth scalp";
        EXPECT_LT(worst, 2e-3f) << int(method) << ": anywhere on the skull (ear creases: up to a voxel)";
    }
}

namespace {

// A head of two closed shells on two nodes (sim/collision/mesh_parts.h): A,
// a sphere (centre (0, 0.1, 0), radius 0.05 m) that its node turns 90°
// about Z through the origin over the clip "move" (1 s), and B (centre
// (0, -0.1, 0), radius 0.05 m), which stays, or with `growB` grows by 20%
// about the origin (a part that does not move rigidly).
std::shared_ptr<const HeadRig> twoPartRig(bool growB) {
    auto rig = std::make_shared<HeadRig>();
    rig->file = "two parts";
    rig->nodes = {{"Root", -1, Affine3f::Identity()}, {"A", 0, Affine3f::Identity()}, {"B", 0, Affine3f::Identity()}};
    rig->materials = {"scalp"};
    for (int part : {0, 1}) {
        const TriangleMesh s = makeSphereMesh(Vec3f(0.f, part == 0 ? 0.1f : -0.1f, 0.f), 0.05f, 32, 64);
        RigMesh m;
        m.name = part == 0 ? "a" : "b";
        m.instance = part;
        m.node = 1 + part;
        m.positions = s.positions;
        m.normals = s.normals;
        m.triangles = s.triangles;
        rig->meshes.push_back(std::move(m));
    }
    RigClip move;
    move.name = "move";
    move.duration = 1.0;
    move.keyRate = 1.0;
    NodeTrack a;
    a.node = 1;
    a.rotation.times = {0.0, 1.0};
    a.rotation.values = {Eigen::Quaternionf::Identity(), Eigen::Quaternionf(Eigen::AngleAxisf(1.57079633f, Vec3f::UnitZ()))};
    move.tracks.push_back(a);
    if (growB) {
        NodeTrack b;
        b.node = 2;
        b.scale.times = {0.0, 1.0};
        b.scale.values = {Vec3f::Ones(), Vec3f::Constant(1.2f)};
        move.tracks.push_back(b);
    }
    rig->clips.push_back(move);
    return rig;
}

/// The largest error of part k's collider of `p` (a PartsCollider) against
/// the analytic sphere distance |q - centre| - radius, at q on and 3 mm off
/// the sphere along the rays through the part's posed vertices.
float worstPartError(const AnimatedHead& head, const HeadPose& p, size_t k, const Vec3f& centre, float radius) {
    const auto* parts = dynamic_cast<const PartsCollider*>(p.collider.get());
    if (!parts) return 1e9f;
    float worst = 0.f;
    for (uint32_t v : head.partition().vertices[k]) {
        const Vec3f x = p.mesh.positions[v];
        EXPECT_NEAR((x - centre).norm(), radius, 1e-5f) << "the posed part is where its node put it";
        for (float off : {-0.003f, 0.f, 0.003f}) {
            const Vec3f q = centre + (x - centre) * ((radius + off) / (x - centre).norm());
            worst = std::max(worst, std::abs(parts->part(k).signedDistance(q) - off));
        }
    }
    return worst;
}

}  // namespace

// The `rigid` collider carries each part's grid by that part's own motion:
// both posed surfaces read distance ~0 from their own part, and points off
// them the analytic |p - c| - r, within the grid's trilinear error (2 mm
// voxels) and the tessellation's sagitta (0.24 mm). (Carried by the head's
// one rigid fit of all vertices, each grid sits between the two motions:
// 29 mm off.)
TEST(HeadAnimation, EachPartsRigidColliderFollowsItsOwnMotion) {
    const AnimatedHead head = animate(twoPartRig(false), 0, ColliderMethod::Rigid);
    ASSERT_EQ(head.partition().count(), 2u);
    const HeadPose p = head.sample(1.0);
    EXPECT_LT(worstPartError(head, p, 0, Vec3f(-0.1f, 0.f, 0.f), 0.05f), 0.5e-3f) << "the turned part A";
    EXPECT_LT(worstPartError(head, p, 1, Vec3f(0.f, -0.1f, 0.f), 0.05f), 0.5e-3f) << "the still part B";
}

// A part that no rigid motion carries within half a voxel (B grown by 20%,
// as a skinned neck bent over its blend) gets a grid of its posed mesh
// under `rigid`; the part that moves rigidly keeps its rest grid. (Any
// rigid carry of B's rest grid is 10 mm off its posed surface.)
TEST(HeadAnimation, RigidColliderRebuildsOnlyThePartsThatDeform) {
    const AnimatedHead head = animate(twoPartRig(true), 0, ColliderMethod::Rigid);
    const HeadPose p = head.sample(1.0);
    EXPECT_LT(worstPartError(head, p, 0, Vec3f(-0.1f, 0.f, 0.f), 0.05f), 0.5e-3f) << "the turned part A";
    EXPECT_LT(worstPartError(head, p, 1, Vec3f(0.f, -0.12f, 0.f), 0.06f), 0.5e-3f) << "the grown part B";
}
