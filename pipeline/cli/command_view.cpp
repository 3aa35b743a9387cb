// `hairpipe view scene.yaml`: the preview pass in an interactive window
// (render/preview/viewer.h), fed by the scene's frame source.
#include "core/log.h"
#include "pipeline/head/animated_head.h"
#include "pipeline/stages/camera_track.h"
#include "pipeline/cli/commands.h"
#include "pipeline/scene/preview_settings.h"
#include "pipeline/stages/stages.h"
#include "pipeline/scene/view_settings.h"
#include "render/preview/viewer.h"
#include "sim/strands/synthetic.h"

#include <climits>
#include <cstdio>
#include <optional>

namespace hp {

namespace {

/// Frames from the scene's frame source, which only moves forward: going
/// back restarts it (cheap until the simulation is wired in; see the note in
/// the report to the lead about caching).
class SourceFrames {
  public:
    SourceFrames(const Scene& scene, ShotSettings shot) : scene_(scene), shot_(std::move(shot)) {}

    ViewerFrame get(int frame) {
        if (frame != current_) {
            if (!source_ || frame < current_) source_ = makeFrameSource(scene_, shot_);
            data_ = source_->get(frame);
            current_ = frame;
            // The head with the visible colliders beside it: built once per
            // frame, not on every redraw (the viewer asks ~60 times a second).
            head_ = data_.head ? &drawnMesh(*data_.head, drawn_) : nullptr;
        }
        ViewerFrame f;
        f.time = data_.time;
        f.strands = data_.strands;
        f.head = head_;
        if (data_.head) f.headTransform = data_.head->transform;
        return f;
    }

  private:
    const Scene& scene_;
    ShotSettings shot_;
    std::unique_ptr<FrameSource> source_;
    FrameData data_;
    TriangleMesh drawn_;  ///< the head and its scenery, while the frame is shown
    const TriangleMesh* head_ = nullptr;  ///< drawn_, or data_'s head mesh when it has no scenery
    int current_ = INT_MIN;
};

}  // namespace

CommandSpec viewCommandSpec() {
    CommandSpec c{"view", "[options] scene.yaml",
                  "show the GL preview in a window: play, scrub, orbit, toggle shadows"};
    c.details =
        "Keys: space play/pause, left/right step, home/end, V voxel shadows, M shadow map,\n"
        "B voxel mode (binary-nearest, additive-nearest, additive-trilinear), S sum along\n"
        "the light, X voxel lookup filter, G generated hair, H head, F per-fragment shading,\n"
        "R reset camera, Q quit.\n"
        "Mouse: drag to orbit, wheel to zoom. Needs a display (X11); headless frames come\n"
        "from `hairpipe render --preview`.";
    c.options = {{"--size", "WxH", "window size (default 1280x720)"},
                 {"--paused", "", "start paused on the first frame"},
                 {"--synthetic", "N", "show N synthetic strands on a sphere head (look check, no simulation)"},
                 {"--exit-after", "N", "scripted: quit after displaying N frames"},
                 {"--screenshot", "FILE", "scripted: save the last displayed frame (PNG)"}};
    c.run = [](const CommandLine& cl) {
        CommandContext ctx(cl);
        const ShotSettings shot = resolveShot(ctx.scene, ctx.options);
        View view = makeView(ctx.scene);
        try {  // the orbit starts from the shot's camera
            view.camera = makeCameraTrack(ctx.scene, view.camera, shot.outputDir).at(shot.frames.front());
        } catch (const FrameError& e) {
            logWarning(e.what(), "; framing the hair by its reach instead");
            view.camera = makeCameraTrack(ctx.scene, view.camera, shot.outputDir, false).at(shot.frames.front());
        }
        const PreviewSettings settings = makePreviewSettings(ctx.scene);
        ViewerOptions options;
        options.frames = shot.frames;
        options.fps = shot.fps;
        options.play = !cl.has("--paused");
        if (cl.has("--exit-after")) options.exitAfter = int(integerOption(cl, "--exit-after", 1, 1000000));
        if (cl.has("--screenshot")) {
            if (!options.exitAfter) throw UsageError("option --screenshot needs --exit-after N");
            options.screenshot = cl.value("--screenshot");
        }
        if (cl.has("--size")) {
            const std::string size = cl.value("--size");
            if (std::sscanf(size.c_str(), "%dx%d", &options.width, &options.height) != 2 || options.width < 16 ||
                options.height < 16 || options.width > 16384 || options.height > 16384)
                throw UsageError("option --size expects WxH, e.g. 1280x720, got '" + size + "'");
        }
        SourceFrames source(ctx.scene, shot);
        std::optional<StrandFrame> synthetic;
        TriangleMesh sphere;
        if (cl.has("--synthetic")) {
            SyntheticHairSettings hs;
            hs.strands = size_t(integerOption(cl, "--synthetic", 1, 10000000));
            synthetic = makeSyntheticHair(hs);
            sphere = makeSphereMesh(Vec3f::Zero(), hs.headRadius, 32, 64);
        }
        runViewer(view, settings,
                  [&](int frame) {
                      ViewerFrame f = source.get(frame);
                      if (synthetic) f.strands = &*synthetic, f.head = &sphere;
                      return f;
                  },
                  options);
        return int(kExitOk);
    };
    return c;
}

}  // namespace hp
