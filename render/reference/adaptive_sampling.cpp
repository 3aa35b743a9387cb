#include "render/reference/adaptive_sampling.h"

#include <algorithm>
#include <cmath>

namespace hp {

float pixelError(const Eigen::Vector3d& meanAll, const Eigen::Vector3d& meanFirstHalf) {
    const double difference = (meanAll - meanFirstHalf).cwiseAbs().sum();
    const double normalize = std::sqrt(std::max(0.0, meanAll.sum()));
    return float(difference / (1e-4 + normalize));
}

void dilateActive(std::vector<uint8_t>& active, int width, int height, int radius) {
    if (radius <= 0) return;
    // Separable: rows, then columns (a square neighbourhood is a max filter
    // of a max filter).
    std::vector<uint8_t> tmp(active.size());
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            uint8_t a = 0;
            for (int dx = std::max(0, x - radius); dx <= std::min(width - 1, x + radius) && !a; ++dx)
                a = active[size_t(y) * width + dx];
            tmp[size_t(y) * width + x] = a;
        }
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            uint8_t a = 0;
            for (int dy = std::max(0, y - radius); dy <= std::min(height - 1, y + radius) && !a; ++dy)
                a = tmp[size_t(dy) * width + x];
            active[size_t(y) * width + x] = a;
        }
}

uint32_t ceilPowerOfTwo(uint32_t n) {
    uint32_t p = 1;
    while (p < n) p <<= 1;
    return p;
}

}  // namespace hp
