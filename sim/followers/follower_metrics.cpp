#include "sim/followers/follower_metrics.h"

#include "sim/followers/follower_neighbours.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace hp {

double medianNeighbourAngle(const StrandFrame& frame, size_t first) {
    std::vector<uint32_t> strands;
    for (size_t i = first; i < frame.strandCount(); ++i)
        if (frame.offsets[i + 1] - frame.offsets[i] >= 2) strands.push_back(uint32_t(i));
    if (strands.size() < 2) return 0.0;
    std::vector<Vec3f> roots(strands.size());
    std::vector<Eigen::Vector3d> tangents(strands.size());
    for (size_t k = 0; k < strands.size(); ++k) {
        const uint32_t a = frame.offsets[strands[k]], n = frame.offsets[strands[k] + 1] - a;
        const uint32_t mid = a + (n - 1) / 2;
        roots[k] = frame.positions[a];
        const Eigen::Vector3d d = (frame.positions[mid + 1] - frame.positions[mid]).cast<double>();
        tangents[k] = d.norm() > 0.0 ? Eigen::Vector3d(d.normalized()) : Eigen::Vector3d::Zero();
    }
    const PointGrid grid(roots);
    std::vector<double> angles(strands.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, strands.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t k = r.begin(); k != r.end(); ++k) {
            uint32_t index[2];
            float d2[2];
            grid.nearest(roots[k], 2, index, d2);
            // The strand itself is its own nearest unless another root coincides.
            const uint32_t other = index[0] == k ? index[1] : index[0];
            const double c = std::clamp(tangents[k].dot(tangents[other]), -1.0, 1.0);
            angles[k] = std::acos(c) * (180.0 / M_PI);
        }
    });
    const size_t m = (angles.size() - 1) / 2;
    std::nth_element(angles.begin(), angles.begin() + m, angles.end());
    return angles[m];
}

}  // namespace hp
