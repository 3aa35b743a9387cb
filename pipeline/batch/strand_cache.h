// The strand cache: one file per frame, written by `hairpipe sim` and read by
// every later stage, so rendering, VDB export and comparison of any frame
// subset run independently (and on other machines). Two versions, both read:
//
// Version 2 (cache.followers: rebuild, the default): the guides only, and the
// one piece of follower state a frame carries to the next (the pinned
// vertices' previous places, FollowerStats::pins). Followers are a pure
// function of the guides, the head's pose and that state (sim/followers/), so
// a reader rebuilds them bit for bit (pipeline/stages/cached_strands.h). A
// frame whose followers take velocities by difference also holds the frame
// before it (its guides and pins), so every file is rebuilt on its own. About
// 0.4 MB a frame for 300 guides, whatever the follower count.
//
// Version 1 (cache.followers: store): every strand, whole (about 650 bytes a
// 24-vertex strand: 650 MB a frame at 1M followers).
//
// Format (little-endian):
//   char[8]  magic "HPSTRAND"
//   u32      version (1 or 2)
//   u32      flags            bit 0: velocities present
//   i32      frame
//   u32      guide count G
//   f64      time (s)
//   u64      strand count S   (the whole frame's, followers included)
//   u64      vertex count V   (likewise)
//   version 1:
//     u32[S+1] offsets, u32[S] ids, f32[3V] positions (m), f32[V] radii (m),
//     f32[3V] velocities (m/s) if flagged
//   version 2: a guide record of this frame, u8 1 when a record of the
//   previous frame follows (0 otherwise), that record. A guide record:
//     i32 frame, f64 time (s), f64 dt (s since the followers' previous frame;
//     0: none, velocities blended from the guides), u64 guide vertex count W,
//     u32[G+1] offsets, u32[G] ids, f32[3W] positions, f32[W] radii,
//     f32[3W] velocities if flagged, u32 pin count P, P × (u32 vertex in the
//     follower block, f32[3] its previous place)
//   u32      CRC-32 (zlib) of every byte before it
// Readers reject a wrong magic, an unknown version, sizes that disagree with
// the file length and a checksum mismatch, naming the file.
#pragma once

#include "sim/followers/followers.h"
#include "sim/strands/strand.h"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace hp {

inline constexpr uint32_t kStrandCacheVersion = 1;  ///< whole strands
inline constexpr uint32_t kGuideCacheVersion = 2;   ///< guides + follower pins

/// One frame's guides and the follower state it carries from the frame
/// before: with the head's pose at `guides.time`, what rebuilds its followers.
struct FollowerSource {
    StrandFrame guides;  ///< the guide strands only (guideCount = strand count), frame and time set
    /// Seconds since the followers' previous frame when they took velocities
    /// by difference from it; 0: no previous frame (velocities blended).
    double dt = 0.0;
    std::vector<FollowerPin> pins;  ///< FollowerStats::pins of this frame
};

/// A version 2 file's content.
struct CachedGuides {
    uint64_t strands = 0, vertices = 0;  ///< of the whole frame, followers included
    FollowerSource current;
    /// The frame before (needed when current.dt > 0: its positions feed the
    /// velocities and the pins' places).
    std::optional<FollowerSource> previous;
};

/// A cache file: version 1 gives `strands`, version 2 `guides`.
struct StrandCacheFile {
    uint32_t version = 0;
    StrandFrame strands;
    std::optional<CachedGuides> guides;
};

/// Writes `frame` whole (version 1) to `path` (directly; callers use writeAtomically).
void writeStrandCache(const std::filesystem::path& path, const StrandFrame& frame);

/// Writes the guides and follower state of a frame (version 2).
void writeGuideCache(const std::filesystem::path& path, const CachedGuides& guides);

/// Reads a version 1 file; throws AssetError naming the file and the problem
/// (a version 2 file is refused: its followers must be rebuilt, see
/// pipeline/stages/cached_strands.h).
StrandFrame readStrandCache(const std::filesystem::path& path);

/// Reads a cache file of either version; throws AssetError naming the file.
StrandCacheFile readStrandCacheFile(const std::filesystem::path& path);

/// Decodes a whole cache file's bytes (what readStrandCacheFile does after
/// reading the file); `name` is the file named in errors. For tools and the
/// fuzz target (tools/fuzz/fuzz_strand_cache.cpp).
StrandCacheFile parseStrandCacheFile(const std::vector<char>& data, const std::string& name);

}  // namespace hp
