// Kept fuzzer inputs (tests/data/fuzz/<target>/: seeds and every crasher the
// fuzzers found, docs/hardening.md) replayed through the fuzz targets' own
// entry points (tools/fuzz/fuzz_*.cpp, compiled here under the names
// fuzz_<target>). Each input must be handled without a crash or an escaping
// non-hairpipe exception; under the sanitizer build (tools/sanitize/run) also
// without a memory or UB report.
#define HP_FUZZ_TARGET(name) static int fuzz_##name
#include "tools/fuzz/fuzz_asset.cpp"
#include "tools/fuzz/fuzz_frame_range.cpp"
#include "tools/fuzz/fuzz_groom_hair.cpp"
#include "tools/fuzz/fuzz_scene.cpp"
#include "tools/fuzz/fuzz_strand_cache.cpp"

#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>

namespace fs = std::filesystem;
using namespace hp::test;

namespace {

/// Feeds every file of tests/data/fuzz/<target>/ to `entry`; returns how many.
size_t replay(const std::string& target, const std::function<int(const uint8_t*, size_t)>& entry) {
    const fs::path dir = sourcePath("tests/data/fuzz/" + target);
    std::vector<fs::path> files;
    if (fs::is_directory(dir))
        for (const auto& e : fs::directory_iterator(dir))
            if (e.is_regular_file()) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files) {
        const std::string bytes = readFile(f);
        EXPECT_NO_THROW(entry(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size())) << f;
    }
    return files.size();
}

}  // namespace

TEST(FuzzRegressions, StrandCacheInputs) { EXPECT_GE(replay("strand_cache", fuzz_strand_cache), 1u); }

TEST(FuzzRegressions, FrameRangeInputs) { EXPECT_GE(replay("frame_range", fuzz_frame_range), 1u); }

TEST(FuzzRegressions, SceneInputs) { EXPECT_GE(replay("scene", fuzz_scene), 1u); }

TEST(FuzzRegressions, AssetInputs) { EXPECT_GE(replay("asset", fuzz_asset), 1u); }

TEST(FuzzRegressions, GroomHairInputs) { EXPECT_GE(replay("groom_hair", fuzz_groom_hair), 1u); }

// The entry points themselves must tell a bad input from a good one, or the
// replay above proves nothing: a valid cache decodes, a property violation
// escapes as a non-hairpipe exception.
TEST(FuzzRegressions, EntryPointsReportViolations) {
    const std::string good = "1-10x3,20";
    EXPECT_EQ(fuzz_frame_range(reinterpret_cast<const uint8_t*>(good.data()), good.size()), 0);
    EXPECT_THROW(HP_FUZZ_CHECK(1 + 1 == 3), std::logic_error);
}
