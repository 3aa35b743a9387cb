// SSIM, the structural similarity index (Wang, Bovik, Sheikh, Simoncelli,
// "Image Quality Assessment: From Error Visibility to Structural Similarity",
// IEEE TIP 2004), on one channel.
//
// With local statistics taken under a Gaussian window w,
//   μx = w∗x, μy = w∗y, σx² = w∗x² − μx², σy² = w∗y² − μy², σxy = w∗(xy) − μxμy,
//   SSIM(x, y) = (2μxμy + C1)(2σxy + C2) / ((μx² + μy² + C1)(σx² + σy² + C2)),
//   C1 = (K1·L)², C2 = (K2·L)².
// The map has one value per pixel in [-1, 1]; 1 means locally identical.
#pragma once

#include "render/image/image_filter.h"

namespace hp {

/// The paper's standard constants: an 11×11 Gaussian window with σ = 1.5,
/// K1 = 0.01, K2 = 0.03, dynamic range L = 1 (inputs are expected in [0, 1]).
struct SsimSettings {
    double sigma = 1.5;
    int radius = 5;  ///< window = 2·radius + 1 pixels square
    double k1 = 0.01;
    double k2 = 0.03;
    double range = 1.0;  ///< L
};

/// Per-pixel SSIM of two planes of equal size. Windows near the border see
/// replicated edge pixels (the paper's MATLAB code crops them instead; a full
/// map lets callers average over any mask). Throws Error on a size mismatch.
ImagePlane ssimMap(const ImagePlane& x, const ImagePlane& y, const SsimSettings& settings = {});

}  // namespace hp
