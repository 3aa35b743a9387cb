// The head as a scene sets it up (pipeline/head/head_setup.h, pipeline/head/scalp.h,
// pipeline/stages/head_source.h): scalp selection, groom roots, scene errors, the
// frame source, `hairpipe info`, and the committed default head asset.
#include "pipeline/head/default_head.h"
#include "pipeline/head/fold_head.h"
#include "pipeline/head/head_setup.h"
#include "pipeline/stages/head_source.h"
#include "render/image/image_io.h"
#include "sim/collision/mesh_collider.h"
#include "sim/collision/mesh_parts.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <functional>
#include <map>

using namespace hp;
using namespace hp::test;

namespace {

const std::string kHead = "head:\n  file: " + sourcePath("scenes/assets/head.glb").string() + "\n";

Scene scene(const std::string& yaml, const std::vector<std::string>& overrides = {}) {
    return Scene::parse(yaml, "test.yaml", std::filesystem::temp_directory_path(), overrides);
}

size_t count(const std::vector<uint8_t>& mask) { return size_t(std::count(mask.begin(), mask.end(), uint8_t(1))); }

/// The SceneError a call throws, or "".
std::string sceneError(const std::function<void()>& f) {
    try {
        f();
    } catch (const SceneError& e) {
        return e.what();
    }
    return "";
}

/// Whether tools/make_head, run with `flags`, writes exactly the bytes of the
/// committed scenes/assets/`name` (make_head is deterministic).
::testing::AssertionResult committedAssetIsToolOutput(const std::string& name, const std::string& flags) {
    TempDir dir;
    const std::string command =
        std::string("'") + HAIRPIPE_MAKE_HEAD + "' '" + (dir / name).string() + "'" + flags + " > /dev/null";
    if (std::system(command.c_str()) != 0) return ::testing::AssertionFailure() << command << " failed";
    if (readFile(dir / name) != readFile(sourcePath("scenes/assets/" + name)))
        return ::testing::AssertionFailure() << "scenes/assets/" << name << " is stale: regenerate it with "
                                             << "'tools/make_head scenes/assets/" << name << flags << "'";
    return ::testing::AssertionSuccess();
}

}  // namespace

TEST(DefaultHead, CommittedAssetIsWhatTheToolWrites) {
    // The bytes: make_head is deterministic, so the committed file must be
    // exactly its output (regenerate with `build/tools/make_head scenes/assets/head.glb`).
    EXPECT_TRUE(committedAssetIsToolOutput("head.glb", ""));

    // The content, through assimp: the rig of pipeline/default_head.
    HeadImportSettings s;
    s.file = sourcePath("scenes/assets/head.glb");
    const HeadRig loaded = importHead(s);
    const HeadRig made = makeDefaultHead();
    ASSERT_EQ(loaded.meshes.size(), 2u);
    EXPECT_EQ(loaded.materials[loaded.meshes[0].material], "scalp");
    EXPECT_EQ(loaded.materials[loaded.meshes[1].material], "skin");
    EXPECT_EQ(loaded.boneCount(), 2u);
    ASSERT_EQ(loaded.clips.size(), 2u);
    EXPECT_EQ(loaded.clips[0].name, "nod_shake_turn");
    EXPECT_NEAR(loaded.clips[0].duration, kDefaultHeadClipSeconds, 1e-6);
    EXPECT_EQ(loaded.clips[1].name, "stress");
    EXPECT_NEAR(loaded.clips[1].duration, kStressClipSeconds, 1e-6);
    const TriangleMesh a = loaded.restMesh(), b = made.restMesh();
    ASSERT_EQ(a.triangles, b.triangles);
    for (double t : {0.5, 1.6, 2.7, 3.4}) {
        TriangleMesh pa = a, pb = b;
        loaded.pose(0, t, pa);
        made.pose(0, t, pb);
        for (size_t v = 0; v < pa.positions.size(); ++v)
            ASSERT_LT((pa.positions[v] - pb.positions[v]).norm(), 1e-5f) << "t = " << t << " vertex " << v;
    }
}

TEST(DefaultHead, CommittedBodyIsWhatTheToolWrites) {
    // scenes/assets/body.glb: `make_head OUT --body`, the shoulders the default scene's hair rests on.
    EXPECT_TRUE(committedAssetIsToolOutput("body.glb", " --body"));
    HeadImportSettings s;
    s.file = sourcePath("scenes/assets/body.glb");
    const HeadRig loaded = importHead(s);
    ASSERT_EQ(loaded.meshes.size(), 1u);
    EXPECT_EQ(loaded.meshes[0].name, "shoulders");
    ASSERT_EQ(loaded.clips.size(), 2u);
    EXPECT_EQ(loaded.clips[0].name, "nod_shake_turn") << "the head's clips, so the body plays the head's clip";
}

TEST(FoldHead, CommittedAssetIsWhatTheToolWritesAndFoldsIntoItself) {
    // scenes/assets/fold.glb: `make_head OUT --fold`, the head of scenes/fold_*.yaml.
    EXPECT_TRUE(committedAssetIsToolOutput("fold.glb", " --fold"));
    HeadImportSettings s;
    s.file = sourcePath("scenes/assets/fold.glb");
    const HeadRig loaded = importHead(s);
    ASSERT_EQ(loaded.meshes.size(), 1u) << "one skinned mesh";
    EXPECT_EQ(loaded.boneCount(), 2u);
    ASSERT_EQ(loaded.clips.size(), 2u);
    EXPECT_EQ(loaded.clips[0].name, "fold_tip");
    EXPECT_EQ(loaded.clips[1].name, "fold_jump");
    // Two shells: the sphere (every vertex at 0.1 m from the origin) and the
    // neck cylinder (at 0.045 m from the Y axis, or on a cap), whose top cap
    // lies 4 cm inside the sphere.
    const TriangleMesh rest = loaded.restMesh();
    const MeshPartition parts = partitionMesh(rest, weldVertices(rest.positions));
    ASSERT_EQ(parts.count(), 2u);
    for (const Vec3f& p : parts.part(rest, 0).positions) ASSERT_NEAR(p.norm(), kFoldHeadRadius, 1e-6f);
    float top = -1.f, bottom = 1.f;
    for (const Vec3f& p : parts.part(rest, 1).positions) {
        const float radial = Vec2f(p.x(), p.z()).norm();
        const bool onCap = std::abs(p.y() - kFoldNeckTop) < 1e-6f ||
                           std::abs(p.y() - (kFoldNeckTop - kFoldNeckLength)) < 1e-6f;
        ASSERT_TRUE(std::abs(radial - kFoldNeckRadius) < 1e-6f || onCap) << p.transpose();
        top = std::max(top, p.y()), bottom = std::min(bottom, p.y());
    }
    EXPECT_NEAR(top, -kFoldHeadRadius + 0.04f, 1e-6f);
    EXPECT_NEAR(top - bottom, kFoldNeckLength, 1e-6f);
    // fold_jump: the rig moves 0.5 m between two keys 1/30 s apart.
    TriangleMesh before = rest, after = rest;
    loaded.pose(1, kFoldJumpStart, before);
    loaded.pose(1, kFoldJumpStart + 1.0 / 30.0, after);
    EXPECT_NEAR((after.positions[0] - before.positions[0]).x(), kFoldJumpDistance, 1e-5f);
}

// Adult proportions (stature ~1.75 m): the shoulder tips (acromion) lie
// about 0.3 m under the top of the head, the neck-shoulder point ~0.25 m; the
// shoulders are ~0.4 m wide. The body stays still while the head moves,
// except beside the neck, which follows the neck bone.
TEST(DefaultHead, ShouldersHaveAdultProportionsAndFollowTheNeck) {
    const HeadRig head = makeDefaultHead(), body = makeDefaultBody();
    const float top = head.restMesh().bounds().max().y();
    const TriangleMesh rest = body.restMesh();
    float tip = -1.f, neck = -1.f, width = 0.f;
    for (const Vec3f& p : rest.positions) {
        if (std::abs(std::abs(p.x()) - 0.17f) < 0.01f && std::abs(p.z() + 0.03f) < 0.02f) tip = std::max(tip, p.y());
        if (std::abs(std::abs(p.x()) - 0.07f) < 0.01f && std::abs(p.z() + 0.03f) < 0.02f) neck = std::max(neck, p.y());
        width = std::max(width, 2.f * std::abs(p.x()));
    }
    EXPECT_NEAR(top - tip, 0.30f, 0.03f) << "skull top to shoulder tip";
    EXPECT_NEAR(top - neck, 0.25f, 0.03f) << "skull top to the shoulder beside the neck";
    EXPECT_NEAR(width, 0.42f, 0.04f) << "shoulder width";
    // The hair that hangs from the back of the head lands on the upper back:
    // 22 cm below the lowest roots of the default scene's cap (~3 cm under
    // the skull centre, at the back, 9-11 cm behind the neck's axis) is
    // below the back's surface there.
    float back = -1.f;
    for (const Vec3f& p : rest.positions)
        if (std::abs(p.x()) < 0.02f && p.z() < -0.09f && p.z() > -0.11f) back = std::max(back, p.y());
    EXPECT_LT(-0.03f - 0.22f, back) << "the upper back is within reach of 22 cm nape hair";
    TriangleMesh still = rest, tipped = rest;
    body.pose(1, 0.0, still);
    body.pose(1, 0.5, tipped);  // the stress clip: tipped back 70°
    float far = 0.f, near = 0.f;
    for (size_t v = 0; v < rest.positions.size(); ++v) {
        const float moved = (tipped.positions[v] - still.positions[v]).norm();
        const float radial = Vec2f(rest.positions[v].x(), rest.positions[v].z() + 0.018f).norm();
        (radial > 0.1f ? far : near) = std::max(radial > 0.1f ? far : near, moved);
    }
    EXPECT_LT(far, 1e-6f) << "shoulders away from the neck stay still";
    EXPECT_GT(near, 0.005f) << "skin beside the neck follows the neck as it tips";
}

TEST(DefaultHead, ProportionsAndAClipThatEndsStill) {
    const HeadRig rig = makeDefaultHead();
    const Eigen::AlignedBox3f box = rig.restMesh().bounds();
    EXPECT_NEAR(box.sizes().x(), 0.17, 0.02) << "head width with ears";
    EXPECT_NEAR(box.max().y(), 0.107, 0.005) << "skull top ~0.1 m above the centre";
    EXPECT_GT(box.sizes().y(), 0.3f) << "head and neck";
    // Closed: every edge is shared by exactly two triangles once the seam
    // and pole copies are welded.
    const TriangleMesh m = rig.restMesh();
    const std::vector<uint32_t> weld = weldVertices(m.positions);
    std::map<std::pair<uint32_t, uint32_t>, int> edges;
    for (const Tri& t : m.triangles)
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = weld[t[k]], b = weld[t[(k + 1) % 3]];
            ++edges[{std::min(a, b), std::max(a, b)}];
        }
    size_t open = 0;
    for (const auto& [e, n] : edges) open += n != 2;
    EXPECT_EQ(open, 0u) << "a closed surface (the collider's inside sign needs one)";
    // Moving fast in the turn, not at all after it: the settling phase.
    TriangleMesh p0 = m, p1 = m, p2 = m, p3 = m;
    rig.pose(0, 2.65, p0);
    rig.pose(0, 2.70, p1);
    rig.pose(0, 3.0, p2);
    rig.pose(0, 3.5, p3);
    float fast = 0.f, still = 0.f;
    for (size_t v = 0; v < m.positions.size(); ++v) {
        fast = std::max(fast, (p1.positions[v] - p0.positions[v]).norm() / 0.05f);
        still = std::max(still, (p3.positions[v] - p2.positions[v]).norm());
    }
    EXPECT_GT(fast, 0.4f) << "m/s at the skull during the fast turn";
    EXPECT_LT(still, 1e-6f);
}

TEST(Scalp, SelectionModesOnTheDefaultHead) {
    const HeadRig rig = makeDefaultHead();
    const TriangleMesh rest = rig.restMesh();
    const size_t scalpTris = rig.meshes[0].triangles.size();
    ScalpSettings s;
    s.method = ScalpMethod::All;
    EXPECT_EQ(count(selectScalp(rig, rest, s)), rest.triangleCount());

    s.method = ScalpMethod::Material;
    s.materials = {"scalp"};
    const std::vector<uint8_t> byMaterial = selectScalp(rig, rest, s);
    EXPECT_EQ(count(byMaterial), scalpTris);
    for (size_t t = 0; t < scalpTris; ++t) ASSERT_TRUE(byMaterial[t]);
    s.materials = {"fur"};
    EXPECT_THROW(selectScalp(rig, rest, s), Error);

    // Vertex colour R carries the same hair mask, smoothed: nearly the same triangles.
    s.method = ScalpMethod::VertexColor;
    s.channel = 0;
    s.threshold = 0.5f;
    const std::vector<uint8_t> byColor = selectScalp(rig, rest, s);
    size_t both = 0, either = 0;
    for (size_t t = 0; t < rest.triangleCount(); ++t) both += byColor[t] && byMaterial[t], either += byColor[t] || byMaterial[t];
    EXPECT_GT(double(both) / double(either), 0.9) << "intersection over union";

    // A texture mask through the uvs: white in the image's top half = v > 0.5
    // = the upper half of the head's spherical uv map.
    TempDir dir;
    Image mask(64, 64, {"R", "G", "B"});
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 64; ++x)
            for (int c = 0; c < 3; ++c) mask.at(x, y, c) = 1.f;
    writeImage((dir / "mask.png").string(), mask);
    s.method = ScalpMethod::Texture;
    s.mask = dir / "mask.png";
    const std::vector<uint8_t> byTexture = selectScalp(rig, rest, s);
    for (size_t t = 0; t < rest.triangleCount(); ++t) {
        float lo = 1.f, hi = 0.f;
        for (uint32_t v : rest.triangles[t]) lo = std::min(lo, rest.uvs[v].y()), hi = std::max(hi, rest.uvs[v].y());
        if (lo > 0.53f) {
            EXPECT_TRUE(byTexture[t]) << t;
        }
        if (hi < 0.47f) {
            EXPECT_FALSE(byTexture[t]) << t;
        }
    }
    s.mask = dir / "missing.png";
    EXPECT_THROW(selectScalp(rig, rest, s), AssetError);

    // A region: Gomes 2024's partial sphere, here the upper hemisphere about the skull centre.
    s.method = ScalpMethod::Region;
    s.center = Vec3f(0, 0.015f, -0.01f);
    s.axis = Vec3f::UnitY();
    s.angleDegrees = 90;
    const std::vector<uint8_t> byRegion = selectScalp(rig, rest, s);
    for (size_t t = 0; t < rest.triangleCount(); ++t) {
        const Tri& tri = rest.triangles[t];
        const float y = (rest.positions[tri[0]].y() + rest.positions[tri[1]].y() + rest.positions[tri[2]].y()) / 3.f;
        ASSERT_EQ(byRegion[t] != 0, y >= 0.015f) << t;
    }
    s.center = Vec3f(0, 1, 0);
    s.angleDegrees = 10;
    try {
        selectScalp(rig, rest, s);
        FAIL() << "an empty scalp was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("selects no triangle"), std::string::npos) << e.what();
    }
}

TEST(HeadSetup, SceneErrorsNameTheKey) {
    EXPECT_NE(sceneError([&] { loadHead(scene(kHead + "  meshes: Tail\n")); }).find("'head.meshes': no mesh 'Tail'"),
              std::string::npos);
    EXPECT_NE(sceneError([&] { loadHead(scene(kHead + "  clip: Dance\n")); }).find("'head.clip': no clip 'Dance'"),
              std::string::npos);
    const std::string empty = sceneError([&] {
        loadHead(scene(kHead + "  scalp:\n    method: region\n    center: [0, 1, 0]\n    angle: 5\n"));
    });
    EXPECT_NE(empty.find("'head.scalp.method'"), std::string::npos) << empty;
    EXPECT_NE(empty.find("selects no triangle"), std::string::npos) << empty;
    EXPECT_NE(sceneError([&] { loadHead(scene(kHead + "  scalp:\n    method: material\n")); })
                  .find("'head.scalp.materials'"),
              std::string::npos);
    EXPECT_NE(sceneError([&] { loadHead(scene(kHead + "  collider:\n    voxel_size: 0.01\n")); })
                  .find("'head.collider.exterior_band': must be at least"),
              std::string::npos);
}

TEST(HeadSetup, DefaultSceneGroomIsOnTheScalpAndDeterministic) {
    const Scene s = Scene::load(sourcePath("scenes/default.yaml"),
                                {"hair.guides.count=200", "hair.followers.count=3000"});
    const HeadSetup head = loadHead(s);
    EXPECT_EQ(head.rest.triangleCount(), head.scalp.size());
    EXPECT_GT(count(head.scalp), 500u);
    for (const char* method : {"fibonacci", "blue-noise"}) {
        const Scene m = Scene::load(sourcePath("scenes/default.yaml"), {"hair.guides.count=200", "hair.followers.count=3000",
                                                                      std::string("hair.roots.method=") + method});
        GroomRoots one, two;
        tbb::task_arena(1).execute([&] { one = placeGroomRoots(m, head); });
        tbb::task_arena(2).execute([&] { two = placeGroomRoots(m, head); });
        ASSERT_EQ(one.guides.size(), 200u) << method;
        ASSERT_EQ(one.followers.size(), 3000u) << method;
        for (const SurfacePoint& r : one.followers) ASSERT_TRUE(head.scalp[r.triangle]) << method;
        for (size_t i = 0; i < one.followers.size(); ++i) {
            ASSERT_EQ(one.followers[i].triangle, two.followers[i].triangle) << method;
            ASSERT_EQ(one.followers[i].b1, two.followers[i].b1) << method;
        }
        // Independent placements: the guides are not a subset of the followers' points.
        size_t shared = 0;
        for (const SurfacePoint& g : one.guides)
            for (const SurfacePoint& f : one.followers)
                shared += g.triangle == f.triangle && g.b1 == f.b1 && g.b2 == f.b2;
        EXPECT_LT(shared, 5u) << method;
    }
}

TEST(HeadSource, YieldsThePoseOfEachFrame) {
    const Scene s = Scene::load(sourcePath("scenes/default.yaml"));
    const HeadSetup head = loadHead(s);
    auto source = makeHeadFrameSource(head.motion, 24.0);
    const FrameData d = source->get(30);
    ASSERT_NE(d.head, nullptr);
    EXPECT_DOUBLE_EQ(d.time, 30 / 24.0);
    EXPECT_DOUBLE_EQ(d.head->time, d.time);
    EXPECT_EQ(d.head->mesh.positions, head.motion->sample(30 / 24.0).mesh.positions);
    ASSERT_TRUE(d.head->collider);
    // The skull centre, carried by the head's rigid motion, is inside.
    EXPECT_LT(d.head->collider->signedDistance(d.head->transform * Vec3f(0, 0.015f, -0.01f)), -0.05f);
}

TEST(HeadInfo, InfoListsMeshesClipsBonesAndMorphs) {
    TempDir dir;
    HP_REQUIRE_ASSET(robot, "RobotExpressive.glb");
    writeFile(dir / "robot.yaml", "head:\n  file: " + robot.string() + "\n  meshes: Head\n");
    const ProcessResult r = runHairpipe("info robot.yaml", dir.path());
    EXPECT_EQ(r.exitCode, 0) << r.output;
    for (const char* text : {"    3: Head-0, 154 triangles, material Grey, 3 morph targets", "morphs:    9 targets on 3 meshes", "clips:     14",
                             "Yes, 1.67 s, 24.00 fps"})
        EXPECT_NE(r.output.find(text), std::string::npos) << text << "\n" << r.output;
    const ProcessResult bad = runHairpipe("info robot.yaml --set head.meshes=Tail", dir.path());
    EXPECT_EQ(bad.exitCode, 1);
    EXPECT_NE(bad.output.find("'head.meshes': no mesh 'Tail'"), std::string::npos) << bad.output;
    const ProcessResult validate = runHairpipe("validate robot.yaml --set head.clip=Tango", dir.path());
    EXPECT_EQ(validate.exitCode, 1);
    EXPECT_NE(validate.output.find("no clip 'Tango'"), std::string::npos) << validate.output;
}
