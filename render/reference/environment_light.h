// @brief The environment as a light of the physical reference: a constant
// radiance plus an HDR lat-long map (View::environment, View::environmentMap),
// importance-sampled by a piecewise-constant 2D distribution over the map's
// pixels, proportional to luminance × sin θ (marginal CDF over rows,
// conditional CDF over the columns of each row), as in Pharr, Jakob and
// Humphreys, "Physically Based Rendering", 3rd ed. 2016, §13.6.7 and §14.2.4.
//
// A pixel (i, j) of a W × H map covers u ∈ [i/W, (i+1)/W), v ∈ [j/H, (j+1)/H)
// with φ = 2π u − π, θ = π v; the density over (u, v) is
//   p(u, v) = f(i, j) / (Σ f / (W H)),   f = luminance(L(i, j)) · sin θ_j,
// and per solid angle (dω = 2π² sin θ du dv)
//   p(ω) = p(u, v) / (2π² sin θ).
// Radiance is looked up per pixel (no interpolation), so L / p(ω) stays
// bounded. Without a map the constant gets a 64 × 32 grid of its own, which
// makes sample() nearly uniform over the sphere; the path tracer then gathers
// the constant sky by BSDF sampling alone (reference_shading.cpp says why).
#pragma once

#include "render/reference/light_sampling.h"
#include "render/view/view.h"

#include <string>
#include <vector>

namespace hp {

/// Reads an HDR lat-long image through OpenImageIO (render/image/image_io.h)
/// into an EnvironmentMap: RGB (a grey image fills all three), negative and
/// non-finite values clamped to 0, the mean computed. Throws AssetError
/// naming the file when it is missing or not an image.
EnvironmentMap loadEnvironmentMap(const std::string& path, float intensity, float rotationDegrees);

/// Direction of map coordinates (u, v) in [0, 1]², before the map's
/// rotation, and back: the lat-long convention of EnvironmentMap.
Vec3f latLongDirection(float u, float v);
Vec2f latLongCoordinates(const Vec3f& dir);

class EnvironmentLight {
  public:
    EnvironmentLight(const Vec3f& constant, const EnvironmentMap& map);

    /// False for a black environment (nothing to sample or add).
    bool active() const { return active_; }
    /// Whether there is a map (else the sky is one constant colour).
    bool hasMap() const { return hasMap_; }
    /// Radiance arriving from unit direction `dir` (the sky seen that way).
    Vec3f radiance(const Vec3f& dir) const;
    /// A direction drawn from the distribution (u uniform in [0, 1)²), its
    /// radiance and solid-angle density; distance ∞.
    LightSample sample(const Vec2f& u) const;
    /// Solid-angle density of sample() producing `dir`.
    float pdf(const Vec3f& dir) const;

    int width() const { return width_; }
    int height() const { return height_; }

  private:
    Vec2f toMap(const Vec3f& dir) const;    ///< world direction to (u, v), with the rotation
    Vec3f fromMap(const Vec2f& uv) const;   ///< and back
    float pdfUv(int i, int j) const;

    bool active_ = false;
    bool hasMap_ = false;
    int width_ = 0, height_ = 0;
    float cosRot_ = 1.f, sinRot_ = 0.f;
    std::vector<Vec3f> radiance_;       ///< per pixel: constant + intensity × map
    std::vector<float> conditionalCdf_; ///< per row, width_ + 1 values from 0 to 1
    std::vector<float> rowSum_;         ///< Σ f over each row
    std::vector<float> marginalCdf_;    ///< height_ + 1 values from 0 to 1
    float total_ = 0.f;                 ///< Σ f over the map
};

}  // namespace hp
