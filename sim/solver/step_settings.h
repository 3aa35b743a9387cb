// The settings every strand model steps by (sim/guides/guides.h
// GuideSettings and sim/curly/curly_wet.h CurlyWetSettings extend them):
// the fixed step, the scene-cut limits, the render radii of the strands
// written, and the fixed partition that keeps results independent of the
// thread count. Units: metres, seconds, degrees for angles.
#pragma once

namespace hp {

/// @brief What the solver skeleton (sim/solver/skeleton.h) needs of a model's settings.
struct StepSettings {
    // Time stepping (Gomes 2024: fixed step 0.02 s).
    float timeStep = 0.02f;         ///< one step, s
    int substeps = 1;               ///< Bullet (or rod) substeps per step

    // Scene cuts: a root or head jump beyond these in one step resets the strands to rest.
    float teleportDistance = 0.1f;  ///< m per step
    float teleportAngle = 45.f;     ///< deg per step

    // Render radii written to StrandFrame, tapered linearly root to tip.
    float rootRadius = 0.00004f;    ///< m (the rod's fibre radius at the root too)
    float tipRadius = 0.00001f;     ///< m (the rod's at the tip)

    // Parallelism. Strands are partitioned into groups of this many (one
    // Bullet world each where the model uses Bullet): a fixed mapping, so
    // results do not depend on the thread count.
    int strandsPerWorld = 16;
    int threads = 0;                ///< 0 = the ambient TBB limit
};

}  // namespace hp
