#include "sim/strands/synthetic.h"

#include "sim/strands/fibonacci.h"

#include <algorithm>

namespace hp {

StrandFrame makeSyntheticHair(const SyntheticHairSettings& s) {
    StrandFrame frame;
    const std::vector<Vec3f> roots = fibonacciCap(s.strands, Vec3f::UnitY(), s.capMinCosine);
    const int n = std::max(2, s.vertices);
    const float segment = s.length / float(n - 1);
    frame.reserve(roots.size(), size_t(n));
    std::vector<Vec3f> p(n);
    std::vector<float> r(n);
    for (size_t i = 0; i < roots.size(); ++i) {
        const Vec3f normal = roots[i];
        p[0] = normal * s.headRadius;
        for (int k = 1; k < n; ++k) {
            // Blend from the normal toward straight down along the strand.
            const float w = s.droop * float(k) / float(n - 1);
            Vec3f d = ((1.f - w) * normal + w * Vec3f(0.f, -1.f, 0.f));
            if (d.squaredNorm() < 1e-8f) d = normal;
            p[k] = p[k - 1] + segment * d.normalized();
            // Keep the strand outside the head (sliding over it like hair).
            const float dist = p[k].norm();
            const float minDist = s.headRadius + 0.5f * s.rootRadius;
            if (dist < minDist) p[k] *= minDist / dist;
        }
        for (int k = 0; k < n; ++k) r[k] = taperedRadius(s.rootRadius, s.tipRadius, float(k) / float(n - 1));
        frame.addStrand(uint32_t(i), p.data(), r.data(), size_t(n));
    }
    frame.guideCount = 0;
    return frame;
}

}  // namespace hp
