// @brief The preview's hair material fitted to the physical fibre: the
// Kajiya-Kay family (render/view/view.h HairLobe: a diffuse colour, a white
// reflection lobe R, a coloured TRT lobe after Scheuermann 2004, "Practical
// Real-Time Hair Rendering and Shading", and a transmission lobe TT for back
// light) with every strength, exponent, shift and azimuthal width derived from
// Chiang et al. 2016's BSDF (hair_bsdf.h), plus the dual-scattering constants
// of Zinke, Yuksel, Weber and Keyser 2008, "Dual Scattering Approximation for
// Fast Multiple Scattering in Hair" (a_f, β_f², A_b) and the azimuthal variance
// s_φ² of the light one fibre scatters forward.
//
// Method: per material, at scene load (~0.1 s, memoised per fibre). The
// physical kernel S is averaged over the fibre's width h (a preview ribbon is
// a pixel wide or less and cannot resolve h) and integrated over the azimuth
// φ on a 36 x 36 grid of (θi, θo), lobe by lobe (HairBsdf::eval's R, TT, TRT
// and residual parts). Each lobe's integrated response A_p(θi, θo) is fitted
// by k cos(θi + θo − shift)^n (least squares over an exponent x shift grid,
// weights cos θi cos θo, k in closed form per colour channel); the residual
// by the diffuse kd·color·cos θi. Each lobe's azimuthal distribution
// N(|φ|; |θo|) is tabulated from the physical lobe at 9 x 9 nodes (one N for
// all θo spread the transmission peak over the sides: the rig's key light
// came out 22% too bright).
// A per-material fit was chosen over lookup tables because the fitted terms
// stay the Kajiya-Kay family's few uniforms (the preview's cost does not
// change) and the fit is cheap enough to run at scene load for any melanin,
// roughness or tilt; tests/test_hair_fit.cpp states its error.
#pragma once

#include "render/reference/hair_bsdf.h"
#include "render/view/view.h"

namespace hp {

/// Zinke 2008's back-scattering density factor d_b (their §4.3: 0.7 for
/// human hair), and their forward density factor d_f, which the preview's
/// Poisson average over crossing counts replaces.
inline constexpr float kDualBackDensity = 0.7f;

/// Sets m.shading = Fitted and the fitted terms (color, kd = 1, r, trt, tt,
/// dual) for the fibre; the Kajiya-Kay fields are left as they are.
void fitHairMaterial(const HairFiberParams& fiber, HairMaterial* m);

}  // namespace hp
