#include "pipeline/stages/head_source.h"

namespace hp {

namespace {

class HeadFrameSource final : public FrameSource {
  public:
    HeadFrameSource(std::shared_ptr<const HeadMotion> head, double fps) : head_(std::move(head)), fps_(fps) {}

    FrameData get(int frame) override {
        FrameData d;
        d.frame = frame;
        d.time = frame / fps_;
        pose_ = head_->sample(d.time);
        d.head = &pose_;
        return d;
    }

  private:
    std::shared_ptr<const HeadMotion> head_;
    double fps_;
    HeadPose pose_;
};

}  // namespace

std::unique_ptr<FrameSource> makeHeadFrameSource(std::shared_ptr<const HeadMotion> head, double fps) {
    return std::make_unique<HeadFrameSource>(std::move(head), fps);
}

}  // namespace hp
