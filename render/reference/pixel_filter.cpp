#include "render/reference/pixel_filter.h"

#include <algorithm>

namespace hp {

const char* pixelFilterName(PixelFilterType type) { return type == PixelFilterType::Box ? "box" : "gaussian"; }

float erfInv(float x) {
    // Giles 2010, single precision: two polynomial branches in w = −ln(1 − x²).
    float w = -std::log((1.f - x) * (1.f + x));
    float p;
    if (w < 5.f) {
        w -= 2.5f;
        p = 2.81022636e-08f;
        p = 3.43273939e-07f + p * w;
        p = -3.5233877e-06f + p * w;
        p = -4.39150654e-06f + p * w;
        p = 0.00021858087f + p * w;
        p = -0.00125372503f + p * w;
        p = -0.00417768164f + p * w;
        p = 0.246640727f + p * w;
        p = 1.50140941f + p * w;
    } else {
        w = std::sqrt(w) - 3.f;
        p = -0.000200214257f;
        p = 0.000100950558f + p * w;
        p = 0.00134934322f + p * w;
        p = -0.00367342844f + p * w;
        p = 0.00573950773f + p * w;
        p = -0.0076224613f + p * w;
        p = 0.00943887047f + p * w;
        p = 1.00167406f + p * w;
        p = 2.83297682f + p * w;
    }
    return p * x;
}

namespace {

/// One axis of the truncated Gaussian: its CDF on [−r, r] is
/// (erf(x/(σ√2)) + c) / (2c) with c = erf(r/(σ√2)); inverted at u.
float sampleGaussian(float u, float sigma, float radius) {
    const float s = sigma * float(M_SQRT2);
    const float c = std::erf(radius / s);
    // Keep the argument inside (−1, 1) where erfInv is finite.
    const float a = std::clamp((2.f * u - 1.f) * c, -0.99999994f, 0.99999994f);
    return std::clamp(s * erfInv(a), -radius, radius);
}

}  // namespace

Eigen::Vector2f sampleFilterOffset(const PixelFilter& filter, const Eigen::Vector2f& u) {
    if (filter.type == PixelFilterType::Box)
        return {(2.f * u.x() - 1.f) * filter.radius, (2.f * u.y() - 1.f) * filter.radius};
    return {sampleGaussian(u.x(), filter.sigma, filter.radius), sampleGaussian(u.y(), filter.sigma, filter.radius)};
}

}  // namespace hp
