#include "batch_support.h"
#include "core/errors.h"
#include "pipeline/batch/strand_cache.h"
#include "pipeline/stages/cached_strands.h"
#include "pipeline/stages/shot.h"
#include "pipeline/stages/usd_export.h"
#include "sim/strands/synthetic.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <fstream>
#include <regex>

using namespace hp;
namespace fs = std::filesystem;

namespace {

StrandFrame sample(bool velocities) {
    SyntheticHairSettings s;
    s.strands = 50;
    s.vertices = 7;
    StrandFrame f = makeSyntheticHair(s);
    f.frame = 12;
    f.time = 0.5;
    f.guideCount = 5;
    for (size_t i = 0; i < f.ids.size(); ++i) f.ids[i] = uint32_t(1000 + 3 * i);
    if (velocities) {
        f.velocities.resize(f.positions.size());
        for (size_t v = 0; v < f.velocities.size(); ++v) f.velocities[v] = Vec3f(float(v), -1.f / (v + 1), 0.25f);
    }
    return f;
}

void expectIdentical(const StrandFrame& a, const StrandFrame& b) {
    EXPECT_EQ(a.frame, b.frame);
    EXPECT_EQ(a.time, b.time);
    EXPECT_EQ(a.guideCount, b.guideCount);
    EXPECT_EQ(a.offsets, b.offsets);
    EXPECT_EQ(a.ids, b.ids);
    EXPECT_EQ(a.radii, b.radii);
    ASSERT_EQ(a.positions.size(), b.positions.size());
    if (!a.positions.empty()) {  // see below
        EXPECT_EQ(0, std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Vec3f)));
    }
    ASSERT_EQ(a.velocities.size(), b.velocities.size());
    // memcmp on an empty vector's null data() is undefined (UBSan): compare only non-empty arrays.
    if (!a.velocities.empty()) {
        EXPECT_EQ(0, std::memcmp(a.velocities.data(), b.velocities.data(), a.velocities.size() * sizeof(Vec3f)));
    }
}

std::string errorOf(const fs::path& p) {
    try {
        readStrandCache(p);
    } catch (const AssetError& e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST(StrandCache, RoundTripIsBitExact) {
    test::TempDir dir;
    for (bool v : {false, true}) {
        const StrandFrame f = sample(v);
        writeStrandCache(dir / "a.hpc", f);
        expectIdentical(readStrandCache(dir / "a.hpc"), f);
    }
}

TEST(StrandCache, EmptyFrameRoundTrips) {
    test::TempDir dir;
    StrandFrame f;
    f.frame = 3;
    writeStrandCache(dir / "e.hpc", f);
    const StrandFrame g = readStrandCache(dir / "e.hpc");
    EXPECT_EQ(g.strandCount(), 0u);
    EXPECT_EQ(g.frame, 3);
}

TEST(StrandCache, CorruptionIsDetectedByChecksum) {
    test::TempDir dir;
    writeStrandCache(dir / "a.hpc", sample(true));
    std::string bytes = test::readFile(dir / "a.hpc");
    bytes[bytes.size() / 2] ^= 0x10;
    test::writeFile(dir / "a.hpc", bytes);
    const std::string e = errorOf(dir / "a.hpc");
    EXPECT_NE(e.find("checksum mismatch"), std::string::npos) << e;
    EXPECT_NE(e.find("a.hpc"), std::string::npos) << e;
}

TEST(StrandCache, TruncationWrongMagicAndVersion) {
    test::TempDir dir;
    writeStrandCache(dir / "a.hpc", sample(false));
    const std::string bytes = test::readFile(dir / "a.hpc");
    test::writeFile(dir / "t.hpc", bytes.substr(0, bytes.size() - 100));
    EXPECT_FALSE(errorOf(dir / "t.hpc").empty());
    test::writeFile(dir / "short.hpc", bytes.substr(0, 5));
    EXPECT_NE(errorOf(dir / "short.hpc").find("truncated"), std::string::npos);
    test::writeFile(dir / "m.hpc", "NOTACACHE" + bytes.substr(9));
    EXPECT_NE(errorOf(dir / "m.hpc").find("wrong magic"), std::string::npos);
    std::string v = bytes;
    v[8] = 9;
    test::writeFile(dir / "v.hpc", v);
    EXPECT_NE(errorOf(dir / "v.hpc").find("version 9 is not supported"), std::string::npos) << errorOf(dir / "v.hpc");
    EXPECT_NE(errorOf(dir / "missing.hpc").find("cannot open"), std::string::npos);
}

TEST(UsdExport, WritesBasisCurvesStructure) {
    test::TempDir dir;
    const StrandFrame f = sample(true);
    StrandFrame g = f;
    g.frame = 13;
    writeUsdCurves(dir / "hair.usda", {&f, &g}, UsdExportSettings{});
    const std::string text = test::readFile(dir / "hair.usda");
    EXPECT_EQ(text.rfind("#usda 1.0", 0), 0u);
    EXPECT_NE(text.find("def BasisCurves \"hair\""), std::string::npos);
    EXPECT_NE(text.find("uniform token type = \"linear\""), std::string::npos);
    // One count per strand, summing to the vertex count.
    const std::smatch m = [&] {
        std::smatch r;
        std::regex_search(text, r, std::regex("int\\[\\] curveVertexCounts = \\[([^\\]]*)\\]"));
        return r;
    }();
    ASSERT_EQ(m.size(), 2u);
    std::stringstream counts(m[1].str());
    size_t n = 0, sum = 0;
    for (std::string item; std::getline(counts, item, ',');) ++n, sum += std::stoul(item);
    EXPECT_EQ(n, f.strandCount());
    EXPECT_EQ(sum, f.vertexCount());
    // One points sample per frame, each with one point per vertex.
    for (int frame : {12, 13}) {
        const std::string key = "        " + std::to_string(frame) + ": [(";
        const size_t at = text.find(key);
        ASSERT_NE(at, std::string::npos) << frame;
        const std::string line = text.substr(at, text.find('\n', at) - at);
        EXPECT_EQ(size_t(std::count(line.begin(), line.end(), '(')), f.vertexCount());
    }
    EXPECT_NE(text.find("widths:interpolation = \"vertex\""), std::string::npos);
    // Brackets and braces balance.
    EXPECT_EQ(std::count(text.begin(), text.end(), '['), std::count(text.begin(), text.end(), ']'));
    EXPECT_EQ(std::count(text.begin(), text.end(), '{'), std::count(text.begin(), text.end(), '}'));
}

TEST(UsdExport, TopologyChangeIsRejected) {
    test::TempDir dir;
    const StrandFrame f = sample(false);
    StrandFrame g = sample(false);
    g.offsets.back() -= 1;
    g.positions.pop_back();
    g.radii.pop_back();
    EXPECT_THROW(writeUsdCurves(dir / "x.usda", {&f, &g}, UsdExportSettings{}), Error);
}

namespace {

/// Bytes of every strand cache frame under `out`.
uintmax_t cacheBytes(const fs::path& out, int frames) {
    uintmax_t bytes = 0;
    for (int f = 1; f <= frames; ++f) {
        char name[64];
        std::snprintf(name, sizeof name, "cache/strands.%04d.hpc", f);
        bytes += fs::file_size(out / name);
    }
    return bytes;
}

}  // namespace

TEST(StrandCache, GuideRecordsRoundTripAndOldVersionsStillRead) {
    test::TempDir dir;
    CachedGuides g;
    g.strands = 50;
    g.vertices = 350;
    g.current.guides = sample(true);
    g.current.guides.offsets.resize(6);  // the 5 guides only
    g.current.guides.ids.resize(5);
    g.current.guides.positions.resize(35);
    g.current.guides.radii.resize(35);
    g.current.guides.velocities.resize(35);
    g.current.dt = 1.0 / 24;
    g.current.pins = {{3, Vec3f(0.1f, -0.2f, 0.3f)}, {290, Vec3f(1e-7f, 2.f, -3.f)}};
    g.previous = g.current;
    g.previous->guides.frame = 11;
    g.previous->dt = 0.0;
    g.previous->pins.clear();
    writeGuideCache(dir / "g.hpc", g);
    const StrandCacheFile f = readStrandCacheFile(dir / "g.hpc");
    EXPECT_EQ(f.version, kGuideCacheVersion);
    ASSERT_TRUE(f.guides && f.guides->previous);
    EXPECT_EQ(f.guides->strands, 50u);
    EXPECT_EQ(f.guides->vertices, 350u);
    expectIdentical(f.guides->current.guides, g.current.guides);
    expectIdentical(f.guides->previous->guides, g.previous->guides);
    EXPECT_EQ(f.guides->current.dt, g.current.dt);
    ASSERT_EQ(f.guides->current.pins.size(), 2u);
    EXPECT_EQ(f.guides->current.pins[1].vertex, 290u);
    EXPECT_EQ(f.guides->current.pins[1].last, g.current.pins[1].last);
    // A version 1 file (whole strands) reads through the same function.
    writeStrandCache(dir / "w.hpc", sample(true));
    const StrandCacheFile w = readStrandCacheFile(dir / "w.hpc");
    EXPECT_EQ(w.version, kStrandCacheVersion);
    EXPECT_FALSE(w.guides);
    expectIdentical(w.strands, sample(true));
    // readStrandCache (whole frames only) says why it refuses version 2.
    EXPECT_NE(errorOf(dir / "g.hpc").find("rebuilds the followers"), std::string::npos) << errorOf(dir / "g.hpc");
    // A pin outside the follower block is refused.
    g.current.pins[1].vertex = 400;
    writeGuideCache(dir / "bad.hpc", g);
    EXPECT_THROW(readStrandCacheFile(dir / "bad.hpc"), AssetError);
}

TEST(StrandCache, GuideCacheRebuildsTheWholeFramesAndTheSameOutputs) {
    // The same small shot cached whole (cache.followers: store, version 1)
    // and as guides (rebuild, version 2): the rebuilt frames are the whole
    // frames bit for bit, in any reading order, and the preview, reference
    // and VDB (density and velocity) rendered from either cache are identical.
    test::TempDir dir;
    const fs::path scene = test::writeSmallScene(dir.path());
    ASSERT_EQ(test::runHairpipe("sim -q " + test::q(scene) + " --out " + test::q(dir / "whole") +
                                " --set cache.followers=store")
                  .exitCode,
              0);
    ASSERT_EQ(test::runHairpipe("sim -q " + test::q(scene) + " --out " + test::q(dir / "guides")).exitCode, 0);
    const uintmax_t whole = cacheBytes(dir / "whole", 6), guides = cacheBytes(dir / "guides", 6);
    EXPECT_LT(guides * 5, whole) << "the guide cache is a fraction of the whole strands";
    std::printf("strand cache of 6 frames: whole %ju bytes, guides %ju bytes\n", whole, guides);

    const Scene s = Scene::load(scene);
    RunOptions options;
    options.outputDir = dir / "guides";
    const ShotSettings shot = resolveShot(s, options);
    CachedStrands cached(s, shot);
    for (int frame : {4, 2, 3, 1, 6, 5, 6}) {  // from scratch, in order, and again
        char name[64];
        std::snprintf(name, sizeof name, "whole/cache/strands.%04d.hpc", frame);
        const StrandFrame expected = readStrandCache(dir / name);
        expectIdentical(cached.read(frame), expected);
    }
    for (const char* out : {"whole", "guides"}) {
        const test::ProcessResult r = test::runHairpipe("run -q " + test::q(scene) + " --out " + test::q(dir / out) +
                                                  " --cache-only --stages preview,reference,vdb");
        ASSERT_EQ(r.exitCode, 0) << r.output;
    }
    std::vector<std::string> compared;
    for (const std::string& f : test::outputFiles(dir / "whole")) {
        if (f.rfind("cache/", 0) == 0) continue;
        test::expectSameFile(dir / "whole", dir / "guides", f);
        compared.push_back(f);
    }
    for (const char* f : {"preview/preview.0006.exr", "reference/reference.0005.exr", "vdb/hair.0006.vdb"})
        EXPECT_NE(std::find(compared.begin(), compared.end(), f), compared.end()) << f << " was not compared";
}
