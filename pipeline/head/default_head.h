// The project's own animated head (scenes/assets/head.glb is this rig,
// written by tools/make_head): a closed head-and-neck mesh of plausible
// proportions (skull ~0.1 m, metres, Y up, face towards +Z), two materials
// ("scalp" above the hairline, "skin" elsewhere; vertex colour R is the
// same hair mask, smoothed), a two-bone skin (Neck, Head) and two clips:
// "nod_shake_turn": still, two nods, two head shakes, a fast turn, then
// still again so the hair visibly settles; "stress": the violent motions
// and the scene cut of B-sim-stress.
#pragma once

#include "pipeline/head/head_rig.h"

namespace hp {

struct DefaultHeadOptions {
    int rings = 40;    ///< latitude bands of the mesh (the poles are the skull top and the neck's base)
    int sectors = 64;  ///< longitude segments
    double keyRate = 30.0;  ///< rotation keys per second of the clip
};

/// Duration of the default head's clip, seconds.
constexpr double kDefaultHeadClipSeconds = 3.5;
/// The second clip, "stress" (scenes/stress.yaml, B-sim-stress): tips back
/// 70° in 0.25 s and forward again, turns 180° in 0.3 s, cuts at 2 s.
constexpr double kStressClipSeconds = 2.5;
constexpr double kStressCut = 2.0;

/// @brief Builds the default head rig. Deterministic: the same options give
/// bit-identical data. About 2·rings·sectors triangles (5k by default).
HeadRig makeDefaultHead(const DefaultHeadOptions& options = {});

/// @brief The shoulders under the default head (scenes/assets/body.glb,
/// `make_head --body`): an upper torso, one mesh "shoulders" skinned to a
/// Chest bone (and, next to the neck, halfway to the head's Neck bone), with
/// the head's Neck and Head bones and both clips, so played with the head's
/// clip it moves as the head's body. The top of the shoulders is 0.25 m
/// below the skull top beside the neck and 0.3 m at the shoulder tips, an
/// adult's proportions; the upper back lies under the nape hair.
HeadRig makeDefaultBody(const DefaultHeadOptions& options = {});

/// The head's inside/outside function (negative inside), metres: a smooth
/// union of skull, jaw, nose, ears and neck. Exposed for tests.
float defaultHeadField(const Vec3f& p);

/// The shoulders' inside/outside function (negative inside), metres.
float defaultBodyField(const Vec3f& p);

/// True above the hairline: the scalp the default scene grows hair on.
float defaultHeadHairMask(const Vec3f& p);

/// Hermite smoothstep: 0 below e0, 1 above e1, 3t² − 2t³ between.
float smoothstep(float e0, float e1, float x);

/// Appends one vertex's skin weights on a neck (bone 0) and head (bone 1)
/// rig: `head` on the head bone, 1 − head on the neck, zero weights left out.
void appendNeckHeadInfluence(RigMesh& m, float head);

}  // namespace hp
