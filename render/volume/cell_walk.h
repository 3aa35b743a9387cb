// @brief Walks the unit cells a straight segment passes through (3D DDA,
// Amanatides & Woo 1987), reporting the parameter interval inside each cell.
//
// Shared by the voxelizer's box filter and DensityGrid's ray integrals, so
// both cut segments at exactly the same planes. The trilinear voxelizer
// (render/volume/voxel_tiles.cpp) writes the same walk out inline, started
// where a segment enters a tile, with the same plane formula.
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <limits>

namespace hp {

/// Calls visit(cell, t0, t1) for every unit cell [c, c+1)³ (c integer) that
/// the segment p(t) = a + t·(b − a), t ∈ [0, 1], crosses, in order along the
/// segment, with t0 < t1 the part of [0, 1] inside that cell. The intervals
/// partition [0, 1] (zero-length pieces at exact corner crossings are
/// skipped), so quantities integrated piecewise sum to the whole segment.
/// @param a, b  segment end points in cell units (finite)
template <typename Visit>
void walkCells(const Eigen::Vector3d& a, const Eigen::Vector3d& b, Visit&& visit) {
    const Eigen::Vector3d d = b - a;
    Eigen::Vector3i cell(int(std::floor(a.x())), int(std::floor(a.y())), int(std::floor(a.z())));
    int step[3];
    double tMax[3], inv[3];
    constexpr double kInf = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
        inv[k] = d[k] != 0 ? 1.0 / d[k] : 0.0;
        if (d[k] > 0) {
            step[k] = 1;
            tMax[k] = (cell[k] + 1 - a[k]) * inv[k];
        } else if (d[k] < 0) {
            step[k] = -1;
            tMax[k] = (cell[k] - a[k]) * inv[k];
        } else {
            step[k] = 0;
            tMax[k] = kInf;
        }
    }
    double t = 0;
    for (;;) {
        const int k = tMax[0] < tMax[1] ? (tMax[0] < tMax[2] ? 0 : 2) : (tMax[1] < tMax[2] ? 1 : 2);
        if (tMax[k] >= 1) {
            if (t < 1) visit(cell, t, 1.0);
            return;
        }
        if (tMax[k] > t) {
            visit(cell, t, tMax[k]);
            t = tMax[k];
        }
        // Recomputed from the plane rather than accumulated, so long segments
        // do not drift off the grid planes.
        cell[k] += step[k];
        tMax[k] = (cell[k] + (step[k] > 0 ? 1 : 0) - a[k]) * inv[k];
    }
}

}  // namespace hp
