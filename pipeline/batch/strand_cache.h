// The strand cache: one file per frame holding a whole StrandFrame, written by
// `hairpipe sim` and read by every later stage, so rendering, VDB export and
// comparison of any frame subset run independently (and on other machines).
//
// Format (little-endian, version 1):
//   char[8]  magic "HPSTRAND"
//   u32      version
//   u32      flags            bit 0: velocities present
//   i32      frame
//   u32      guide count
//   f64      time (s)
//   u64      strand count S
//   u64      vertex count V
//   u32[S+1] offsets
//   u32[S]   ids
//   f32[3V]  positions (m)
//   f32[V]   radii (m)
//   f32[3V]  velocities (m/s), if flagged
//   u32      CRC-32 (zlib) of every byte before it
// Readers reject a wrong magic, an unknown version, sizes that disagree with
// the file length and a checksum mismatch, naming the file.
#pragma once

#include "sim/strands/strand.h"

#include <filesystem>
#include <string>
#include <vector>

namespace hp {

inline constexpr uint32_t kStrandCacheVersion = 1;

/// Writes `frame` to `path` (directly; callers use writeAtomically).
void writeStrandCache(const std::filesystem::path& path, const StrandFrame& frame);

/// Reads a cache file; throws AssetError naming the file and the problem.
StrandFrame readStrandCache(const std::filesystem::path& path);

/// Decodes a whole cache file's bytes (what readStrandCache does after
/// reading the file); `name` is the file named in errors. For tools and the
/// fuzz target (tools/fuzz/fuzz_strand_cache.cpp).
StrandFrame parseStrandCache(const std::vector<char>& data, const std::string& name);

}  // namespace hp
