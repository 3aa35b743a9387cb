// The "preview" frame stage: renders each frame's strands, head and generated
// hair with the GL preview (render/preview/preview.h) and writes EXR (+ PNG) frames.
// One headless GL context serves the whole run, created on the first frame
// that needs it (so resumed runs with nothing to do never touch GL).
#include "core/log.h"
#include "pipeline/head/animated_head.h"
#include "pipeline/stages/camera_track.h"
#include "pipeline/batch/output.h"
#include "pipeline/batch/path_template.h"
#include "pipeline/scene/preview_settings.h"
#include "pipeline/stages/stages.h"
#include "pipeline/scene/view_settings.h"
#include "render/preview/gl_context.h"

#include <optional>

namespace fs = std::filesystem;

namespace hp {

namespace {

class PreviewStage final : public FrameStage {
  public:
    PreviewStage(const Scene& scene, const ShotSettings& shot)
        : view_(makeView(scene)), scene_(scene), display_(makeDisplaySettings(scene)),
          settings_(makePreviewSettings(scene)), outputDir_(shot.outputDir) {
        checkCameraKeys(scene);
        for (const char* key : {"preview.exr", "preview.png"}) {
            const std::string& t = scene.text(key);
            if (!t.empty() && !hasFrameToken(t))
                scene.fail(key, "needs a frame number token (#### or %04d), or every frame would overwrite one file");
        }
        exr_ = scene.text("preview.exr");
        png_ = scene.text("preview.png");
        if (exr_.empty() && png_.empty())
            scene.fail("preview.exr", "preview.exr and preview.png are both empty: the preview would write nothing");
        sceneName_ = scene.name();
    }

    std::string name() const override { return "preview"; }

    std::vector<fs::path> outputs(int frame) const override {
        std::vector<fs::path> paths;
        for (const std::string* t : {&exr_, &png_})
            if (!t->empty()) paths.push_back(outputDir_ / expandFrame(*t, frame));
        return paths;
    }

    void run(const FrameData& data) override {
        if (!data.strands && !data.head)
            throw FrameError(cat("preview: frame ", data.frame,
                                 " has neither hair strands nor a head mesh to draw (the shot's frame source "
                                 "provides no geometry)"));
        ensureRenderer();
        PreviewFrame frame;
        frame.time = data.time;
        frame.strands = data.strands;
        TriangleMesh drawn;  // the head with the visible colliders beside it
        if (data.head) {
            frame.head = &drawnMesh(*data.head, drawn);
            frame.headTransform = data.head->transform;
        }
        View view = view_;
        view.camera = cameraAt(data.frame, data.strands);
        const Image image = renderer_->render(view, frame);
        ImageWriteOptions options;
        options.metadata = {{"hairpipe:scene", sceneName_},
                            {"hairpipe:frame", std::to_string(data.frame)},
                            {"hairpipe:stage", "preview"},
                            {"hairpipe:renderer", renderer_->stats().renderer}};
        for (const fs::path& path : outputs(data.frame))
            writeAtomically(path, [&](const fs::path& tmp) { writeImageWithDisplay(tmp.string(), image, display_, options); });
    }

  private:
    void ensureRenderer() {
        if (renderer_) {
            context_->makeCurrent();
            return;
        }
        try {
            context_ = GlContext::createHeadless();
            renderer_ = std::make_unique<PreviewRenderer>(settings_);
        } catch (const FrameError&) {
            throw;
        } catch (const Error& e) {
            context_.reset();
            throw FrameError(cat("preview: ", e.what()));
        }
        logVerbose("preview: rendering with ", context_->description());
    }

    View view_;
    Scene scene_;  ///< a copy: callers may pass a temporary scene
    std::optional<CameraTrack> track_;  ///< made on the first frame: it may read the strand cache

    /// The camera of `frame` (camera auto reads the clip once, on first use).
    const Camera& cameraAt(int frame, const StrandFrame* hair) {
        if (!track_) track_ = makeCameraTrack(scene_, view_.camera, outputDir_);
        return track_->at(frame, hair);
    }
    DisplaySettings display_;  // PNG frames only; EXRs stay linear
    PreviewSettings settings_;
    fs::path outputDir_;
    std::string exr_, png_, sceneName_;
    std::unique_ptr<GlContext> context_;
    std::unique_ptr<PreviewRenderer> renderer_;  // destroyed before the context (declared after it)
};

}  // namespace

StagePtr makePreviewStage(const Scene& scene, const ShotSettings& shot) {
    if (!scene.flag("preview.enabled")) return nullptr;
    return std::make_unique<PreviewStage>(scene, shot);
}

}  // namespace hp
