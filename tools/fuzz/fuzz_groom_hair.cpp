// libFuzzer target: the .hair groom reader (pipeline/groom/groom_file.h,
// parseHairFile + checkCurves). Any bytes must decode into curves whose
// offsets index their points, or throw AssetError; a declared count the
// bytes cannot hold must be refused before anything is allocated for it
// (the -rss_limit_mb of tools/fuzz/run catches an allocation that is not).
#include "tools/fuzz/fuzz_target.h"

#include "core/errors.h"
#include "pipeline/groom/groom_file.h"

#include <vector>

HP_FUZZ_TARGET(groom_hair)(const uint8_t* data, size_t size) {
    const std::vector<char> bytes(data, data + size);
    try {
        const hp::GroomCurves c = hp::parseHairFile(bytes, "fuzz.hair");
        HP_FUZZ_CHECK(!c.offsets.empty() && c.offsets.front() == 0 && c.offsets.back() == c.points.size());
        for (size_t s = 0; s < c.count(); ++s) HP_FUZZ_CHECK(c.offsets[s] <= c.offsets[s + 1]);
        HP_FUZZ_CHECK(c.points.size() * 12 <= size);  // never more points than the bytes hold
        hp::checkCurves(c, "fuzz.hair");
    } catch (const hp::Error&) {
    }
    return 0;
}
