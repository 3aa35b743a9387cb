// Grooms: the default scalp, units declared by the file, settled procedural
// grooms and the user's own groom imported from OBJ, .hair and .usda.
#include "pipeline/groom/groom_file.h"
#include "pipeline/groom/groom_import.h"
#include "pipeline/head/head_import.h"
#include "pipeline/scene/scene.h"
#include "pipeline/stages/shot_simulation.h"
#include "pipeline/batch/strand_cache.h"
#include "pipeline/stages/usd_export.h"
#include "sim/collision/mesh_query.h"
#include "test_support.h"

#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <assimp/scene.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>

using namespace hp;
using namespace hp::test;
namespace fs = std::filesystem;

namespace {

const std::string kProjectHead = sourcePath("scenes/assets/head.glb").string();

Scene sceneFrom(const std::string& yaml, const fs::path& dir, const std::vector<std::string>& overrides = {}) {
    return Scene::parse(yaml, "test.yaml", dir, overrides);
}

/// A sphere (radius r, centre at the origin, the face toward +Z) on an open
/// neck tube (radius r/2 from y = -2.2 r to y = -0.83 r), as an OBJ in
/// `scale` units per metre, outward-wound. No materials.
void writeSphereNeckObj(const fs::path& path, float r, float scale) {
    std::vector<Vec3f> v;
    std::vector<std::array<int, 3>> f;
    auto quad = [&](int a, int b, int c, int d, const std::function<Vec3f(const Vec3f&)>& outward) {
        for (std::array<int, 3> t : {std::array<int, 3>{a, b, c}, std::array<int, 3>{a, c, d}}) {
            const Vec3f n = (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]);
            const Vec3f mid = (v[t[0]] + v[t[1]] + v[t[2]]) / 3.f;
            if (n.dot(outward(mid)) < 0.f) std::swap(t[1], t[2]);
            f.push_back(t);
        }
    };
    const int rings = 24, sectors = 32;
    for (int i = 0; i <= rings; ++i)
        for (int j = 0; j < sectors; ++j) {
            const float th = float(M_PI) * float(i) / rings, ph = 2.f * float(M_PI) * float(j) / sectors;
            v.emplace_back(r * std::sin(th) * std::cos(ph), r * std::cos(th), r * std::sin(th) * std::sin(ph));
        }
    auto sphereOut = [](const Vec3f& p) { return p; };
    for (int i = 0; i < rings; ++i)
        for (int j = 0; j < sectors; ++j)
            quad(i * sectors + j, (i + 1) * sectors + j, (i + 1) * sectors + (j + 1) % sectors, i * sectors + (j + 1) % sectors,
                 sphereOut);
    const int base = int(v.size());
    for (int i = 0; i <= 6; ++i)
        for (int j = 0; j < sectors; ++j) {
            const float y = -0.83f * r - 1.37f * r * float(i) / 6.f, ph = 2.f * float(M_PI) * float(j) / sectors;
            v.emplace_back(0.5f * r * std::cos(ph), y, 0.5f * r * std::sin(ph));
        }
    auto neckOut = [](const Vec3f& p) { return Vec3f(p.x(), 0.f, p.z()); };
    for (int i = 0; i < 6; ++i)
        for (int j = 0; j < sectors; ++j)
            quad(base + i * sectors + j, base + (i + 1) * sectors + j, base + (i + 1) * sectors + (j + 1) % sectors,
                 base + i * sectors + (j + 1) % sectors, neckOut);
    std::ofstream out(path);
    for (const Vec3f& p : v) out << "v " << p.x() * scale << " " << p.y() * scale << " " << p.z() * scale << "\n";
    for (const auto& t : f) out << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
}

std::vector<Vec3f> rootPositions(const HeadSetup& head, const std::vector<SurfacePoint>& roots) {
    std::vector<Vec3f> p;
    for (const SurfacePoint& r : roots) p.push_back(evaluate(head.rest, r).position);
    return p;
}

}  // namespace

// ---- the default scalp ----------------------------------------------------------

TEST(DefaultScalp, SphereAndNeckGrowsACapOverTopAndBackOnly) {
    TempDir dir;
    const float r = 0.09f;
    writeSphereNeckObj(dir / "head.obj", r, 1.f);
    const Scene s = sceneFrom("head: {file: head.obj, collider: {method: none}}\nhair: {guides: {count: 300}, followers: {count: 3000}}\n",
                              dir.path());
    const HeadSetup head = loadHead(s);
    ASSERT_EQ(head.scalpUsed.method, ScalpMethod::Region);
    // The fitted cranium is the sphere, not pulled down by the neck.
    EXPECT_LT((head.scalpUsed.center - Vec3f::Zero()).norm(), 0.05f * r);
    const GroomRoots roots = placeGroomRoots(s, head);
    size_t back = 0, top = 0;
    for (const auto* set : {&roots.guides, &roots.followers})
        for (const Vec3f& p : rootPositions(head, *set)) {
            // Neck and chin: well below the sphere's equator (the cap reaches 6° below it at the back only).
            ASSERT_GT(p.y(), -0.2f * r) << "a root on the neck or chin at " << p.transpose();
            // Face: the front (within 40° of +Z about the vertical) below the forehead.
            ASSERT_FALSE(p.z() > 0.77f * std::hypot(p.x(), p.z()) && p.y() < 0.6f * r) << "a root on the face at " << p.transpose();
            back += p.z() < -0.7f * r;
            top += p.y() > 0.9f * r;
        }
    EXPECT_GT(back, 100u) << "the back of the head grows hair";
    EXPECT_GT(top, 100u) << "the top of the head grows hair";
    // `all` stays available by name.
    const HeadSetup all = loadHead(sceneFrom("head: {file: head.obj, collider: {method: none}, scalp: {method: all}}\n", dir.path()));
    EXPECT_EQ(size_t(std::count(all.scalp.begin(), all.scalp.end(), 1)), all.rest.triangleCount());
    // stderr says which region was chosen and how to pick another.
    writeFile(dir / "s.yaml", "head: {file: head.obj, collider: {method: none}}\n");
    const ProcessResult v = runHairpipe("validate s.yaml", dir.path());
    EXPECT_EQ(v.exitCode, 0) << v.output;
    EXPECT_NE(v.output.find("a cap over the top and back of the head"), std::string::npos) << v.output;
    EXPECT_NE(v.output.find("head.scalp.method"), std::string::npos) << v.output;
}

TEST(DefaultScalp, ProjectHeadUsesItsScalpMaterialAndNoFaceOrNeck) {
    TempDir dir;
    const Scene s = sceneFrom("head: {file: " + kProjectHead + "}\nhair: {guides: {count: 300}, followers: {count: 3000}}\n",
                              dir.path());
    const HeadSetup head = loadHead(s);
    ASSERT_EQ(head.scalpUsed.method, ScalpMethod::Material);
    ASSERT_EQ(head.scalpUsed.materials, std::vector<std::string>{"scalp"});
    // Face and neck measured from the mesh: the skull (pipeline/head/default_head.cpp)
    // ends 0.077 m below the origin, and the neck goes on below it to the base.
    const Eigen::AlignedBox3f box = head.rest.bounds();
    const float top = box.max().y(), height = box.sizes().y();
    ASSERT_LT(box.min().y(), -0.2f) << "the project head has a neck";
    const GroomRoots roots = placeGroomRoots(s, head);
    for (const auto* set : {&roots.guides, &roots.followers})
        for (const Vec3f& p : rootPositions(head, *set)) {
            ASSERT_GT(p.y(), -0.08f) << "a root on the neck at " << p.transpose();
            ASSERT_FALSE(p.z() > 0.5f * box.max().z() && p.y() < top - 0.2f * height)
                << "a root on the face at " << p.transpose();
        }
}

// ---- units ----------------------------------------------------------------------

TEST(Units, FbxInCentimetresIsReadInMetresAndInfoSaysSo) {
    TempDir dir;
    const float r = 0.09f;
    writeSphereNeckObj(dir / "cm.obj", r, 100.f);  // centimetres, no unit of its own
    // assimp's FBX exporter declares UnitScaleFactor 1: centimetres.
    Assimp::Importer importer;
    const aiScene* obj = importer.ReadFile((dir / "cm.obj").string(), 0);
    ASSERT_NE(obj, nullptr) << importer.GetErrorString();
    Assimp::Exporter exporter;
    ASSERT_EQ(exporter.Export(obj, "fbxa", (dir / "cm.fbx").string()), AI_SUCCESS) << exporter.GetErrorString();
    ASSERT_NE(readFile(dir / "cm.fbx").find("\"UnitScaleFactor\", \"double\", \"Number\", \"\", 1"), std::string::npos)
        << "assimp's FBX exporter no longer writes centimetres";

    HeadImportSettings settings;
    settings.file = dir / "cm.fbx";
    settings.unitScaleGiven = false;
    const HeadRig rig = importHead(settings);
    EXPECT_DOUBLE_EQ(rig.fileUnitScale, 0.01);
    const float height = rig.restMesh().bounds().sizes().y();
    EXPECT_NEAR(height, 2.2f * r + r, 1e-3f) << "sphere top to neck base, metres";
    settings.unitScaleGiven = true;  // the scene's head.unit_scale wins
    settings.unitScale = 0.001;
    EXPECT_NEAR(importHead(settings).restMesh().bounds().sizes().y(), 0.1f * (2.2f * r + r), 1e-4f);

    // The file's up axis: the same data declared Z up turns its Y extent into Z.
    std::string zUp = readFile(dir / "cm.fbx");
    const std::string yAxis = "\"UpAxis\", \"int\", \"Integer\", \"\", 1";
    ASSERT_NE(zUp.find(yAxis), std::string::npos) << "assimp's FBX exporter no longer writes UpAxis 1";
    zUp.replace(zUp.find(yAxis), yAxis.size(), "\"UpAxis\", \"int\", \"Integer\", \"\", 2");
    writeFile(dir / "zup.fbx", zUp);
    settings.file = dir / "zup.fbx";
    settings.unitScaleGiven = false;
    settings.upAxisGiven = false;
    const HeadRig zRig = importHead(settings);
    EXPECT_EQ(zRig.fileUpAxis, 'z');
    EXPECT_NEAR(zRig.restMesh().bounds().sizes().z(), 2.2f * r + r, 1e-3f) << "the file's Y extent, now along Z";

    writeFile(dir / "s.yaml", "head: {file: cm.fbx, collider: {method: none}}\n");
    const ProcessResult info = runHairpipe("info s.yaml", dir.path());
    EXPECT_EQ(info.exitCode, 0) << info.output;
    EXPECT_NE(info.output.find("unit:      0.01 m per file unit (the file declares 0.01 m"), std::string::npos) << info.output;
    EXPECT_NE(info.output.find("up axis:   y (the file declares y"), std::string::npos) << info.output;
    // The same head as an OBJ, which declares no unit: 31 m... no, 0.31 m
    // read as 31 m tall: warned about, naming head.unit_scale.
    writeFile(dir / "o.yaml", "head: {file: cm.obj, collider: {method: none}}\n");
    const ProcessResult warned = runHairpipe("validate o.yaml", dir.path());
    EXPECT_NE(warned.output.find("implausible for a head"), std::string::npos) << warned.output;
    EXPECT_NE(warned.output.find("head.unit_scale"), std::string::npos) << warned.output;
}

// ---- settled grooms -------------------------------------------------------------

namespace {

const std::string kSmallShot = "frames: 1-30\nfps: 24\nhead: {file: " + kProjectHead +
                               "}\nhair: {guides: {count: 24}, followers: {count: 60}}\n";

bool sameBytes(const std::vector<Vec3f>& a, const std::vector<Vec3f>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3f)) == 0;
}

}  // namespace

TEST(Settle, ConvergesLiesOnTheHeadHoldsStillAndIsReusedByteForByte) {
    TempDir dir;
    // The pre-load unbounded (simulation.preload_limit 0), so that the
    // settled groom is an exact equilibrium below; the default bound trades
    // part of that hold for hair that does not stand up when the head moves
    // (docs/physics.md, "Pre-load"; test_shot_simulation measures it).
    const Scene s = sceneFrom(kSmallShot, dir.path(), {"simulation.preload_limit=0"});
    const fs::path cache = dir / "cache" / "settled_groom.bin";
    ShotSimulation first(s, 24.0, 1, {cache, true});
    const SimFrameStats stats = first.stats();
    ASSERT_GE(stats.settleSeconds, 0.0);
    EXPECT_TRUE(stats.settleConverged) << "kinetic energy " << stats.settleEnergy << " J after " << stats.settleSeconds << " s";
    // At rest: RMS speed below hair.groom.settle_speed, E_kin < ½·M·v² with
    // M = guides × N·ρ·πr² × L (the rod's mass, from the scene's keys).
    const double r = s.number("hair.radius.root"),
                 mu = s.number("hair.material.hairs_per_guide") * s.number("hair.material.density") * M_PI * r * r,
                 speed = s.number("hair.groom.settle_speed");
    EXPECT_LT(stats.settleEnergy, 0.5 * 24 * mu * s.number("hair.guides.length") * speed * speed);
    EXPECT_FALSE(stats.settleCached);
    ASSERT_TRUE(fs::is_regular_file(cache));
    const std::string bytes = readFile(cache);
    const StrandFrame f1 = first.advanceTo(1);

    // Lying on the head: straight strands start along the normals; settled,
    // their tips hang lower than their roots and no vertex is inside the head.
    const HeadPose& pose = first.pose();
    size_t below = 0;
    for (size_t g = 0; g < first.guideCount(); ++g) {
        const Vec3f root = f1.positions[f1.first(g)], tip = f1.positions[f1.first(g) + f1.vertexCount(g) - 1];
        below += tip.y() < root.y();
        for (uint32_t v = 0; v < f1.vertexCount(g); ++v)
            EXPECT_GT(pose.collider->signedDistance(f1.positions[f1.first(g) + v]), -1e-3f) << "guide " << g << " vertex " << v;
    }
    EXPECT_GT(below, first.guideCount() * 3 / 4) << "most tips hang below their roots";
    // Followers copy their nearest guide's hanging shape (in world space, not
    // in their own root frame, which would turn it out from the crown).
    size_t followersBelow = 0;
    for (size_t f = first.guideCount(); f < f1.strandCount(); ++f)
        followersBelow += f1.positions[f1.first(f) + f1.vertexCount(f) - 1].y() < f1.positions[f1.first(f)].y() - 0.05f;
    EXPECT_GT(followersBelow, first.followerCount() * 3 / 4) << "most follower tips hang 5 cm below their roots";
    // The settled shape is the rest shape: the head is still over the clip's
    // first frames, and so is the hair (no sag, no bounce).
    const StrandFrame f4 = first.advanceTo(4);
    float moved = 0.f;
    for (size_t i = 0; i < f1.offsets[first.guideCount()]; ++i) moved = std::max(moved, (f4.positions[i] - f1.positions[i]).norm());
    EXPECT_LT(moved, 1e-3f) << "m, guide vertices between frames 1 and 4 of a still head";

    // A rerun (or a frame chunk) reads the same settled groom back.
    ShotSimulation second(s, 24.0, 1, {cache, true});
    EXPECT_TRUE(second.stats().settleCached);
    EXPECT_EQ(readFile(cache), bytes) << "the cache was rewritten";
    EXPECT_TRUE(sameBytes(second.advanceTo(1).positions, f1.positions));
    // Another input (the settle time) is another groom: the cache is not reused.
    const Scene other = sceneFrom(kSmallShot, dir.path(), {"simulation.preload_limit=0", "hair.groom.settle=4"});
    ShotSimulation third(other, 24.0, 1, {cache, true});
    EXPECT_FALSE(third.stats().settleCached);
}

// ---- groom import ---------------------------------------------------------------

namespace {

constexpr int kVertices = 24;  // hair.guides.segments (23) + 1
constexpr float kUp = 0.03f, kAlong = 0.05f;  // the L-shaped strands' two legs, m

/// A test groom on the project head's rest mesh: strands on every k-th scalp
/// triangle, each an L (kUp along the normal, then kAlong along the
/// tangent) drawn with unevenly spaced points, in metres, Y up.
struct TestGroom {
    std::vector<std::vector<Vec3f>> strands;
    /// Where arc length s of strand i lies (the analytic resampling target).
    std::vector<std::function<Vec3f(float)>> at;
};

TestGroom makeGroom(const HeadSetup& head, size_t count) {
    std::vector<uint32_t> scalp;
    for (uint32_t t = 0; t < head.scalp.size(); ++t)
        if (head.scalp[t]) scalp.push_back(t);
    TestGroom g;
    for (size_t i = 0; i < count; ++i) {
        // Roots anywhere on their triangles (near corners too), so neighbouring
        // roots' tangent frames differ (mesh tangents follow triangle edges).
        const float b1 = 0.05f + 0.9f * float(i % 7) / 7.f, b2 = (1.f - b1) * float(i % 3) / 3.f;
        const SurfaceFrame f = evaluate(head.rest, SurfacePoint{scalp[i * scalp.size() / count], b1, b2});
        const Vec3f n = f.normal.normalized();
        const Vec3f t = (f.tangent - n * n.dot(f.tangent)).normalized();
        const Vec3f root = f.position, corner = root + kUp * n;
        g.strands.push_back({root, root + 0.4f * kUp * n, corner, corner + 0.3f * kAlong * t, corner + kAlong * t});
        g.at.push_back([=](float s) { return s <= kUp ? Vec3f(root + s * n) : Vec3f(corner + (s - kUp) * t); });
    }
    return g;
}

void writeObjGroom(const fs::path& path, const TestGroom& g) {
    std::ofstream out(path);
    for (const auto& s : g.strands)
        for (const Vec3f& p : s) out << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
    size_t v = 1;
    for (const auto& s : g.strands) {
        out << "l";
        for (size_t i = 0; i < s.size(); ++i) out << " " << v++;
        out << "\n";
    }
}

/// A .hair file: `points` in file units, header counts as given.
std::string hairBytes(uint32_t strands, uint32_t points, uint32_t flags, const std::vector<uint16_t>& segments,
                      const std::vector<Vec3f>& pts) {
    std::string b(128, '\0');
    std::memcpy(b.data(), "HAIR", 4);
    std::memcpy(b.data() + 4, &strands, 4);
    std::memcpy(b.data() + 8, &points, 4);
    std::memcpy(b.data() + 12, &flags, 4);
    b.append(reinterpret_cast<const char*>(segments.data()), segments.size() * 2);
    for (const Vec3f& p : pts) b.append(reinterpret_cast<const char*>(p.data()), 12);
    return b;
}

/// The groom as a .hair in centimetres, Z up (as the published models are).
void writeHairGroom(const fs::path& path, const TestGroom& g) {
    const Eigen::Matrix3f toFile = upAxisRotation(UpAxis::Z).transpose() * 100.f;
    std::vector<uint16_t> segments;
    std::vector<Vec3f> pts;
    for (const auto& s : g.strands) {
        segments.push_back(uint16_t(s.size() - 1));
        for (const Vec3f& p : s) pts.push_back(toFile * p);
    }
    writeFile(path, hairBytes(uint32_t(g.strands.size()), uint32_t(pts.size()), 3, segments, pts));
}

void writeUsdaGroom(const fs::path& path, const TestGroom& g) {
    StrandFrame f;
    for (size_t i = 0; i < g.strands.size(); ++i) {
        const std::vector<float> radii(g.strands[i].size(), 5e-5f);
        f.addStrand(uint32_t(i), g.strands[i].data(), radii.data(), g.strands[i].size());
    }
    f.guideCount = uint32_t(g.strands.size());
    writeUsdCurves(path, f, {});
}

/// Largest distance of strand `s` (kVertices points) from the analytic
/// resampling of groom strand `i`.
float shapeError(const std::vector<Vec3f>& s, const TestGroom& g, size_t i) {
    float worst = 0.f;
    for (int k = 0; k < kVertices; ++k)
        worst = std::max(worst, (s[size_t(k)] - g.at[i]((kUp + kAlong) * float(k) / (kVertices - 1))).norm());
    return worst;
}

std::vector<SurfaceFrame> restFrames(const HeadSetup& head, const std::vector<SurfacePoint>& roots) {
    std::vector<SurfaceFrame> f;
    for (const SurfacePoint& r : roots) f.push_back(evaluate(head.rest, r));
    return f;
}

}  // namespace

TEST(GroomImport, ObjHairAndUsdaImportWithTheirStrandCountAndShape) {
    TempDir dir;
    const HeadSetup head = loadHead(sceneFrom("head: {file: " + kProjectHead + "}\n", dir.path()));
    TestGroom groom = makeGroom(head, 40);
    // One more strand, 10 cm off the head: reported and dropped.
    const Vec3f far = groom.strands[0][0] + Vec3f(0.f, 0.1f, 0.f);
    groom.strands.push_back({far, far + Vec3f(0.f, 0.05f, 0.f)});
    groom.at.push_back({});
    writeObjGroom(dir / "g.obj", groom);
    writeHairGroom(dir / "g.hair", groom);
    writeUsdaGroom(dir / "g.usda", groom);
    for (const std::string file : {"g.obj", "g.hair", "g.usda"}) {
        SCOPED_TRACE(file);
        const std::string units = file == "g.hair" ? ", unit_scale: 0.01, up_axis: z" : "";
        const Scene s = sceneFrom("head: {file: " + kProjectHead + "}\nhair: {guides: {count: 100}, followers: {count: 10}, groom: {file: " +
                                      file + units + "}}\n",
                                  dir.path());
        const ImportedGroom imported = importGroom(s, head, kVertices);
        EXPECT_EQ(imported.read, 41u);
        EXPECT_EQ(imported.dropped, 1u);
        ASSERT_EQ(imported.roots.guides.size(), 40u);
        EXPECT_EQ(imported.followerShapes.count(), 0u) << "a sparse groom: procedural followers";
        EXPECT_EQ(imported.roots.followers.size(), 10u);
        const auto strands = strandsAt(imported.guideShapes, restFrames(head, imported.roots.guides));
        for (size_t g = 0; g < strands.size(); ++g) {
            ASSERT_EQ(strands[g].size(), size_t(kVertices));
            EXPECT_LT(shapeError(strands[g], groom, imported.sources[g]), 2e-5f) << "strand " << imported.sources[g];
        }
    }
}

TEST(GroomImport, DenseGroomFollowersReproduceItAtRestAndRootsRideTheSkinnedHead) {
    TempDir dir;
    const std::string yaml = "frames: 1-30\nfps: 24\nhead: {file: " + kProjectHead +
                             "}\nhair: {guides: {count: 12}, followers: {count: 5}, groom: {file: g.obj}}\n";
    const HeadSetup head = loadHead(sceneFrom("head: {file: " + kProjectHead + "}\n", dir.path()));
    const TestGroom groom = makeGroom(head, 150);
    writeObjGroom(dir / "g.obj", groom);
    const Scene s = sceneFrom(yaml, dir.path());
    const ImportedGroom imported = importGroom(s, head, kVertices);
    ASSERT_EQ(imported.roots.guides.size(), 12u);
    ASSERT_EQ(imported.roots.followers.size(), 138u) << "every other strand is a follower";
    ASSERT_EQ(imported.followerShapes.count(), 138u);

    ShotSimulation sim(s, 24.0, 1);
    EXPECT_LT(sim.stats().settleSeconds, 0.0) << "an imported groom is not settled";
    const StrandFrame f1 = sim.advanceTo(1);  // the clip is still here: the rest pose
    ASSERT_EQ(f1.strandCount(), 150u);
    float worst = 0.f;
    for (size_t i = 0; i < 150; ++i) {
        const std::vector<Vec3f> s1(f1.positions.begin() + f1.first(i), f1.positions.begin() + f1.first(i) + f1.vertexCount(i));
        worst = std::max(worst, shapeError(s1, groom, imported.sources[i]));
    }
    EXPECT_LT(worst, 2e-5f) << "m: guides and followers at rest are the groom";

    // Nodded down 20° (frame 9, t = 0.375 s): every root is on the posed, skinned surface.
    const StrandFrame f12 = sim.advanceTo(9);
    const MeshQuery posed(sim.pose().mesh);
    size_t movedRoots = 0;
    for (size_t i = 0; i < f12.strandCount(); ++i) {
        const Vec3f root = f12.positions[f12.first(i)];
        EXPECT_LT(posed.closest(root).distance, 1e-5f) << "strand " << i;
        movedRoots += (root - f1.positions[f1.first(i)]).norm() > 0.005f;
    }
    EXPECT_GT(movedRoots, 100u) << "the nod moves the roots";
}

TEST(GroomImport, ExportedUsdaImportsBackAsTheCachedFrame) {
    TempDir dir;
    writeFile(dir / "s.yaml", "frames: 1-2\nfps: 24\nhead: {file: " + kProjectHead +
                                  "}\nhair: {guides: {count: 10}, followers: {count: 40}}\n");
    // Whole strands in the cache (version 1), to compare the USD with here.
    ProcessResult r = runHairpipe("sim s.yaml --out out --set cache.followers=store", dir.path());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    r = runHairpipe("export-usd s.yaml --out out --frames 1", dir.path());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const StrandFrame cached = readStrandCache(dir / "out/cache/strands.0001.hpc");
    const GroomCurves curves = parseUsdaCurves(readFile(dir / "out/usd/hair.usda"), "hair.usda");
    EXPECT_EQ(curves.offsets, cached.offsets);
    EXPECT_TRUE(sameBytes(curves.points, cached.positions)) << "%.9g text round-trips every float";

    // As a groom: 50 strands, 10 chosen as guides, the others keep their shape.
    const Scene g = sceneFrom("head: {file: " + kProjectHead +
                                  "}\nhair: {guides: {count: 10}, groom: {file: out/usd/hair.usda}}\n",
                              dir.path());
    const HeadSetup head = loadHead(g);
    const ImportedGroom imported = importGroom(g, head, kVertices);
    ASSERT_EQ(imported.read, 50u);
    ASSERT_EQ(imported.roots.followers.size(), 40u);
    const auto strands = strandsAt(imported.guideShapes, restFrames(head, imported.roots.guides));
    for (size_t i = 0; i < strands.size(); ++i)
        for (int k = 0; k < kVertices; ++k)
            EXPECT_LT((strands[i][size_t(k)] - cached.positions[cached.first(imported.sources[i]) + uint32_t(k)]).norm(), 2e-5f);
}

// ---- bad groom files ------------------------------------------------------------

namespace {

std::string assetError(const std::function<void()>& f) {
    try {
        f();
    } catch (const AssetError& e) {
        return e.what();
    }
    return "(no AssetError)";
}

}  // namespace

TEST(GroomFile, BadInputIsAClearErrorNamingTheFileAndTheProblem) {
    TempDir dir;
    auto hair = [&](const std::string& bytes) {
        writeFile(dir / "bad.hair", bytes);
        return assetError([&] { readGroomFile(dir / "bad.hair"); });
    };
    const std::vector<Vec3f> two = {Vec3f(0, 0, 0), Vec3f(0, 1, 0)};
    EXPECT_NE(hair("").find("bad.hair: the .hair file is empty"), std::string::npos) << hair("");
    EXPECT_NE(hair("HAIR\1").find("truncated .hair header"), std::string::npos);
    EXPECT_NE(hair("OBJ!" + std::string(200, 'x')).find("not a .hair file"), std::string::npos);
    // 10^8 strands declared in a 128-byte file: refused before any allocation.
    const std::string huge = hair(hairBytes(100000000u, 200000000u, 3, {}, {}));
    EXPECT_NE(huge.find("declares 100000000 strands"), std::string::npos) << huge;
    const std::string lying = hair(hairBytes(1000u, 2000u, 3, {1}, two));
    EXPECT_NE(lying.find("truncated .hair file"), std::string::npos) << lying;
    EXPECT_NE(hair(hairBytes(1, 2, 1, {1}, two)).find("no points array"), std::string::npos);
    EXPECT_NE(hair(hairBytes(1, 3, 3, {1}, {two[0], two[1], two[1]})).find("2 points in all but the file declares 3"),
              std::string::npos);
    const float nan = std::nanf("");
    EXPECT_NE(hair(hairBytes(1, 2, 3, {1}, {two[0], Vec3f(0, nan, 0)})).find("strand 0 point 1 is not a finite number"),
              std::string::npos);
    EXPECT_NE(hair(hairBytes(2, 3, 3, {1, 0}, {two[0], two[1], two[1]})).find("strand 1 has 1 point"), std::string::npos);
    EXPECT_NE(hair(hairBytes(1, 2, 3, {1}, {two[0], two[0]})).find("strand 0 has zero length"), std::string::npos);

    auto usda = [&](const std::string& text) {
        writeFile(dir / "bad.usda", text);
        return assetError([&] { readGroomFile(dir / "bad.usda"); });
    };
    const std::string head = "#usda 1.0\n(\n    metersPerUnit = 1\n)\n\n";
    const std::string curves = "def BasisCurves \"hair\" (\n    kind = \"component\"\n)\n{\n";
    EXPECT_NE(usda("").find("empty"), std::string::npos);
    EXPECT_NE(usda("#usda 1.0\n(\n    metersPerUnit = 0.01\n)\n").find("line 3: 'metersPerUnit = 0.01': only the layer metadata"),
              std::string::npos);
    EXPECT_NE(usda(head + "def Xform \"root\"\n{\n}\n").find("only a BasisCurves prim"), std::string::npos);
    EXPECT_NE(usda(head + curves + "    uniform token type = \"cubic\"\n}\n").find("only linear, nonperiodic"),
              std::string::npos);
    EXPECT_NE(usda(head + curves + "    int[] curveVertexCounts = [2, 2]\n    point3f[] points = [(0, 0, 0), (0, 1, 0)]\n}\n")
                  .find("add up to 4 points but the BasisCurves has 2"),
              std::string::npos);
    EXPECT_NE(usda(head + curves + "    int[] curveVertexCounts = [2]\n    point3f[] points.timeSamples = {\n").find("truncated"),
              std::string::npos);
    EXPECT_NE(usda(head + curves + "    rel material:binding = </M>\n}\n").find("not part of the BasisCurves"),
              std::string::npos);

    writeFile(dir / "empty.obj", "");
    EXPECT_NE(assetError([&] { readGroomFile(dir / "empty.obj"); }).find("empty.obj: the .obj file is empty"), std::string::npos);
    writeFile(dir / "faces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    EXPECT_NE(assetError([&] { readGroomFile(dir / "faces.obj"); }).find("contains no polylines"), std::string::npos);
    EXPECT_NE(assetError([&] { readGroomFile(dir / "g.abc"); }).find("groom file not found"), std::string::npos);

    // The command line: exit 1, the file and the problem named.
    writeFile(dir / "bad.hair", hairBytes(1000u, 2000u, 3, {1}, two));
    writeFile(dir / "s.yaml", "head: {file: " + kProjectHead + "}\nhair: {guides: {count: 10}, groom: {file: bad.hair}}\n");
    const ProcessResult r = runHairpipe("sim s.yaml --frames 1 --out out", dir.path());
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find("bad.hair: truncated .hair file"), std::string::npos) << r.output;
}
