#include "pipeline/stages/cached_strands.h"

#include "core/log.h"
#include "pipeline/stages/hair_source.h"
#include "pipeline/stages/shot_simulation.h"

#include <chrono>
#include <mutex>

namespace hp {

namespace {

/// What identifies the groom a simulation was set up on: the scene (with its
/// overrides) and where its settled groom is cached.
std::string lendKey(const Scene& scene, const ShotSettings& shot) {
    return cat(scene.dump(), "\n", shot.outputDir.string(), "\n", shot.fps);
}

std::mutex lentMutex;
std::string lentKey;
/// Never destroyed: a simulation lent at the end of a run may outlive main(),
/// and must not be torn down after TBB's and the logger's statics.
std::unique_ptr<ShotSimulation>& lent = *new std::unique_ptr<ShotSimulation>;

}  // namespace

void lendToCachedStrands(const Scene& scene, const ShotSettings& shot, std::unique_ptr<ShotSimulation> simulation) {
    const std::lock_guard<std::mutex> lock(lentMutex);
    lent = std::move(simulation);
    lentKey = lent ? lendKey(scene, shot) : std::string();
}

CachedStrands::CachedStrands(const Scene& scene, const ShotSettings& shot) : scene_(scene), shot_(shot) {}

CachedStrands::~CachedStrands() = default;

const StrandFrame& CachedStrands::read(int frame) { return read(cachePath(scene_, shot_, "cache.strands", frame)); }

const StrandFrame& CachedStrands::read(const std::filesystem::path& file) {
    StrandCacheFile f = readStrandCacheFile(file);
    if (!f.guides) {
        guides_.reset();
        whole_ = std::move(f.strands);
        return whole_;
    }
    guides_ = std::move(f.guides);
    const auto start = std::chrono::steady_clock::now();
    if (!rebuilder_) {
        const std::lock_guard<std::mutex> lock(lentMutex);
        if (lent && lentKey == lendKey(scene_, shot_)) {
            rebuilder_ = std::move(lent);
            logVerbose("strand cache: rebuilding followers on the simulation that cached them");
        }
    }
    if (!rebuilder_) {
        // The simulation's own set-up (head, roots, settled groom, followers):
        // the groom the followers were built on. The settled groom is read
        // back from the cache beside the strands, as a resumed simulation does.
        SettleCache settle;
        if (scene_.flag("cache.enabled")) {
            const std::filesystem::path p = scene_.text("cache.settled_groom");
            settle.file = p.is_absolute() ? p : shot_.outputDir / p;
            settle.reuse = true;
        }
        rebuilder_ = std::make_unique<ShotSimulation>(scene_, shot_.fps, scene_.frames("frames").front(), settle, true);
    }
    const StrandFrame& strands = rebuilder_->rebuild(*guides_, file.string());
    logVerbose("strand cache: frame ", strands.frame, ": ", strands.strandCount() - strands.guideCount,
               " followers rebuilt from ", strands.guideCount, " cached guides in ",
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), " s");
    return strands;
}

}  // namespace hp
