// Groom files: curves drawn in a DCC, read into plain polylines.
//
// Three formats, chosen by the file's extension:
// - `.obj`: polylines (`l` records) read through assimp, which returns them
//   as meshes of two-index line segments; the segments are chained back into
//   strands (groom_obj.cpp, the only groom source that includes assimp).
// - `.hair`: Cem Yuksel's binary hair format (little-endian; a 128-byte
//   header, then the segments, points, thickness, transparency and colour
//   arrays its flags announce). Only segments and points are used.
// - `.usda`: the BasisCurves subset `hairpipe export-usd` writes
//   (pipeline/stages/usd_export.cpp): one linear, non-periodic BasisCurves prim,
//   metres, Y up; its points, or the first of their time samples. Anything
//   else (another prim, cubic curves, other units) is rejected by line.
//
// Every reader checks what it reads before it allocates for it (a declared
// count is compared with the bytes the file holds), and every strand is
// checked: at least two points, all finite, not of zero length. Errors are
// AssetErrors naming the file and the problem.
#pragma once

#include "sim/strands/head.h"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace hp {

/// Polylines in file units and axes, StrandFrame-style offsets.
struct GroomCurves {
    std::vector<uint32_t> offsets{0};
    std::vector<Vec3f> points;

    size_t count() const { return offsets.size() - 1; }
    uint32_t size(size_t i) const { return offsets[i + 1] - offsets[i]; }
    /// Appends one strand of `n` points.
    void add(const Vec3f* p, size_t n);
};

/// Strands beyond this are refused before anything is allocated for them.
inline constexpr uint64_t kMaxGroomStrands = 10'000'000;
inline constexpr uint64_t kMaxGroomPoints = 400'000'000;

/// @brief Reads a groom file by its extension (.obj, .hair, .usda) and checks
/// its strands. Throws AssetError naming the file and the problem.
GroomCurves readGroomFile(const std::filesystem::path& path);

/// Decodes a whole `.hair` file (for readGroomFile and the fuzz target).
GroomCurves parseHairFile(const std::vector<char>& bytes, const std::string& name);
/// Decodes the `.usda` BasisCurves subset `export-usd` writes.
GroomCurves parseUsdaCurves(const std::string& text, const std::string& name);
/// OBJ polylines through assimp (groom_obj.cpp).
GroomCurves readObjCurves(const std::filesystem::path& path);

/// @brief Throws AssetError(name, ...) at the first strand with fewer than two
/// points, a non-finite point or zero length (all points equal).
void checkCurves(const GroomCurves& curves, const std::string& name);

}  // namespace hp
