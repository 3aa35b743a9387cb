#include "sim/followers/follower_neighbours.h"

#include "core/errors.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

namespace hp {

namespace {

// Keeps the k best (distance², index) pairs sorted; k is small (2..16).
struct Best {
    int k, count = 0;
    uint32_t* index;
    float* dist2;

    float bound() const { return count < k ? std::numeric_limits<float>::infinity() : dist2[k - 1]; }
    void offer(float d2, uint32_t i) {
        if (count == k && !(d2 < dist2[k - 1] || (d2 == dist2[k - 1] && i < index[k - 1]))) return;
        int pos = count < k ? count++ : k - 1;
        while (pos > 0 && (d2 < dist2[pos - 1] || (d2 == dist2[pos - 1] && i < index[pos - 1]))) {
            dist2[pos] = dist2[pos - 1];
            index[pos] = index[pos - 1];
            --pos;
        }
        dist2[pos] = d2;
        index[pos] = i;
    }
};

}  // namespace

PointGrid::PointGrid(std::vector<Vec3f> points) : points_(std::move(points)) {
    if (points_.empty()) return;
    Eigen::AlignedBox3f box;
    for (const Vec3f& p : points_) {
        if (!p.allFinite()) throw Error("neighbour grid: non-finite root position");
        box.extend(p);
    }
    // Cell edge from the mean spacing of points spread over a surface:
    // area ~ (sum of the two largest extents)², two points per cell.
    Vec3f extent = box.sizes();
    std::sort(extent.data(), extent.data() + 3);
    const float span = std::max(extent[1] + extent[2], 1e-6f);
    cell_ = std::max(span * std::sqrt(2.f / float(points_.size())), 1e-6f);
    origin_ = box.min();
    for (int a = 0; a < 3; ++a)
        dims_[a] = std::clamp(int(std::floor(box.sizes()[a] / cell_)) + 1, 1, 512);
    // Re-derive the cell so the grid covers the box even when an axis was capped.
    for (int a = 0; a < 3; ++a) cell_ = std::max(cell_, box.sizes()[a] / float(dims_[a]) * 1.0001f);

    const size_t cells = size_t(dims_.x()) * dims_.y() * dims_.z();
    cellStart_.assign(cells + 1, 0);
    std::vector<uint32_t> cellOfPoint(points_.size());
    for (size_t i = 0; i < points_.size(); ++i) {
        const Eigen::Vector3i c = cellOf(points_[i]);
        cellOfPoint[i] = uint32_t(cellIndex(c.x(), c.y(), c.z()));
        ++cellStart_[cellOfPoint[i] + 1];
    }
    for (size_t c = 0; c < cells; ++c) cellStart_[c + 1] += cellStart_[c];
    order_.resize(points_.size());
    std::vector<uint32_t> fill(cellStart_.begin(), cellStart_.end() - 1);
    for (size_t i = 0; i < points_.size(); ++i) order_[fill[cellOfPoint[i]]++] = uint32_t(i);
}

Eigen::Vector3i PointGrid::cellOf(const Vec3f& p) const {
    Eigen::Vector3i c;
    for (int a = 0; a < 3; ++a) c[a] = std::clamp(int(std::floor((p[a] - origin_[a]) / cell_)), 0, dims_[a] - 1);
    return c;
}

int PointGrid::nearest(const Vec3f& query, int k, uint32_t* index, float* dist2) const {
    k = std::min<int>(k, int(points_.size()));
    if (k <= 0) return 0;
    Best best{k, 0, index, dist2};
    const Eigen::Vector3i c = cellOf(query);
    const int maxRing = std::max({c.x(), dims_.x() - 1 - c.x(), c.y(), dims_.y() - 1 - c.y(), c.z(),
                                  dims_.z() - 1 - c.z()});
    for (int r = 0; r <= maxRing; ++r) {
        // Visit the cells at Chebyshev distance exactly r from c.
        const int z0 = std::max(c.z() - r, 0), z1 = std::min(c.z() + r, dims_.z() - 1);
        const int y0 = std::max(c.y() - r, 0), y1 = std::min(c.y() + r, dims_.y() - 1);
        const int x0 = std::max(c.x() - r, 0), x1 = std::min(c.x() + r, dims_.x() - 1);
        auto visit = [&](int x, int y, int z) {
            const size_t cell = cellIndex(x, y, z);
            for (uint32_t j = cellStart_[cell]; j < cellStart_[cell + 1]; ++j) {
                const uint32_t i = order_[j];
                best.offer(distance2(query, points_[i]), i);
            }
        };
        for (int z = z0; z <= z1; ++z)
            for (int y = y0; y <= y1; ++y) {
                if (std::abs(z - c.z()) == r || std::abs(y - c.y()) == r) {
                    for (int x = x0; x <= x1; ++x) visit(x, y, z);
                } else {  // only the two x faces of the ring
                    if (c.x() - r >= 0) visit(c.x() - r, y, z);
                    if (r > 0 && c.x() + r < dims_.x()) visit(c.x() + r, y, z);
                }
            }
        // Any point outside the (2r+1)³ block is farther than the distance
        // from the query to the block's nearest open face.
        float reach = std::numeric_limits<float>::infinity();
        for (int a = 0; a < 3; ++a) {
            if (c[a] - r > 0) reach = std::min(reach, query[a] - (origin_[a] + float(c[a] - r) * cell_));
            if (c[a] + r < dims_[a] - 1) reach = std::min(reach, origin_[a] + float(c[a] + r + 1) * cell_ - query[a]);
        }
        if (reach == std::numeric_limits<float>::infinity()) break;  // the block covers the grid
        // The margin covers rounding in the cell assignment of points near a face.
        reach -= 1e-4f * cell_;
        if (best.count == k && reach > 0.f && best.bound() < reach * reach) break;
    }
    return best.count;
}

}  // namespace hp
