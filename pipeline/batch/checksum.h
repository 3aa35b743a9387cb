// @brief CRC-32 (zlib's polynomial) of a byte range: the trailer of the
// strand cache and of the settled groom, so a truncated or corrupt file is
// refused instead of read.
#pragma once

#include <cstddef>
#include <cstdint>

namespace hp {

/// zlib's crc32 over `n` bytes, fed in pieces that fit zlib's uInt lengths.
uint32_t crc32Of(const char* data, size_t n);

}  // namespace hp
