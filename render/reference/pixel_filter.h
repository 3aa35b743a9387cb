// @brief The reference renderer's pixel filter, applied by filter importance
// sampling (Ernst, Stamminger and Greiner 2006, "Filter Importance Sampling";
// pbrt-v4's film does the same): each camera sample's offset from the pixel
// centre is drawn from the filter itself, and every sample then counts with
// weight one in its own pixel.
//
// Why: a box filter (one sample anywhere inside its pixel, as before) aliases
// the sub-pixel hair into jagged, flickering edges and makes two renders of
// the same frame disagree more than their noise. Splatting samples into
// several pixels with filter weights would correlate neighbouring pixels and
// break the per-pixel error estimate of adaptive sampling
// (render/reference/adaptive_sampling.h); drawing the offsets from the filter
// keeps every pixel an independent mean of its own samples.
//
// The Gaussian is pbrt-v4's default: σ = 0.5 px, truncated at radius 1.5 px,
// separable. Truncation without re-normalising is what drawing from the
// truncated distribution means, so the estimate is the filtered image of the
// truncated (normalised) Gaussian: unbiased for that filter.
#pragma once

#include <Eigen/Core>

#include <cmath>

namespace hp {

enum class PixelFilterType { Box, Gaussian };

/// "box" / "gaussian".
const char* pixelFilterName(PixelFilterType type);

struct PixelFilter {
    PixelFilterType type = PixelFilterType::Gaussian;
    float radius = 1.5f;  ///< half-width in pixels (box: 0.5 is one pixel)
    float sigma = 0.5f;   ///< Gaussian standard deviation in pixels
};

/// Inverse error function erf⁻¹(x) for x in (−1, 1), after Giles 2010,
/// "Approximating the erfinv function" (single-precision branch; relative
/// error below 4e-7 across the range used here).
float erfInv(float x);

/// Offset (pixels, each axis in [−radius, radius]) of the sample drawn
/// from `filter` for the uniform pair u in [0, 1)²: the inverse CDF of the
/// filter's (truncated, separable) marginal along each axis.
Eigen::Vector2f sampleFilterOffset(const PixelFilter& filter, const Eigen::Vector2f& u);

}  // namespace hp
