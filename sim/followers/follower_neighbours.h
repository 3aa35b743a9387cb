// @brief k-nearest guide roots for follower roots: a uniform grid over the
// guide roots searched in rings of cells, exact and deterministic.
//
// Gomes 2024 (section 4.5): "for each follower root, the distance to the guide
// roots; select, ordered, the two nearest neighbours". Brute force is
// F × G distance evaluations (400k × 845 = 3.4e8); the grid visits a few
// cells per follower. Ties are broken by guide index, so the result equals a
// brute-force sort by (squared distance, index) exactly.
#pragma once

#include "sim/strands/strand.h"

#include <cstdint>
#include <vector>

namespace hp {

/// Squared distance as every neighbour query computes it (one formula, so
/// the grid and a brute-force check agree to the last bit).
inline float distance2(const Vec3f& a, const Vec3f& b) {
    const float dx = a.x() - b.x(), dy = a.y() - b.y(), dz = a.z() - b.z();
    return dx * dx + dy * dy + dz * dz;
}

/// A fixed point set bucketed in a uniform grid (about two points per
/// occupied cell for points spread over a surface).
class PointGrid {
  public:
    explicit PointGrid(std::vector<Vec3f> points);

    /// The min(k, size()) points nearest to `query`, ordered by (squared
    /// distance, index): indices into `index`, squared distances into `dist2`
    /// (both arrays hold at least k entries). Returns how many were written.
    /// Thread-safe (const).
    int nearest(const Vec3f& query, int k, uint32_t* index, float* dist2) const;

    size_t size() const { return points_.size(); }
    const Vec3f& point(size_t i) const { return points_[i]; }

  private:
    Eigen::Vector3i cellOf(const Vec3f& p) const;
    size_t cellIndex(int x, int y, int z) const { return (size_t(z) * dims_.y() + y) * dims_.x() + x; }

    std::vector<Vec3f> points_;
    Vec3f origin_ = Vec3f::Zero();
    float cell_ = 1.f;
    Eigen::Vector3i dims_ = Eigen::Vector3i::Ones();
    std::vector<uint32_t> cellStart_;  ///< CSR: points of cell c are order_[cellStart_[c], cellStart_[c+1])
    std::vector<uint32_t> order_;
};

}  // namespace hp
