// Procedural strands for tests and benchmarks, made without simulation: roots
// on a Fibonacci cap of a sphere head, each strand leaving along the normal
// and drooping toward -Y like hair hanging under gravity, kept outside the
// head. Deterministic (no randomness).
#pragma once

#include "sim/strands/strand.h"

namespace hp {

struct SyntheticHairSettings {
    size_t strands = 100000;
    int vertices = 24;            ///< per strand (23 segments)
    float length = 0.25f;         ///< metres
    float headRadius = 0.1f;      ///< sphere head centred at the origin
    float capMinCosine = 0.f;     ///< 0 = upper hemisphere (docs/benchmarks.md)
    float rootRadius = 0.00004f;  ///< 0.04 mm
    float tipRadius = 0.00001f;   ///< 0.01 mm
    float droop = 1.f;            ///< 0 = straight along the normal, 1 = hangs down by the tip
};

/// Strands of the B-render/B-vdb scenes when no simulated frame is at hand.
StrandFrame makeSyntheticHair(const SyntheticHairSettings& settings);

}  // namespace hp
