// Generated hair (Dehlin and Styngberg 2017, "Badhairday"): short hair and fur grown on the GPU
// from the head mesh itself, with no simulation. The region's triangles are
// tessellated as PN triangles (cubic Bezier positions, quadratic normals) and
// one strand is grown per generated triangle in a geometry shader, bending
// toward a force (gravity + gusting wind) segment by segment (shaders/fur.*).
// This file holds the plain settings and the CPU side: which triangle grows
// which hair type.
#pragma once

#include "sim/strands/head.h"

#include <cstdint>
#include <vector>

namespace hp {

/// One kind of generated hair (a row of the hair-type texture the shaders read).
struct HairType {
    Vec3f color{0.85f, 0.8f, 0.7f};  ///< diffuse albedo (linear); replaces the hair material's colour
    int segments = 4;                 ///< 1..kMaxHairSegments; fewer segments = stiffer hair (seed, fig. 5)
    float segmentLength = 0.004f;     ///< metres
    float forceWeight = 1.f;          ///< scales the force added to the direction at each segment
    float rootRadius = 0.00004f;      ///< metres
    float tipRadius = 0.00001f;
};

inline constexpr int kMaxHairSegments = 16;  ///< fixed by the geometry shader's output size

/// Where a hair type grows. Regions apply in order; a later one overrides an
/// earlier one on the triangles they share.
struct HairRegion {
    enum class Shape { All, Cap, Mask };
    Shape shape = Shape::Cap;
    int type = 0;                 ///< index into GeneratedHairSettings::types
    Vec3f axis{0.f, 1.f, 0.f};    ///< Cap: direction from the head's centre, in the head's rest frame
    float angle = 60.f;           ///< Cap: half-angle, degrees (180 = everywhere)
};

struct GeneratedHairSettings {
    bool enabled = false;
    std::vector<HairType> types;
    std::vector<HairRegion> regions;
    int innerLevel = 4;           ///< tessellation levels of the region's triangles (1..64)
    int outerLevel = 4;
    Vec3f gravity{0.f, -0.2f, 0.f};  ///< dimensionless: added to the unit growth direction per segment
    Vec3f wind{0.1f, 0.f, 0.f};      ///< same units; gusts travel along it
    float gust = 0.5f;               ///< relative gust strength
    float gustFrequency = 0.5f;      ///< Hz
    float gustWavelength = 0.25f;    ///< metres between gust fronts along the wind

    /// Longest strand any type grows (metres), to pad bounds.
    float maxLength() const;
};

/// Dehlin and Styngberg 2017's force vector at `time` for a strand rooted at `root`:
/// gravity + wind * (1 + gust * sin(2 pi (f t - (root . wind_dir) / wavelength))).
/// shaders/fur.geom evaluates the same expression.
Vec3f hairForce(const GeneratedHairSettings& s, double time, const Vec3f& root);

/// Per-triangle hair type of `mesh`: 0 = none, k = types[k-1]. Cap regions test
/// the direction of each triangle's centroid from the mesh's centre in the
/// rest frame (`toRest` maps world to rest space, the inverse of the head
/// pose), so the region sticks to a moving head. `scalpMask` (one entry per
/// triangle, non-zero = scalp, from head import) serves Mask regions.
/// Throws hp::Error when a Mask region has no mask or a type index is out of range.
std::vector<uint8_t> assignHairTypes(const TriangleMesh& mesh, const GeneratedHairSettings& s,
                                     const Eigen::Isometry3f& toRest, const std::vector<uint8_t>* scalpMask);

}  // namespace hp
