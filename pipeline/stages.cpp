#include "pipeline/stages.h"

#include "pipeline/head_setup.h"
#include "pipeline/head_source.h"

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

}  // namespace

std::unique_ptr<FrameSource> makeFrameSource(const Scene& scene, const ShotSettings& shot) {
    if (sceneHasHead(scene)) return makeHeadFrameSource(loadHead(scene).motion, shot.fps);
    return std::make_unique<TimeOnlySource>(shot.fps);
}

std::vector<StagePtr> makeStages(const Scene& scene, const ShotSettings& shot, const std::set<std::string>& only) {
    std::vector<StagePtr> stages;
    auto add = [&](StagePtr stage) {
        if (stage && (only.empty() || only.count(stage->name()))) stages.push_back(std::move(stage));
    };
    add(makePreviewStage(scene, shot));
    add(makeReferenceStage(scene, shot));
    add(makeVdbStage(scene, shot));
    add(makeCompareStage(scene, shot));  // last: reads the other stages' files
    return stages;
}

}  // namespace hp
