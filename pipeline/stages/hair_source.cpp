#include "pipeline/stages/hair_source.h"

#include "core/log.h"
#include "pipeline/batch/output.h"
#include "pipeline/batch/path_template.h"
#include "pipeline/stages/shot_simulation.h"
#include "pipeline/batch/strand_cache.h"
#include "pipeline/stages/cached_strands.h"

namespace fs = std::filesystem;

namespace hp {

bool sceneHasHair(const Scene& scene) {
    return sceneHasHead(scene) && scene.integer("hair.guides.count") > 0;
}

fs::path cachePath(const Scene& scene, const ShotSettings& shot, const std::string& key, int frame) {
    const fs::path p = expandFrame(scene.text(key), frame);
    return p.is_absolute() ? p : shot.outputDir / p;
}

namespace {

class HairFrameSource final : public FrameSource {
  public:
    HairFrameSource(const Scene& scene, const ShotSettings& shot)
        : scene_(scene), shot_(shot), first_(scene.frames("frames").front()) {
        for (const char* key : {"cache.strands", "cache.checkpoint"})
            if (!hasFrameToken(scene.text(key))) scene.fail(key, "needs a frame number (#### or %04d)");
        if (!shot.frames.empty() && shot.frames.front() < first_)
            throw UsageError(cat("frame ", shot.frames.front(), " is before the shot's first frame ", first_,
                                 " (the simulation starts there)"));
    }

    ~HairFrameSource() override {
        // The cache readers after this source (the frame stages of a run that
        // simulated first) rebuild followers on this simulation's groom.
        if (sim_ && scene_.flag("cache.enabled")) lendToCachedStrands(scene_, shot_, std::move(sim_));
    }

    FrameData get(int frame) override {
        FrameData data;
        data.frame = frame;
        data.time = frame / shot_.fps;
        const fs::path cache = cachePath(scene_, shot_, "cache.strands", frame);
        std::error_code ec;
        if (shot_.requireCache && !fs::is_regular_file(cache, ec))
            throw FrameError(cat("no strand cache for frame ", frame, ": ", cache.string(),
                                 " is missing (run `hairpipe sim` for this frame first)"));
        if ((shot_.requireCache || (!shot_.force && scene_.flag("cache.enabled"))) && fs::is_regular_file(cache, ec)) {
            try {
                data.strands = &cached().read(cache);
            } catch (const AssetError& e) {
                throw FrameError(std::string(e.what()) + " (delete it, or rerun with --force to re-simulate)");
            }
            data.guides = cached().guides() ? &*cached().guides() : nullptr;
            if (!head_) head_ = std::make_unique<HeadSetup>(loadHead(scene_));
            pose_ = head_->motion->sample(data.time);
            data.head = &pose_;
            return data;
        }
        simulateTo(frame);
        data.strands = &sim_->advanceTo(frame);
        data.head = &sim_->pose();
        data.simulation = &sim_->stats();
        guides_ = sim_->cachedGuides();
        data.guides = guides_ ? &*guides_ : nullptr;
        if (shot_.writesCache && scene_.flag("cache.checkpoints") && !sim_->canCheckpoint() && !warned_) {
            logWarning("no checkpoints: the ", scene_.text("simulation.formulation"),
                       " formulation cannot be restored exactly, so a stopped simulation restarts from frame ",
                       first_);
            warned_ = true;
        }
        if (shot_.writesCache && scene_.flag("cache.checkpoints") && sim_->canCheckpoint()) {
            const fs::path checkpoint = cachePath(scene_, shot_, "cache.checkpoint", frame);
            try {
                writeAtomically(checkpoint, [&](const fs::path& tmp) { sim_->saveCheckpoint(tmp); });
            } catch (const IoError& e) {
                // Only a resume needs it: the frame fails, its strands are still good.
                data.failures.push_back(e.what());
            }
        }
        return data;
    }

  private:
    /// Makes sim_ able to advance to `frame`: starts it, or jumps ahead to the
    /// latest checkpoint that has its cached strands beside it.
    /// Starts the simulation at the shot's first frame (settling the groom
    /// through the cache beside the strand cache).
    std::unique_ptr<ShotSimulation> start() const {
        SettleCache settle;
        if (scene_.flag("cache.enabled")) {
            const fs::path p = scene_.text("cache.settled_groom");
            settle.file = p.is_absolute() ? p : shot_.outputDir / p;
            settle.reuse = !shot_.force;
        }
        return std::make_unique<ShotSimulation>(scene_, shot_.fps, first_, settle);
    }

    void simulateTo(int frame) {
        if (sim_ && sim_->frame() > frame) sim_.reset();  // frames come in order; a fresh source restarts
        const int from = sim_ ? sim_->frame() : first_;
        if (!shot_.force && scene_.flag("cache.enabled") && scene_.flag("cache.checkpoints")) {
            for (int c = frame - 1; c > from; --c) {
                const fs::path checkpoint = cachePath(scene_, shot_, "cache.checkpoint", c);
                const fs::path strands = cachePath(scene_, shot_, "cache.strands", c);
                std::error_code ec;
                if (!fs::is_regular_file(checkpoint, ec) || !fs::is_regular_file(strands, ec)) continue;
                try {
                    const StrandFrame& whole = cached().read(strands);
                    std::optional<FollowerSource> source;
                    if (cached().guides()) source = cached().guides()->current;
                    else if (scene_.text("cache.followers") == "rebuild")
                        throw AssetError(strands.string(), "is a whole-strand cache (version 1): the frames after it "
                                                           "need its guide record (cache.followers: rebuild)");
                    if (!sim_) sim_ = start();
                    sim_->restoreCheckpoint(checkpoint, whole, source);
                    logInfo("simulation: resumed from the checkpoint of frame ", c);
                    return;
                } catch (const AssetError& e) {
                    logWarning("ignoring checkpoint of frame ", c, ": ", e.what());
                    sim_.reset();
                }
            }
        }
        if (!sim_) sim_ = start();
    }

    const Scene& scene_;
    ShotSettings shot_;
    int first_;
    std::unique_ptr<ShotSimulation> sim_;
    /// Reads cached frames (rebuilding followers from cached guides): made on first use.
    CachedStrands& cached() {
        if (!cached_) cached_ = std::make_unique<CachedStrands>(scene_, shot_);
        return *cached_;
    }

    std::unique_ptr<HeadSetup> head_;  ///< for cached frames, loaded on first use
    std::unique_ptr<CachedStrands> cached_;
    std::optional<CachedGuides> guides_;  ///< the simulated frame's, for the sim stage
    HeadPose pose_;
    bool warned_ = false;
};

}  // namespace

std::unique_ptr<FrameSource> makeHairFrameSource(const Scene& scene, const ShotSettings& shot) {
    return std::make_unique<HairFrameSource>(scene, shot);
}

}  // namespace hp
