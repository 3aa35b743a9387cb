// Perceptually uniform colour maps for error heat maps.
//
// Magma (van der Walt & Smith's matplotlib map, the one the FLIP paper uses
// for its error maps): lightness rises monotonically from black to pale
// yellow, so equal error steps look like equal steps and the map survives
// greyscale printing. Stored as 17 knots of the 256-entry table, linearly
// interpolated (within 0.01 of the full table).
#pragma once

#include <array>

namespace hp {

/// Display (sRGB-encoded) colour of `t` in [0, 1] (clamped) on the magma map.
std::array<float, 3> magma(float t);

}  // namespace hp
