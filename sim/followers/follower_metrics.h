// @brief An honest figure for how alike neighbouring followers are: the
// median angle between the mid-strand tangents of root-neighbouring
// followers (issue 19, item 5). 0 for parallel copies; a few degrees for
// followers that fuse into flat feathers at production density; tens of
// degrees for clumped, wavy or frizzy hair.
#pragma once

#include "sim/strands/strand.h"

#include <cstddef>

namespace hp {

/// For every strand i in [first, strandCount()) with at least two vertices:
/// its nearest other strand j of the range by root (vertex 0) distance, ties
/// by index (sim/followers/follower_neighbours.h's grid), and the angle between the
/// two strands' middle segments (segment floor((n - 1) / 2) of each, unit
/// directions), acos(clamp(t_i · t_j, -1, 1)). Returns the median of those
/// angles in degrees (the lower middle for an even count), 0 for fewer than
/// two strands. Deterministic; runs on TBB's threads.
double medianNeighbourAngle(const StrandFrame& frame, size_t first);

}  // namespace hp
