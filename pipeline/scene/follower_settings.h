// Maps the scene's hair.followers.* keys (and the shot seed) onto
// sim/followers/followers.h's FollowerSettings.
#pragma once

#include "pipeline/scene/scene.h"
#include "sim/followers/followers.h"
#include "sim/strands/groom_modifiers.h"

namespace hp {

/// Follower mode, neighbour rule, Algorithm 1's constants, collision and
/// the seed of the per-segment random values. Radii keep FollowerSettings'
/// defaults (0.04 mm root, 0.01 mm tip) until a hair radius key exists.
FollowerSettings followerSettings(const Scene& scene);

/// The groom modifiers of hair.followers.* (length_variation, clump*, wave*,
/// curl, frizz), seeded by the shot seed.
GroomModifiers groomModifiers(const Scene& scene);

}  // namespace hp
