// Procedural grooms: the rest shape of every guide at the start of a shot.
//
// `straight` is Gomes 2024's default (each strand straight along its root
// normal). `combed` lays the hair down the way a comb would: each strand
// leaves the scalp along its normal and turns smoothly toward a comb
// direction (gravity's, by default), sliding over the head instead of
// through it. The solvers pre-load their springs so whichever shape they are
// given holds still under gravity at the first frame.
#pragma once

#include "sim/strands/head.h"

#include <vector>

namespace hp {

/// @brief The rest shape of a groomed strand: straight along the root
/// normal, or combed toward a direction.
enum class GroomStyle { Straight, Combed };

/// @brief The groom's shape (scene keys hair.groom.*): the strand's
/// segments and length, which every style has, then the style and what
/// combing adds.
struct GroomSettings {
    int segments = 23;
    float length = 0.25f;          ///< m
    GroomStyle style = GroomStyle::Straight;
    /// Combed: how far the strand turns toward `direction`, 0 (straight) to
    /// 1 (the tip points along it).
    float droop = 0.85f;
    Vec3f direction{0.f, -1.f, 0.f};  ///< combed: world direction the hair is combed toward
    float clearance = 0.001f;      ///< combed: distance kept from the head surface, m
};

/// @brief World-space vertices (segments + 1 per strand) of the groom at the
/// roots' current frames. Segment lengths are length / segments exactly;
/// with a collider, combed vertices are pushed out to `clearance` (rotating
/// each segment about its start, so lengths stay exact).
std::vector<std::vector<Vec3f>> groomStrands(const std::vector<SurfaceFrame>& roots, const GroomSettings& settings,
                                             const Collider* head);

}  // namespace hp
