// OpenVDB export: round trips through openvdb::io::File (grid names, class,
// transform, metadata, values), deterministic bytes, empty frames, and the
// "vdb" stage and command (atomic writes, failed frames, exit codes).
#include "pipeline/batch/output.h"
#include "pipeline/scene/scene.h"
#include "pipeline/stages/shot.h"
#include "pipeline/stages/stages.h"
#include "render/volume/vdb_writer.h"
#include "render/volume/voxelizer.h"
#include "sim/strands/synthetic.h"
#include "batch_support.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <tbb/task_arena.h>

#include <Eigen/Geometry>

#include <cmath>

using namespace hp;
namespace fs = std::filesystem;

namespace {

/// A few hundred synthetic strands with a spin velocity (the B-vdb geometry, smaller).
StrandFrame smallHair(size_t strands = 400) {
    SyntheticHairSettings hs;
    hs.strands = strands;
    StrandFrame hair = makeSyntheticHair(hs);
    hair.velocities.resize(hair.positions.size());
    for (size_t v = 0; v < hair.positions.size(); ++v)
        hair.velocities[v] = Vec3f(0, 1.57f, 0).cross(hair.positions[v]);
    return hair;
}

VdbFrameInfo frameInfo(const StrandFrame& hair, int frame) {
    VdbFrameInfo info;
    info.frame = frame;
    info.fps = 30;
    info.time = frame / 30.0;
    info.scene = "roundtrip";
    info.strandCount = hair.strandCount();
    info.hairVolume = hairVolume(hair);
    return info;
}

const VdbGridInfo* findGrid(const VdbContents& c, const std::string& name) {
    for (const VdbGridInfo& g : c.grids)
        if (g.name == name) return &g;
    return nullptr;
}

/// Every stored voxel of `a` (× scale) equals `b`'s; with a tolerance,
/// within it relatively, plus 1e-7 absolute for values that underflow a half
/// float. Exact comparisons also compare the active voxel counts.
void expectSameValues(const DensityGrid& a, const DensityGrid& b, double tolerance, float scale = 1.f) {
    if (tolerance == 0) {
        ASSERT_EQ(a.activeVoxelCount(), b.activeVoxelCount());
    }
    for (size_t i = 0; i < a.blockCount(); ++i)
        for (int x = 0; x < 8; ++x)
            for (int y = 0; y < 8; ++y)
                for (int z = 0; z < 8; ++z) {
                    const Vec3i v = a.blockOrigin(i) + Vec3i(x, y, z);
                    const float expected = a.blockDensity(i)[DensityGrid::voxelOffset(x, y, z)] * scale;
                    const float got = b.density(v);
                    if (tolerance == 0) {
                        ASSERT_EQ(got, expected) << "voxel " << v.transpose();
                    } else {
                        ASSERT_NEAR(got, expected, tolerance * expected + 1e-7f) << "voxel " << v.transpose();
                    }
                }
}

}  // namespace

TEST(VdbFile, RoundTripKeepsNamesClassTransformMetadataAndValues) {
    test::TempDir dir;
    const StrandFrame hair = smallHair();
    const double h = 0.002;
    VoxelizeSettings vs;
    vs.velocity = true;
    const DensityGrid grid = voxelize(hair, GridTransform::uniform(h), vs);
    const fs::path file = dir / "hair.0007.vdb";
    writeDensityVdb(file, grid, frameInfo(hair, 7));

    const VdbContents c = readDensityVdb(file);
    ASSERT_EQ(c.grids.size(), 2u);
    const VdbGridInfo* d = findGrid(c, "density");
    ASSERT_NE(d, nullptr);
    EXPECT_EQ(d->valueType, "float");
    EXPECT_EQ(d->gridClass, "fog volume");
    EXPECT_EQ(d->background, 0.0);
    EXPECT_FALSE(d->savedAsHalf);
    EXPECT_DOUBLE_EQ(d->voxelSize, h);
    EXPECT_TRUE(d->indexToWorld.isApprox(Eigen::Vector4d(h, h, h, 1).asDiagonal().toDenseMatrix(), 1e-12))
        << d->indexToWorld;
    EXPECT_EQ(d->metadata.at("frame"), "7");
    EXPECT_EQ(d->metadataType.at("frame"), "int32");
    EXPECT_EQ(d->metadata.at("fps"), "30");
    EXPECT_EQ(d->metadataType.at("time"), "double");
    EXPECT_EQ(d->metadata.at("scene"), "roundtrip");
    EXPECT_NE(d->metadata.at("units").find("hair volume fraction"), std::string::npos);
    EXPECT_EQ(d->metadataType.at("voxel_size"), "double");
    EXPECT_DOUBLE_EQ(std::stod(d->metadata.at("voxel_size")), h);
    EXPECT_EQ(d->metadata.at("strand_count"), "400");
    EXPECT_EQ(d->metadataType.at("strand_count"), "int64");
    EXPECT_EQ(d->metadata.at("filter"), "trilinear");
    // Metadata text has 6 significant digits.
    EXPECT_NEAR(std::stod(d->metadata.at("hair_volume")), hairVolume(hair), 1e-5 * hairVolume(hair));
    EXPECT_EQ(d->metadata.at("creator"), "hairpipe");

    EXPECT_EQ(d->activeVoxels, grid.activeVoxelCount());
    Vec3i lo, hi;
    ASSERT_TRUE(grid.activeBounds(&lo, &hi));
    EXPECT_EQ(d->activeMin, lo);
    EXPECT_EQ(d->activeMax, hi);

    ASSERT_TRUE(c.hasDensity);
    expectSameValues(grid, c.density, 0.0);
    EXPECT_NEAR(c.density.totalVolume(), hairVolume(hair), 1e-6 * hairVolume(hair));

    const VdbGridInfo* v = findGrid(c, "velocity");
    ASSERT_NE(v, nullptr);
    EXPECT_EQ(v->valueType, "vec3s");
    EXPECT_EQ(v->vectorType, "contravariant relative");
    EXPECT_EQ(v->activeVoxels, grid.activeVoxelCount());
    ASSERT_TRUE(c.density.hasVelocity());
    for (size_t b = 0; b < grid.blockCount(); b += 7)
        for (int i = 0; i < DensityGrid::kBlockVoxels; i += 5) {
            const Vec3i voxel = grid.blockOrigin(b) + Vec3i(i >> 6, (i >> 3) & 7, i & 7);
            EXPECT_EQ(c.density.velocity(voxel), grid.velocity(voxel)) << voxel.transpose();
        }
}

TEST(VdbFile, HalfFloatScaleAndNoCompression) {
    test::TempDir dir;
    const StrandFrame hair = smallHair(200);
    const DensityGrid grid = voxelize(hair, GridTransform::uniform(0.002));
    VdbWriteSettings ws;
    ws.halfFloat = true;
    ws.densityScale = 2e4;  // e.g. an extinction scale baked in
    writeDensityVdb(dir / "half.vdb", grid, frameInfo(hair, 1), ws);
    ws.halfFloat = false;
    ws.compression = VdbCompression::None;
    writeDensityVdb(dir / "plain.vdb", grid, frameInfo(hair, 1), ws);

    const VdbContents half = readDensityVdb(dir / "half.vdb");
    ASSERT_EQ(half.grids.size(), 1u);  // no velocity channel in the grid
    EXPECT_TRUE(half.grids[0].savedAsHalf);
    EXPECT_EQ(half.grids[0].metadata.at("density_scale"), "20000");
    expectSameValues(grid, half.density, 1e-3, 2e4f);
    const VdbContents plain = readDensityVdb(dir / "plain.vdb");
    expectSameValues(grid, plain.density, 1e-7, 2e4f);
    EXPECT_LT(fs::file_size(dir / "half.vdb"), fs::file_size(dir / "plain.vdb"));
}

TEST(VdbFile, EmptyFrameWritesAValidEmptyGrid) {
    test::TempDir dir;
    const DensityGrid empty = voxelize(StrandFrame(), GridTransform::uniform(0.001));
    VdbFrameInfo info;
    info.frame = 3;
    writeDensityVdb(dir / "empty.vdb", empty, info);
    const VdbContents c = readDensityVdb(dir / "empty.vdb");
    ASSERT_EQ(c.grids.size(), 1u);
    EXPECT_EQ(c.grids[0].name, "density");
    EXPECT_EQ(c.grids[0].gridClass, "fog volume");
    EXPECT_EQ(c.grids[0].activeVoxels, 0u);
    EXPECT_EQ(c.grids[0].metadata.at("strand_count"), "0");
    EXPECT_DOUBLE_EQ(c.grids[0].voxelSize, 0.001);
    ASSERT_TRUE(c.hasDensity);
    EXPECT_EQ(c.density.blockCount(), 0u);
}

TEST(VdbFile, AffineLightSpaceTransformRoundTrips) {
    test::TempDir dir;
    const StrandFrame hair = smallHair(100);
    const Vec3d z = Vec3d(-1, -1, -1).normalized(), x = z.unitOrthogonal(), y = z.cross(x);
    Eigen::Matrix3d axes;
    axes << x * 0.003, y * 0.003, z * 0.003;
    const GridTransform t = GridTransform::fromAxes(axes, Vec3d(0.01, 0.2, -0.05));
    const DensityGrid grid = voxelize(hair, t);
    writeDensityVdb(dir / "light.vdb", grid, frameInfo(hair, 1));
    const VdbContents c = readDensityVdb(dir / "light.vdb");
    EXPECT_NEAR(c.grids[0].voxelSize, 0.003, 1e-12);  // rotated, but cubic voxels
    EXPECT_NEAR(std::stod(c.grids[0].metadata.at("voxel_size")), 0.003, 1e-9);
    EXPECT_TRUE(c.density.transform().linear.isApprox(t.linear, 1e-12));
    EXPECT_TRUE(c.density.transform().offset.isApprox(t.offset, 1e-9));
    expectSameValues(grid, c.density, 0.0);
}

TEST(VdbFile, BytesAreIdenticalForOneAndTwoThreadsAndRepeatedWrites) {
    test::TempDir dir;
    const StrandFrame hair = smallHair(300);
    VoxelizeSettings vs;
    vs.velocity = true;
    auto writeWith = [&](int threads, const fs::path& file, int frame) {
        tbb::task_arena(threads).execute([&] {
            const DensityGrid grid = voxelize(hair, GridTransform::uniform(0.0015), vs);
            writeDensityVdb(file, grid, frameInfo(hair, frame));
        });
    };
    writeWith(1, dir / "one.vdb", 1);
    writeWith(2, dir / "two.vdb", 1);
    writeWith(2, dir / "again.vdb", 1);
    writeWith(2, dir / "frame2.vdb", 2);
    const std::string one = test::readFile(dir / "one.vdb"), two = test::readFile(dir / "two.vdb");
    ASSERT_GT(one.size(), 10000u);
    EXPECT_TRUE(one == two) << "1-thread and 2-thread files differ";
    EXPECT_TRUE(one == test::readFile(dir / "again.vdb")) << "repeated write differs";
    // The header's UUID identifies the contents: another frame, another UUID.
    const std::string other = test::readFile(dir / "frame2.vdb");
    EXPECT_NE(one.substr(21, 36), other.substr(21, 36));
    EXPECT_EQ(one[21 + 8], '-');
}

// The writer serializes the leaves' buffers in parallel (ParallelBuffersGrid
// in vdb_writer.cpp). OpenVDB's own serial writer, given the grids read back
// from the file, must write the same bytes (all but the header's UUID,
// random in OpenVDB's file, a content digest in ours), for the default file
// (half floats, no Blosc) and for full floats with Blosc and velocity.
TEST(VdbFile, ParallelLeafBuffersGiveOpenVdbsSerialBytes) {
    test::TempDir dir;
    const StrandFrame hair = smallHair(300);
    VoxelizeSettings vs;
    vs.velocity = true;
    const DensityGrid grid = voxelize(hair, GridTransform::uniform(0.0015), vs);
    ASSERT_GT(grid.blockCount(), 2000u);  // several chunks and rounds of leaves
    openvdb::initialize();
    for (const bool half : {true, false}) {
        VdbWriteSettings ws;
        ws.halfFloat = half;
        ws.compression = half ? VdbCompression::None : VdbCompression::Blosc;
        const fs::path ours = dir / "ours.vdb", theirs = dir / "theirs.vdb";
        writeDensityVdb(ours, grid, frameInfo(hair, 1), ws);
        openvdb::io::File in(ours.string());
        in.open(false);
        openvdb::GridPtrVec grids;
        for (auto name = in.beginName(); name != in.endName(); ++name) grids.push_back(in.readGrid(name.gridName()));
        in.close();
        ASSERT_EQ(grids.size(), 2u);
        openvdb::io::File out(theirs.string());
        out.setCompression(uint32_t(openvdb::io::COMPRESS_ACTIVE_MASK) | (half ? 0u : uint32_t(openvdb::io::COMPRESS_BLOSC)));
        out.write(grids);
        out.close();
        std::string a = test::readFile(ours), b = test::readFile(theirs);
        ASSERT_EQ(a.size(), b.size()) << (half ? "half" : "float");
        a.replace(21, 36, 36, '-');
        b.replace(21, 36, 36, '-');
        EXPECT_TRUE(a == b) << (half ? "half" : "float") << " file differs from OpenVDB's serial write";
    }
}

TEST(VdbFile, UnreadableFileNamesIt) {
    test::TempDir dir;
    test::writeFile(dir / "junk.vdb", "not a vdb file at all");
    try {
        readDensityVdb(dir / "junk.vdb");
        FAIL() << "expected an error";
    } catch (const AssetError& e) {
        EXPECT_NE(std::string(e.what()).find("junk.vdb"), std::string::npos) << e.what();
    }
}

// ---------------------------------------------------------------------------
// The stage and the command

namespace {

/// Frame data with strands, as the simulation will provide.
class HairSource final : public FrameSource {
  public:
    explicit HairSource(const StrandFrame* hair) : hair_(hair) {}
    FrameData get(int frame) override {
        FrameData d;
        d.frame = frame;
        d.time = frame / 24.0;
        d.strands = hair_;
        return d;
    }

  private:
    const StrandFrame* hair_;
};

ShotSettings shotIn(const Scene& scene, const fs::path& out) {
    RunOptions options;
    options.outputDir = out;
    return resolveShot(scene, options);
}

}  // namespace

TEST(VdbStage, WritesOneFilePerFrameAtomicallyAndResumes) {
    test::TempDir dir;
    const Scene scene = Scene::parse("name: stage\nframes: 1-2\nvdb: {enabled: true, voxel_size: 0.004, velocity: true}\n",
                                     "stage.yaml", dir.path());
    const ShotSettings shot = shotIn(scene, dir / "out");
    std::vector<StagePtr> stages = makeStages(scene, shot, {"vdb"});
    ASSERT_EQ(stages.size(), 1u);
    EXPECT_EQ(stages[0]->name(), "vdb");
    EXPECT_EQ(stages[0]->outputs(2).front(), dir / "out/vdb/hair.0002.vdb");

    const StrandFrame hair = smallHair(100);
    HairSource source(&hair);
    RunReport report = runFrames(source, stages, shot);
    EXPECT_TRUE(report.failures.empty()) << report.failures.front();
    for (const char* name : {"hair.0001.vdb", "hair.0002.vdb"}) {
        const VdbContents c = readDensityVdb(dir / "out/vdb" / name);
        EXPECT_EQ(c.grids.size(), 2u);
        EXPECT_EQ(c.grids[0].metadata.at("scene"), "stage");
        EXPECT_EQ(c.grids[0].metadata.at("strand_count"), "100");
        // The scene default stores half floats: each value rounds by at most
        // 2^-11 relative (normal halves) or 2^-25 absolute (subnormal ones).
        EXPECT_TRUE(c.grids[0].savedAsHalf);
        const double bound = std::ldexp(hairVolume(hair), -11) +
                             double(c.grids[0].activeVoxels) * std::ldexp(c.density.transform().voxelVolume(), -25);
        EXPECT_NEAR(c.density.totalVolume(), hairVolume(hair), bound);
    }
    for (const auto& entry : fs::directory_iterator(dir / "out/vdb"))
        EXPECT_EQ(entry.path().filename().string().rfind(kTemporaryPrefix, 0), std::string::npos) << entry.path();
    report = runFrames(source, stages, shot);
    EXPECT_EQ(report.outputsSkipped, 2u);
}

TEST(VdbStage, UnwritableOutputAndMissingStrandsFailTheFrame) {
    test::TempDir dir;
    test::writeFile(dir / "out/vdb", "a file where the folder should be");
    const Scene scene = Scene::parse("frames: 4\nvdb: {enabled: true, voxel_size: 0.004}\n", "s.yaml", dir.path());
    const ShotSettings shot = shotIn(scene, dir / "out");
    std::vector<StagePtr> stages = makeStages(scene, shot, {});
    const StrandFrame hair = smallHair(50);
    HairSource source(&hair);
    RunReport report = runFrames(source, stages, shot);
    ASSERT_EQ(report.failures.size(), 1u);
    EXPECT_NE(report.failures[0].find("frame 4 vdb"), std::string::npos) << report.failures[0];
    EXPECT_NE(report.failures[0].find("cannot create folder"), std::string::npos) << report.failures[0];

    HairSource none(nullptr);
    report = runFrames(none, stages, shot);
    ASSERT_EQ(report.failures.size(), 1u);
    EXPECT_NE(report.failures[0].find("has no strands"), std::string::npos) << report.failures[0];
}

TEST(VdbStage, AWriteBesideTheNextFrameThatFailsFailsItsFrameAndLeavesNoFile) {
    // With the overlap lane the vdb stage writes frame N's file on a thread
    // of its own while frame N+1 voxelizes, so a failed write is known only
    // after run() returned; the stage reports it through collectFailures for
    // its own frame. Frames 2 and 3 cannot replace the folders in their place
    // (the rename after the whole temporary file was written fails): frame
    // 2's failure is collected after frame 3's run, the last frame's only
    // when the run waits for its write at the end. Frame 1 is written, and no
    // temporary file is left.
    test::TempDir dir;
    for (const char* name : {"hair.0002.vdb", "hair.0003.vdb"}) fs::create_directories(dir / "out/vdb" / name);
    const Scene scene = Scene::parse("frames: 1-3\nvdb: {enabled: true, voxel_size: 0.004}\n", "s.yaml", dir.path());
    ShotSettings shot = shotIn(scene, dir / "out");
    shot.force = true;  // frames 2 and 3 have an "output" (a folder)
    ASSERT_TRUE(shot.overlap);
    std::vector<StagePtr> stages = makeStages(scene, shot, {"vdb"});
    const StrandFrame hair = smallHair(100);
    HairSource source(&hair);
    RunReport report;
    tbb::task_arena(2).execute([&] { report = runFrames(source, stages, shot); });
    ASSERT_EQ(report.failures.size(), 2u);
    for (int f : {2, 3}) {
        const std::string& failure = report.failures[size_t(f - 2)];
        EXPECT_NE(failure.find(cat("frame ", f, " vdb: ")), std::string::npos) << failure;
        EXPECT_NE(failure.find("cannot rename"), std::string::npos) << failure;
        EXPECT_TRUE(fs::is_empty(dir / "out/vdb" / cat("hair.000", f, ".vdb")));
    }
    EXPECT_EQ(report.framesDone, 3u);
    EXPECT_EQ(readDensityVdb(dir / "out/vdb/hair.0001.vdb").grids.size(), 1u);
    for (const auto& entry : fs::directory_iterator(dir / "out/vdb"))
        EXPECT_FALSE(isTemporary(entry.path())) << entry.path();
}

TEST(VdbStage, SceneKeysAreValidated) {
    test::TempDir dir;
    const Scene noToken = Scene::parse("vdb: {enabled: true, output: vdb/hair.vdb}\n", "s.yaml", dir.path());
    try {
        makeVdbStage(noToken, shotIn(noToken, dir / "out"));
        FAIL() << "expected an error";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("'vdb.output'"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("frame token"), std::string::npos) << e.what();
    }
    EXPECT_THROW(Scene::parse("vdb: {voxel_size: 0}\n", "s.yaml", dir.path()), SceneError);
    EXPECT_THROW(Scene::parse("vdb: {filter: gaussian}\n", "s.yaml", dir.path()), SceneError);
    const Scene off = Scene::parse("frames: 1\n", "s.yaml", dir.path());
    EXPECT_EQ(makeVdbStage(off, shotIn(off, dir / "out")), nullptr);
}

TEST(VdbCommand, ExitCodes) {
    test::TempDir dir;
    test::writeFile(dir / "on.yaml", "frames: 1-2\nvdb: {enabled: true}\n");
    // The CLI's shots have no strands until the simulation is integrated:
    // every frame fails with a message, exit code 2.
    const test::ProcessResult r = test::runHairpipe("vdb on.yaml --out out", dir.path());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("frame 2 vdb: the shot has no strands"), std::string::npos) << r.output;
    // A write that fails while the next frame voxelizes (the stage's write
    // beside it) still fails the run with exit code 2, naming its frame, and
    // leaves no temporary file.
    const fs::path small = test::writeSmallScene(dir.path(), "1-3");
    fs::create_directories(dir / "blocked/vdb/hair.0002.vdb");
    const test::ProcessResult blocked = test::runHairpipe(
        "vdb " + test::q(small) + " --out " + test::q(dir / "blocked") + " --force --set vdb.velocity=false", dir.path());
    EXPECT_EQ(blocked.exitCode, 2) << blocked.output;
    EXPECT_NE(blocked.output.find("frame 2 vdb: "), std::string::npos) << blocked.output;
    for (const char* name : {"hair.0001.vdb", "hair.0003.vdb"}) EXPECT_TRUE(fs::exists(dir / "blocked/vdb" / name)) << name;
    for (const auto& entry : fs::directory_iterator(dir / "blocked/vdb"))
        EXPECT_FALSE(isTemporary(entry.path())) << entry.path();
    test::writeFile(dir / "off.yaml", "frames: 1\n");
    const test::ProcessResult off = test::runHairpipe("vdb off.yaml --out out", dir.path());
    EXPECT_EQ(off.exitCode, 1) << off.output;
    EXPECT_NE(off.output.find("--set vdb.enabled=true"), std::string::npos) << off.output;
    EXPECT_EQ(test::runHairpipe("vdb --help").exitCode, 0);
}
