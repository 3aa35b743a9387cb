// @brief Lights with size for the physical reference: sampling a light from a
// shading point, and finding it along a BSDF-sampled ray, with the solid-angle
// densities that multiple importance sampling needs (Veach and Guibas 1995,
// "Optimally Combining Sampling Techniques for Monte Carlo Rendering"; the
// light shapes as in Pharr, Jakob and Humphreys, "Physically Based Rendering",
// 4th ed. 2023, ch. 12).
//
// - Directional with angle α (angular diameter): a cone of half-angle
//   α/2 around the direction toward the light, uniform radiance
//   L = E / (π sin²(α/2)) for the light's irradiance E = intensity·colour,
//   sampled uniformly in the cone, pdf 1 / (2π (1 − cos(α/2))).
// - Quad and disk: one-sided Lambertian emitters facing `direction`,
//   L = intensity·colour / area, sampled uniformly by area, pdf
//   r² / (area · cos θ_l) per solid angle.
// - Point and directional without angle are delta lights: light-sampled only
//   (pdf reported as 0, and no ray can hit them).
#pragma once

#include "render/view/view.h"

#include <limits>

namespace hp {

/// One sample of a light seen from a point.
struct LightSample {
    Vec3f wi = Vec3f::Zero();            ///< unit, toward the light
    Vec3f radiance = Vec3f::Zero();      ///< delta: irradiance at the point; else emitted radiance
    float distance = std::numeric_limits<float>::infinity();  ///< to the sampled point on the light
    float pdf = 0.f;                     ///< solid-angle density; 0 for delta lights
    bool valid = false;                  ///< false where the light cannot reach the point
};

/// A world-space light with its frame and constants, ready for sampling.
class SampledLight {
  public:
    explicit SampledLight(const Light& light);

    const Light& light() const { return light_; }
    bool delta() const { return delta_; }
    /// A sample of the light from p, u uniform in [0, 1)².
    LightSample sample(const Vec3f& p, const Vec2f& u) const;
    /// Whether the ray o + t·d (unit d) meets the light before tmax (the
    /// scene's hit distance, ∞ for a miss); if so its radiance and the
    /// density sample() has for d from o.
    bool hit(const Vec3f& o, const Vec3f& d, float tmax, Vec3f* radiance, float* pdf) const;
    /// Max over RGB of the irradiance a delta light of the same intensity
    /// would give at p: the scale shadow-ray roulette compares against.
    float scale(const Vec3f& p) const;

  private:
    Light light_;
    bool delta_ = true;
    Vec3f normal_ = Vec3f::UnitZ();  ///< directional: toward the light; quad/disk: the way it faces
    Vec3f ex_ = Vec3f::UnitX(), ey_ = Vec3f::UnitY();
    float cosMax_ = 1.f;             ///< cone: cos of the half-angle
    float area_ = 0.f;
    Vec3f radiance_ = Vec3f::Zero(); ///< emitted radiance (lights with size)
};

}  // namespace hp
