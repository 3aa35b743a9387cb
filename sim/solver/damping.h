// Velocity damping that does not depend on the step size, shared by the
// strand models whose damping is a rate (the guides' rod and rope).
#pragma once

#include <cmath>

namespace hp::strand {

/// @brief Velocity damping over a time h: v ← v·exp(-c·h), c the decay rate
/// (1/s). Applying it n times with h/n gives the same decay as once with h.
inline float dampingFactor(float rate, float h) { return std::exp(-rate * h); }

}  // namespace hp::strand
