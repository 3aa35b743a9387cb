// @brief Writes a DensityGrid as an OpenVDB file (and reads one back).
//
// The only place hairpipe includes OpenVDB (render/volume/vdb_writer.cpp), so its
// compile cost stays in one translation unit and this header stays plain.
//
// File layout, one file per frame:
// - "density": FloatGrid, grid class fog volume, background 0, a linear
//   transform equal to the DensityGrid's (uniform voxels of the scene's voxel
//   size: index (i,j,k) is the voxel centred at (i,j,k)·h in metres), values
//   in hair volume fraction × density_scale, only voxels with hair active.
//   Metadata: frame, time, fps, scene, units, voxel_size, strand_count,
//   hair_volume, filter, density_scale, creator.
// - "velocity" (optional): Vec3SGrid (vector type contravariant-relative),
//   m/s, the density-weighted mean velocity of the hair in each voxel, active
//   where density is.
//
// Deterministic bytes: OpenVDB stamps every file with a random UUID; the
// writer replaces it by a digest of what the file holds (voxel values,
// metadata, transform, options, OpenVDB version), so the same grid gives a
// byte-identical file (resume checks, caches, diffs). Nothing else in an
// OpenVDB 10 file varies between runs (no time stamps); file_mem_bytes and
// the other grid statistics follow from the tree.
#pragma once

#include "render/volume/density_grid.h"

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace hp {

/// Shot facts written as grid metadata.
struct VdbFrameInfo {
    int frame = 0;
    double time = 0.0;   ///< seconds
    double fps = 24.0;
    std::string scene;   ///< scene name
    size_t strandCount = 0;
    double hairVolume = 0.0;  ///< m³ (what the grid conserves); written for checks downstream
    std::string filter = "trilinear";
};

enum class VdbCompression {
    Blosc,  ///< Blosc LZ4 + active-mask compression (OpenVDB's default; read by Blender and Houdini)
    None,   ///< active-mask compression only (OpenVDB never zips fog volumes)
};

struct VdbWriteSettings {
    VdbCompression compression = VdbCompression::Blosc;
    bool halfFloat = false;      ///< store values as 16-bit floats (half the size; ~3 significant digits)
    double densityScale = 1.0;   ///< written value = hair volume fraction × densityScale
    bool velocity = true;        ///< write the "velocity" grid when the DensityGrid has one
};

/// @brief Writes `grid` to `file` (the caller makes it atomic: writeAtomically).
/// @throws IoError naming the file when OpenVDB cannot write it.
void writeDensityVdb(const std::filesystem::path& file, const DensityGrid& grid, const VdbFrameInfo& info,
                     const VdbWriteSettings& settings = {});
/// Same, consuming the grid: each block is freed as soon as OpenVDB holds a
/// copy, so peak memory is about one grid instead of two (the grid is left
/// empty).
void writeDensityVdb(const std::filesystem::path& file, DensityGrid&& grid, const VdbFrameInfo& info,
                     const VdbWriteSettings& settings = {});

/// One grid of a VDB file as read back.
struct VdbGridInfo {
    std::string name;
    std::string valueType;   ///< OpenVDB's type name: "float", "vec3s", ...
    std::string gridClass;   ///< "fog volume", "level set", "unknown", ...
    std::string vectorType;  ///< for vector grids ("contravariant relative", ...)
    bool savedAsHalf = false;
    double background = 0.0; ///< scalar grids
    Eigen::Matrix4d indexToWorld = Eigen::Matrix4d::Identity();  ///< column-vector convention
    double voxelSize = 0.0;  ///< voxel edge when all three index axes have that length, else 0
    size_t activeVoxels = 0;
    Vec3i activeMin = Vec3i::Zero(), activeMax = Vec3i::Zero();  ///< inclusive index bounds (if any active)
    /// Every grid metadata item as text (OpenVDB's str()), keyed by name.
    std::map<std::string, std::string> metadata;
    /// OpenVDB's type name of each metadata item ("int32", "double", "string", ...).
    std::map<std::string, std::string> metadataType;
};

struct VdbContents {
    std::vector<VdbGridInfo> grids;
    /// The "density" grid's values (and "velocity" if present) with its transform.
    DensityGrid density;
    bool hasDensity = false;
};

/// @brief Reads a VDB file through openvdb::io::File: every grid's
/// description, and the density (and velocity) values.
/// @throws AssetError naming the file when it cannot be read.
VdbContents readDensityVdb(const std::filesystem::path& file);

}  // namespace hp
