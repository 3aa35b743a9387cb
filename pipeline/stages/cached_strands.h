// The strand cache read back whole: a version 1 file is the frame itself; a
// version 2 file holds the guides and the follower pins, and the followers
// are rebuilt from them here on the shot's own groom (a ShotSimulation set up
// as for the simulation, settled groom reused through cache.settled_groom,
// never stepped), bit for bit what the simulation wrote. Every reader of the
// cache (the frame source, camera auto/follow, USD export) goes through it.
#pragma once

#include "pipeline/batch/strand_cache.h"
#include "pipeline/scene/scene.h"
#include "pipeline/stages/stage.h"

#include <filesystem>
#include <memory>
#include <optional>

namespace hp {

class ShotSimulation;

class CachedStrands {
  public:
    /// `scene` is copied; `shot` gives the output folder and fps.
    CachedStrands(const Scene& scene, const ShotSettings& shot);
    ~CachedStrands();

    /// Frame `frame` of the cache (cache.strands), whole; throws AssetError
    /// naming the file (missing, corrupt, or not this scene's hair). The
    /// reference stays valid until the next read.
    const StrandFrame& read(int frame);
    /// The same for a file given by path.
    const StrandFrame& read(const std::filesystem::path& file);
    /// The guide record of the last version 2 file read (none after version 1).
    const std::optional<CachedGuides>& guides() const { return guides_; }

  private:
    Scene scene_;
    ShotSettings shot_;
    std::unique_ptr<ShotSimulation> rebuilder_;  ///< made on the first version 2 file
    StrandFrame whole_;                          ///< the last version 1 frame
    std::optional<CachedGuides> guides_;
};

/// @brief Hands a simulation that has stopped stepping (e.g. the one that
/// just filled the cache) to the next CachedStrands of the same scene and
/// output folder in this process, which rebuilds on it instead of setting
/// the groom up again (about a minute at 1M followers). Holds one at a time.
void lendToCachedStrands(const Scene& scene, const ShotSettings& shot, std::unique_ptr<ShotSimulation> simulation);

}  // namespace hp
