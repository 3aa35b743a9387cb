#include "pipeline/stages/stages.h"

#include <algorithm>

#include "pipeline/head/head_setup.h"
#include "pipeline/stages/hair_source.h"
#include "pipeline/stages/head_source.h"

namespace hp {

namespace {

/// Frame data that is only the frame number and time: the shot has no head
/// or hair stage yet.
class TimeOnlySource final : public FrameSource {
  public:
    explicit TimeOnlySource(double fps) : fps_(fps) {}
    FrameData get(int frame) override {
        FrameData d;
        d.frame = frame;
        d.time = frame / fps_;
        return d;
    }

  private:
    double fps_;
};

/// Runs a stage only on the frames of its `<stage>.frames` key (say, a
/// reference every 12th frame): other frames have no outputs for it.
class FrameSubset final : public FrameStage {
  public:
    FrameSubset(StagePtr stage, std::vector<int> frames) : stage_(std::move(stage)), frames_(std::move(frames)) {}
    std::string name() const override { return stage_->name(); }
    std::vector<std::filesystem::path> outputs(int frame) const override {
        return selected(frame) ? stage_->outputs(frame) : std::vector<std::filesystem::path>{};
    }
    bool needsFrameData() const override { return stage_->needsFrameData(); }
    bool overlaps() const override { return stage_->overlaps(); }
    bool exclusive() const override { return stage_->exclusive(); }
    void run(const FrameData& data) override {
        if (selected(data.frame)) stage_->run(data);
    }
    std::vector<std::string> collectFailures(bool wait) override { return stage_->collectFailures(wait); }
    void finish(const ShotSettings& shot) override {
        // The whole-run outputs cover the run's frames this stage ran on.
        ShotSettings subset = shot;
        subset.frames.clear();
        for (int f : shot.frames)
            if (selected(f)) subset.frames.push_back(f);
        if (!subset.frames.empty()) stage_->finish(subset);  // none: keep what an earlier run wrote
    }

  private:
    bool selected(int frame) const { return std::binary_search(frames_.begin(), frames_.end(), frame); }
    StagePtr stage_;
    std::vector<int> frames_;
};

StagePtr withFrameSubset(StagePtr stage, const Scene& scene) {
    if (!stage) return stage;
    const std::string key = stage->name() + ".frames";
    if (!scene.has(key)) return stage;
    return std::make_unique<FrameSubset>(std::move(stage), scene.frames(key));
}

}  // namespace

const std::vector<std::string>& stageNames() {
    static const std::vector<std::string> names = {"sim", "preview", "reference", "vdb", "compare"};
    return names;
}

std::unique_ptr<FrameSource> makeFrameSource(const Scene& scene, const ShotSettings& shot) {
    if (sceneHasHair(scene)) return makeHairFrameSource(scene, shot);
    if (sceneHasHead(scene)) return makeHeadFrameSource(loadHead(scene).motion, shot.fps);
    return std::make_unique<TimeOnlySource>(shot.fps);
}

std::vector<StagePtr> makeStages(const Scene& scene, const ShotSettings& shot, const std::set<std::string>& only) {
    std::vector<StagePtr> stages;
    auto add = [&](StagePtr stage) {
        if (stage && (only.empty() || only.count(stage->name())))
            stages.push_back(withFrameSubset(std::move(stage), scene));
    };
    add(makeSimStage(scene, shot));  // first: the strand cache of the frame
    add(makePreviewStage(scene, shot));
    add(makeReferenceStage(scene, shot));
    add(makeVdbStage(scene, shot));
    add(makeCompareStage(scene, shot));  // last: reads the other stages' files
    return stages;
}

}  // namespace hp
