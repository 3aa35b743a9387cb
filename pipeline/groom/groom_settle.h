// Settled grooms (hair.groom.settle): a procedural groom is a shape drawn
// without gravity (a bell of straight or combed strands). Before the first
// frame it is simulated on the first frame's pose held still, with gravity
// and head collisions, through the public GuideSolver interface (so any
// formulation the scene configures), until it is at rest or the time runs
// out. At rest: the guides' RMS speed sqrt(2·E_kin/M) is below
// hair.groom.settle_speed, i.e. E_kin < ½·M·v² with M = guides·μ·L their
// mass (settleEnergy), a criterion that does not change with the groom's
// size or hairs_per_guide. The shape it comes to rest in becomes
// the rest shape the shot's solver is initialised with (its pre-load then
// makes it the equilibrium), so hair lies on the head from frame 1.
//
// The settling solver runs without pre-load (otherwise the drawn shape would
// already be an equilibrium), with its bend and limit springs scaled by
// hair.groom.settle_stiffness (the strand models' springs hold the drawn
// shape almost rigidly, so at full stiffness a bell stays a bell: the
// settle is a drape, as an artist's groom is drawn already lying on the
// head), and with at least kSettleDamping: damping does not move an
// equilibrium, it only reaches it sooner.
//
// Cache file (cache.settled_groom; little-endian, version 1):
//   char[8] "HPSETTLE", u32 version, u64 key, f64 seconds simulated,
//   f64 final kinetic energy (J), u32 converged, u32 strands S,
//   u32 points per strand V, f32[3·S·V] positions (m), u32 CRC-32 (zlib) of
//   every byte before it.
// `key` hashes everything that determines the result (the groom, the roots,
// the posed head mesh, the solver and groom keys, the settle time); a file
// with another key, version or checksum is ignored and rewritten, so reruns
// and frame chunks of a shot reuse one settled groom byte for byte.
#pragma once

#include "pipeline/scene/scene.h"
#include "sim/guides/guides.h"

#include <cstdint>
#include <filesystem>
#include <vector>

namespace hp {

inline constexpr float kSettleDamping = 10.f;   ///< 1/s, at least, while settling

/// The kinetic energy below which `guides` guides of `settings` are at
/// rest: ½·M·v², M = guides·μ·L, v = `restSpeed` (RMS), J.
double settleEnergy(const GuideSettings& settings, size_t guides, double restSpeed);

struct SettledGroom {
    std::vector<std::vector<Vec3f>> strands;  ///< world space at the pose's time
    double seconds = 0.0;        ///< simulated
    double kineticEnergy = 0.0;  ///< J, at the end
    bool converged = false;      ///< kinetic energy fell below settleEnergy (else the time ran out)
    bool fromCache = false;
};

struct SettleCache {
    std::filesystem::path file;  ///< empty: no cache
    bool reuse = true;           ///< read a matching file (false: --force)
};

/// @brief Hash of the inputs that determine a settled groom (FNV-1a 64).
/// `sceneKeys` is the text of the scene keys that configure the solver.
uint64_t settleKey(const GuideSettings& settings, const std::vector<SurfaceFrame>& roots, const HeadPose& pose,
                   const std::vector<std::vector<Vec3f>>* groom, double seconds, const std::string& sceneKeys);

/// The resolved simulation.*, hair.guides.* and hair.groom.* keys as text.
std::string settleSceneKeys(const Scene& scene);

/// @brief Settles `groom` (null: straight along the root normals) on `pose`
/// for at most `seconds` or until at rest (RMS speed below `restSpeed`, m/s), springs scaled by
/// `stiffness`, or reads it from `cache` when the key matches.
/// Throws FrameError when the simulation diverges, IoError when the cache
/// cannot be written.
SettledGroom settleGroom(const GuideSettings& settings, const std::vector<SurfaceFrame>& roots, const HeadPose& pose,
                         const std::vector<std::vector<Vec3f>>* groom, double seconds, float stiffness,
                         double restSpeed, const SettleCache& cache, const std::string& sceneKeys);

/// Writes / reads the cache file (readSettledGroom: false when it is absent,
/// of another key or version, or corrupt).
void writeSettledGroom(const std::filesystem::path& file, uint64_t key, const SettledGroom& groom);
bool readSettledGroom(const std::filesystem::path& file, uint64_t key, SettledGroom& groom);

}  // namespace hp
