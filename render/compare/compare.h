// Comparison of two renders of the same frame (typically the GL preview
// against the Embree reference): error metrics and difference images.
//
// Inputs are linear RGB(A) images (render/image/image_io.h; 8-bit files are
// linearised when read). Every metric looks at the *display values*: each of
// R, G, B clamped to [0, 1] (NaN → 0, +∞ → 1), i.e. what an sRGB display
// shows at exposure 1. HDR values above 1 therefore compare as 1: the metrics
// judge the picture a lighting artist sees, and PSNR's peak is well defined.
// Colour is compared as stored (premultiplied over black); A is only the mask.
//
// Metrics (FrameMetrics), each over all pixels or over the mask:
// - RMSE: sqrt(mean over pixels and R, G, B of (a − b)²), computed by
//   OpenImageIO's ImageBufAlgo::compare. 0 = identical; lower is better.
// - PSNR: 20·log10(1 / RMSE) dB (peak 1, as OpenImageIO defines it); +∞ for
//   identical images; higher is better. Gaussian noise of σ gives ≈ 20·log10(1/σ).
// - SSIM: mean of the SSIM map (render/compare/ssim.h: Gaussian window σ = 1.5,
//   11×11, K1 = 0.01, K2 = 0.03, L = 1) on luma: the luminance
//   0.2126R + 0.7152G + 0.0722B of the display values, sRGB-encoded — SSIM's
//   constants assume gamma-encoded values, and dark hair would otherwise sit
//   in the range where C1, C2 swamp the signal. 1 = identical; it falls with
//   noise and blur far more than with a uniform brightness change.
// - FLIP: mean of the LDR-FLIP error map (render/compare/flip.h) of B (test) against
//   A (reference), in [0, 1]; 0 = indistinguishable when flipping between them.
// - maxError: largest per-channel |a − b| (OpenImageIO's compare).
//
// Mask (MaskMode::Hair): the pixels whose alpha is > 0 in either image. The
// SSIM and FLIP maps are still computed on the whole frame (their filters need
// the surroundings); only the averages are restricted to the mask.
#pragma once

#include "render/compare/flip.h"
#include "render/image/image_io.h"

#include <string>

namespace hp {

enum class MaskMode { None, Hair };

struct CompareSettings {
    MaskMode mask = MaskMode::None;
    FlipSettings flip;
};

/// Metrics of one frame pair (definitions above). With an empty mask every
/// metric reports "identical" (RMSE 0, PSNR +∞, SSIM 1, FLIP 0) and pixels = 0.
struct FrameMetrics {
    long pixels = 0;  ///< pixels the averages cover (mask size, or width·height)
    double rmse = 0;
    double psnr = 0;  ///< dB; +∞ when rmse == 0
    double maxError = 0;
    double ssim = 1;
    double flip = 0;
};

/// Metrics plus the per-pixel maps behind them.
struct Comparison {
    FrameMetrics metrics;
    ImagePlane flipMap;  ///< LDR-FLIP error per pixel, [0, 1]
    ImagePlane ssimMap;  ///< SSIM per pixel
    ImagePlane mask;     ///< 1 inside the mask, 0 outside (all 1 for MaskMode::None)
    Image absDiff;  ///< |a − b| of the display values, channels R, G, B
};

/// Compares `test` (B) against `reference` (A). Images without R, G, B
/// channels compare as grey from their Y (or first) channel. Throws Error
/// when the sizes differ or the mask needs an alpha channel that neither
/// image has; callers add the file names.
Comparison compareImages(const Image& reference, const Image& test, const CompareSettings& settings = {});

/// The FLIP error map through the magma colour map, as an sRGB-encoded RGB
/// image (write it with ImageWriteOptions::srgbFor8Bit = false).
Image flipHeatmap(const ImagePlane& flipMap);

/// The display values of an image (R, G, B clamped to [0, 1]), as in the metrics.
Image displayImage(const Image& image);

}  // namespace hp
