// ꟻLIP (LDR-FLIP): a perceptual difference between a reference and a test
// image, as seen by an observer flipping between them (Andersson, Nilsson,
// Akenine-Möller, Oskarsson, Åström, Fairchild, "FLIP: A Difference Evaluator
// for Alternating Images", HPG 2020). Written from the paper.
//
// Colour pipeline (per pixel, after spatial filtering):
//   1. linear sRGB → CIE XYZ (D65) → YCxCz, the linear opponent space
//      Y' = 116·Y/Yn − 16, Cx = 500·(X/Xn − Y/Yn), Cz = 200·(Y/Yn − Z/Zn);
//   2. each channel convolved with its contrast sensitivity filter, a sum of
//      Gaussians a·sqrt(π/b)·exp(−π²r²/b) (r in degrees; achromatic a=1,
//      b=0.0047; red-green a=1, b=0.0053; blue-yellow a=34.1, b=0.04 plus
//      a=13.5, b=0.025), sampled at 1/PPD degrees per pixel and normalised —
//      this removes detail the eye cannot resolve at that viewing distance;
//   3. back to linear RGB, clamped to [0, 1], to CIELAB, and Hunt-adjusted
//      (a, b scaled by 0.01·L: colour differences fade in dark regions);
//   4. HyAB distance ΔE = |ΔL| + sqrt(Δa² + Δb²), raised to q_c = 0.7 and
//      remapped to [0, 1]: values below p_c·c_max (p_c = 0.4) map linearly to
//      [0, p_t] (p_t = 0.95), the rest linearly to [p_t, 1]; c_max is the
//      (exponentiated) distance between Hunt-adjusted pure green and blue.
// Feature pipeline (on the unfiltered luminance Y/Yn):
//   edges and points are the magnitudes of the first and second Gaussian
//   derivatives (σ = ½·0.082°·PPD, radius ⌈3σ⌉, each kernel's positive and
//   negative weights normalised to +1 and −1); the feature difference is
//   ΔE_f = (max(|‖e_ref‖ − ‖e_test‖|, |‖p_ref‖ − ‖p_test‖|)/√2)^q_f, q_f = 0.5.
// Per-pixel error: e = ΔE_c^(1 − ΔE_f), in [0, 1]; 0 means indistinguishable.
// Feature differences raise the colour error toward 1 where edges or points
// moved, appeared or vanished.
#pragma once

#include "render/image/image_filter.h"

namespace hp {

/// Three linear-sRGB planes of equal size with values in [0, 1].
struct RgbPlanes {
    ImagePlane r, g, b;
    int width() const { return r.width; }
    int height() const { return r.height; }
};

struct FlipSettings {
    /// Pixels per degree of visual angle of the observer. The paper's default
    /// 67 corresponds to a 0.7 m wide 3840-pixel display viewed from 0.7 m.
    double pixelsPerDegree = 67.0;
};

/// Pixels per degree for a display `widthMetres` wide with `pixelsX` columns
/// seen from `distanceMetres`: distance · (pixelsX / width) · π / 180.
double pixelsPerDegree(double distanceMetres, double widthMetres, int pixelsX);

/// The per-pixel LDR-FLIP error map of `test` against `reference`, values in
/// [0, 1]. Throws Error if the sizes differ or PPD is not positive.
ImagePlane flipErrorMap(const RgbPlanes& reference, const RgbPlanes& test, const FlipSettings& settings = {});

}  // namespace hp
