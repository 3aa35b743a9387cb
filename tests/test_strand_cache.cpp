#include "core/errors.h"
#include "pipeline/batch/strand_cache.h"
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
