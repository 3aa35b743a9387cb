#include "render/reference/path_splitting.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hp {

void SplitStats::add(double y, double i1, double i2, double c, double indirectCost) {
    n += 1.0;
    sumY += y, sumY2 += y * y;
    sumI2 += i1 * i1;
    sumSplit += 0.5 * (i1 - i2) * (i1 - i2);
    cost += c, costIndirect += indirectCost;
}

void SplitStats::add(const SplitStats& o) {
    n += o.n;
    sumY += o.sumY, sumY2 += o.sumY2;
    sumI2 += o.sumI2, sumSplit += o.sumSplit;
    cost += o.cost, costIndirect += o.costIndirect;
    devY += o.devY;
}

void SplitStats::centre() {
    // Σ(y − ȳ)² = Σy² − (Σy)² / n.
    devY = n > 0.0 ? std::max(0.0, sumY2 - sumY * sumY / n) : 0.0;
}

float efficientSplitRate(const SplitStats& s, float minRate, float maxRate) {
    if (!(s.n > 1.0) || !(s.sumI2 > 0.0) || !(s.costIndirect > 0.0)) return 1.f;
    const double inv = 1.0 / s.n;
    const double V = s.devY * inv;   // Var(Y)
    const double M = s.sumI2 * inv;  // E[I²]
    const double W = s.sumSplit * inv;  // E[Var(I | first hit)]
    const double c1 = s.costIndirect * inv;
    const double c0 = std::max(s.cost * inv - c1, 1e-3 * c1);  // at least the camera ray
    // Var − M ≤ 0: the indirect part is all of the noise, roulette only adds to it.
    const double rr = V > M ? std::sqrt(M * c0 / ((V - M) * c1)) : std::numeric_limits<double>::infinity();
    double r = 1.0;
    if (rr < 1.0)
        r = rr;
    else {
        const double split = V > W ? std::sqrt(W * c0 / ((V - W) * c1)) : std::numeric_limits<double>::infinity();
        if (split > 1.0) r = split;
    }
    return float(std::clamp(r, double(minRate), double(maxRate)));
}

int splitCount(float rate, float u) {
    const float whole = std::floor(rate);
    return int(whole) + (u < rate - whole ? 1 : 0);
}

std::vector<SplitStats> poolSplitStats(const std::vector<SplitStats>& stats, int width, int height, int radius) {
    // Separable box sums: rows, then columns (a fixed order, so the same bits
    // for any thread count).
    std::vector<SplitStats> centred = stats, rows(stats.size()), out(stats.size());
    for (SplitStats& s : centred) s.centre();
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            SplitStats& s = rows[size_t(y) * width + x];
            for (int dx = std::max(0, x - radius); dx <= std::min(width - 1, x + radius); ++dx)
                s.add(centred[size_t(y) * width + dx]);
        }
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            SplitStats& s = out[size_t(y) * width + x];
            for (int dy = std::max(0, y - radius); dy <= std::min(height - 1, y + radius); ++dy)
                s.add(rows[size_t(dy) * width + x]);
        }
    return out;
}

}  // namespace hp
