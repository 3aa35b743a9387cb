// @brief The hair-hair grid's settings (scene keys simulation.volume.*,
// pipeline/scene/keys/simulation.yaml). Plain data: sim/guides/guides.h
// holds one in GuideSettings.
#pragma once

namespace hp {

struct VolumeSettings {
    /// Off in the library (tests and benchmarks ask for it); the scene key
    /// simulation.volume.enabled turns it on by default.
    bool enabled = false;
    float cellSize = 0.01f;        ///< Δ, m
    /// Hair length per volume above which the volume step pushes, in hairs
    /// per cm² (hairs crossing a square centimetre of section). Default: the
    /// mean scalp density of Barman, Astore and Pecoraro, "The normal
    /// trichogram of the adult" (J. Invest. Dermatol., 1965), 223 hairs/cm²
    /// (175–300): loose hair packed no denser than where it grows.
    float targetDensity = 223.f;
    float friction = 10.f;         ///< k: velocities blend toward the grid's at rate k, 1/s
    float relaxTime = 0.01f;       ///< τ: the volume step's time constant, s (0: off)
    /// Wisps against wisps (sim/volume/wisp_contact.h), with the grid
    /// (enabled): vertices of different guides kept this many wisp diameters
    /// apart (a wisp of hairsPerGuide hairs at targetDensity); 0: off. Scene
    /// key simulation.volume.contact_scale. Off by default: in the default
    /// shot it keeps the hair moving after the head stops (docs/physics.md);
    /// 1.5 holds the crossing wisps (1 diameter lets 80% through).
    float contactScale = 0.f;
    int contactIterations = 4;     ///< Jacobi sweeps of the wisp contact a substep

    /// Throws hp::Error naming the first setting out of range.
    void validate() const;
};

}  // namespace hp
