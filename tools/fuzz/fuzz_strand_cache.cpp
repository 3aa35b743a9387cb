// libFuzzer target: the strand-cache reader (pipeline/batch/strand_cache.h). Any
// bytes must decode into a frame that passes StrandFrame::validate() or throw
// AssetError.
//
// The file's last four bytes are a CRC-32 of the rest, checked before any
// field is decoded; a random mutation almost never matches it, so the target
// rewrites the CRC of every input (after the fixed 12-byte header) to let the
// fuzzer reach the decoder. The checksum test itself is a unit test
// (test_strand_cache).
#include "tools/fuzz/fuzz_target.h"

#include "core/errors.h"
#include "pipeline/batch/strand_cache.h"

#include <zlib.h>

#include <cstring>
#include <vector>

HP_FUZZ_TARGET(strand_cache)(const uint8_t* data, size_t size) {
    std::vector<char> bytes(data, data + size);
    if (bytes.size() >= 16) {
        const size_t body = bytes.size() - 4;
        const uint32_t c = uint32_t(crc32(crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(bytes.data()),
                                          uInt(body)));
        std::memcpy(bytes.data() + body, &c, 4);
    }
    try {
        const hp::StrandCacheFile file = hp::parseStrandCacheFile(bytes, "fuzz.hpc");
        // parseStrandCacheFile promises a consistent frame (version 1) or guide records (version 2).
        if (file.guides) {
            file.guides->current.guides.validate();
            if (file.guides->previous) file.guides->previous->guides.validate();
        } else {
            file.strands.validate();
        }
    } catch (const hp::Error&) {
    }
    return 0;
}
