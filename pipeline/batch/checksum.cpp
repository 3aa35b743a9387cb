#include "pipeline/batch/checksum.h"

#include <zlib.h>

#include <algorithm>
#include <limits>

namespace hp {

uint32_t crc32Of(const char* data, size_t n) {
    uLong c = crc32(0L, Z_NULL, 0);
    while (n > 0) {
        const uInt chunk = uInt(std::min<size_t>(n, std::numeric_limits<uInt>::max()));
        c = crc32(c, reinterpret_cast<const Bytef*>(data), chunk);
        data += chunk;
        n -= chunk;
    }
    return uint32_t(c);
}

}  // namespace hp
