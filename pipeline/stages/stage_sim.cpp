// The "sim" stage: writes each frame's strands to the strand cache, the
// simulation's statistics beside them, and (cache.usd) a USD export.
#include "core/log.h"
#include "pipeline/stages/hair_source.h"
#include "pipeline/batch/output.h"
#include "pipeline/batch/path_template.h"
#include "pipeline/stages/shot_simulation.h"
#include "pipeline/stages/stages.h"
#include "pipeline/batch/strand_cache.h"
#include "pipeline/stages/usd_export.h"

#include <fstream>

namespace fs = std::filesystem;

namespace hp {

namespace {

class SimStage final : public FrameStage {
  public:
    SimStage(const Scene& scene, const ShotSettings& shot)
        : scene_(scene), shot_(shot), rebuild_(scene.text("cache.followers") == "rebuild") {
        for (const char* key : {"cache.strands", "cache.stats"})
            if (!hasFrameToken(scene.text(key))) scene.fail(key, "needs a frame number (#### or %04d)");
        if (!scene.text("cache.usd").empty() && !hasFrameToken(scene.text("cache.usd")))
            scene.fail("cache.usd", "needs a frame number (#### or %04d)");
    }
    std::string name() const override { return "sim"; }
    std::vector<fs::path> outputs(int frame) const override {
        std::vector<fs::path> out{cachePath(scene_, shot_, "cache.strands", frame),
                                  cachePath(scene_, shot_, "cache.stats", frame)};
        if (!scene_.text("cache.usd").empty()) out.push_back(cachePath(scene_, shot_, "cache.usd", frame));
        return out;
    }
    void run(const FrameData& data) override {
        if (!data.strands) throw FrameError(cat("frame ", data.frame, " has no strands to cache"));
        const std::vector<fs::path> paths = outputs(data.frame);
        // cache.followers: rebuild writes the guides and pins (version 2); a
        // frame without its guide record (resumed from a version 1 cache)
        // falls back to whole strands, which every reader still reads.
        if (rebuild_ && data.guides) {
            writeAtomically(paths[0], [&](const fs::path& tmp) { writeGuideCache(tmp, *data.guides); });
        } else {
            if (rebuild_) logWarning("frame ", data.frame, ": no guide record (resumed from a whole-strand cache): ",
                                     "caching its strands whole");
            writeAtomically(paths[0], [&](const fs::path& tmp) { writeStrandCache(tmp, *data.strands); });
        }
        // Statistics exist only for simulated frames; a frame read back from
        // the cache (e.g. only the stats file was lost) records that.
        const std::string json = data.simulation ? data.simulation->json()
                                                 : cat("{\"frame\": ", data.frame, ", \"from_cache\": true}");
        writeTextAtomically(paths[1], json + "\n");
        if (paths.size() > 2) {
            UsdExportSettings usd;
            usd.fps = shot_.fps;
            writeAtomically(paths[2], [&](const fs::path& tmp) { writeUsdCurves(tmp, *data.strands, usd); });
        }
    }

  private:
    const Scene& scene_;
    ShotSettings shot_;
    bool rebuild_;  ///< cache.followers: rebuild
};

}  // namespace

StagePtr makeSimStage(const Scene& scene, const ShotSettings& shot) {
    if (!sceneHasHair(scene) || !scene.flag("cache.enabled")) return nullptr;
    return std::make_unique<SimStage>(scene, shot);
}

}  // namespace hp
