// The folding head (`make_head OUT --fold`, scenes/assets/fold.glb): a head
// as a rigger often hands it over, not a clean closed surface. One skinned
// mesh of two closed shells that overlap: a sphere head (radius 0.1 m) and
// a cylinder neck (radius 0.045 m, 0.12 m long) whose top cap sits 4 cm
// inside the sphere. Two bones, Neck (at the neck's base) and Head (where
// the neck enters the sphere). Roots everywhere on it
// (`head.scalp.method: all`) put hair on the buried neck top and on the
// sphere's underside inside the neck: the self-intersection of
// docs/colliders.md. Two clips:
// - "fold_tip": the head tips back 70° and forward 70° fast (0.2 s each way),
//   folding the sphere onto the neck;
// - "fold_jump": the neck bends 40° forward, then the whole rig jumps 0.5 m
//   sideways between two keys 1/30 s apart; the sampler interpolates the
//   jump linearly, so at 24 fps (steps of 1/72 s) it spreads over 3-4
//   simulation steps.
#pragma once

#include "pipeline/head/head_rig.h"

namespace hp {

struct FoldHeadOptions {
    int rings = 32;         ///< latitude bands of the sphere
    int sectors = 48;       ///< segments around sphere and neck
    int neckRings = 12;     ///< bands along the neck
    double keyRate = 30.0;  ///< keys per second of the clips
};

constexpr float kFoldHeadRadius = 0.1f;    ///< the sphere, centred at the origin
constexpr float kFoldNeckRadius = 0.045f;  ///< the cylinder, about the Y axis
constexpr float kFoldNeckTop = -0.06f;     ///< its top cap: 4 cm above the sphere's bottom (y = -0.1)
constexpr float kFoldNeckLength = 0.12f;   ///< its bottom cap at kFoldNeckTop - kFoldNeckLength
constexpr double kFoldTipSeconds = 1.2;    ///< duration of "fold_tip"
constexpr double kFoldJumpSeconds = 1.5;   ///< duration of "fold_jump"
constexpr double kFoldJumpStart = 1.0;     ///< the jump runs from here to + 1/keyRate
constexpr float kFoldJumpDistance = 0.5f;  ///< along +X, metres

/// @brief Builds the folding head rig (deterministic: same options, same bits).
/// Mesh "fold" (material "scalp"): the sphere's triangles first, then the
/// neck's (side, top cap, bottom cap).
HeadRig makeFoldHead(const FoldHeadOptions& options = {});

}  // namespace hp
