// @brief The guide-root triangulation that barycentric followers read
// (FollowerMode::Barycentric): three guides per follower instead of
// Gomes 2024's two, so followers fill the volume between guides instead of lying
// on the ruled sheets between guide pairs (issue 19, item 5).
//
// Scalp roots lie on a curved surface, so they are mapped to a plane first:
// a sphere fitted to the roots by linear least squares,
//   |p|² = 2 c · p + k   (unknowns c, k),
// then the azimuthal equidistant map about the mean root direction m from c,
//   u = (p - c)/|p - c|,  θ = acos(u · m),  x = θ (cos α, sin α)
// (α the azimuth of u about m), which keeps a cap of the head up to nearly
// the whole sphere one-to-one. Roots close to a plane (the sphere fit's
// radius beyond 100 times the roots' extent) use the plane of their two
// largest principal axes instead. The 2D Delaunay triangulation of the
// mapped roots (Bowyer-Watson, points inserted in index order, in-circle
// tests in double) is the triangulation: deterministic, and neighbouring
// followers in one triangle share their three guides, so the interpolation
// is continuous across shared edges.
#pragma once

#include "sim/followers/follower_neighbours.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace hp {

class GuideTriangulation {
  public:
    /// Triangulates `roots` (guide root positions). Fewer than three roots,
    /// or roots all on one line, give no triangles (locate() then returns
    /// the nearest root with weight 1).
    explicit GuideTriangulation(std::vector<Vec3f> roots);

    /// Three guides over `p` and their barycentric weights in the mapped
    /// plane, ordered by weight (largest first, ties by index); weights are
    /// >= 0 and sum to 1. A point outside the triangulation takes the
    /// triangle, among those around its 8 nearest roots, it is least outside
    /// of, with negative weights clamped to 0 and the rest renormalised.
    struct Location {
        std::array<uint32_t, 3> guide{{0, 0, 0}};
        std::array<float, 3> weight{{1.f, 0.f, 0.f}};
    };
    Location locate(const Vec3f& p) const;

    const std::vector<std::array<uint32_t, 3>>& triangles() const { return triangles_; }
    /// The mapped position of `p` (exposed for tests).
    Eigen::Vector2d map(const Vec3f& p) const;

  private:
    PointGrid grid_;
    std::vector<Eigen::Vector2d> mapped_;
    std::vector<std::array<uint32_t, 3>> triangles_;
    std::vector<std::vector<uint32_t>> incident_;  ///< triangles around each root
    bool planar_ = true;
    Eigen::Vector3d centre_ = Eigen::Vector3d::Zero(), pole_ = Eigen::Vector3d::UnitY();
    Eigen::Vector3d axis1_ = Eigen::Vector3d::UnitX(), axis2_ = Eigen::Vector3d::UnitZ();
};

}  // namespace hp
