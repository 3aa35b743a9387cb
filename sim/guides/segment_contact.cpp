#include "sim/guides/segment_contact.h"

namespace hp::strand {

void separateSegments(Vec3f& a0, Vec3f& a1, Vec3f& b0, Vec3f& b1, float s, float t, const Vec3f& normal,
                      float depth, const float w[4]) {
    const float alpha[2] = {1.f - s, s};
    const float beta[2] = {1.f - t, t};
    const float denom = w[0] * alpha[0] * alpha[0] + w[1] * alpha[1] * alpha[1] + w[2] * beta[0] * beta[0] +
                        w[3] * beta[1] * beta[1];
    if (denom <= 0.f) return;
    const float lambda = depth / denom;
    a0 += w[0] * alpha[0] * lambda * normal;
    a1 += w[1] * alpha[1] * lambda * normal;
    b0 -= w[2] * beta[0] * lambda * normal;
    b1 -= w[3] * beta[1] * lambda * normal;
}

}  // namespace hp::strand
