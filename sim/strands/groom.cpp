#include "sim/strands/groom.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace hp {

std::vector<std::vector<Vec3f>> groomStrands(const std::vector<SurfaceFrame>& roots, const GroomSettings& s,
                                             const Collider* head) {
    std::vector<std::vector<Vec3f>> strands(roots.size());
    const int n = std::max(1, s.segments);
    const float segment = s.length / float(n);
    const Vec3f comb = s.direction.norm() > 0.f ? Vec3f(s.direction.normalized()) : Vec3f(0.f, -1.f, 0.f);
    tbb::parallel_for(size_t(0), roots.size(), [&](size_t g) {
        const Vec3f& normal = roots[g].normal;
        std::vector<Vec3f>& p = strands[g];
        p.resize(size_t(n) + 1);
        p[0] = roots[g].position;
        for (int k = 0; k < n; ++k) {
            Vec3f d = normal;
            if (s.style == GroomStyle::Combed) {
                // Smoothstep from the normal toward the comb direction: the
                // strand leaves the scalp upright and bends over gradually.
                const float t = float(k) / float(std::max(1, n - 1));
                const float w = s.droop * t * t * (3.f - 2.f * t);
                d = (1.f - w) * normal + w * comb;
                if (d.squaredNorm() < 1e-8f) d = normal;
                d.normalize();
            }
            Vec3f next = p[k] + segment * d;
            if (head && s.style == GroomStyle::Combed && k > 0) {
                // Lift the segment's end out of the head, keeping its length:
                // push out along the distance gradient, then renormalise.
                for (int it = 0; it < 4; ++it) {
                    Vec3f gradient;
                    const float dist = head->signedDistance(next, &gradient);
                    if (dist >= s.clearance) break;
                    next += (s.clearance - dist) * gradient;
                    next = p[k] + segment * (next - p[k]).normalized();
                }
            }
            p[k + 1] = next;
        }
    });
    return strands;
}

}  // namespace hp
