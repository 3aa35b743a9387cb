// The shot's camera at each frame: the scene's fixed camera, or camera auto
// (render.camera.mode: auto / follow), which frames the head and its hair
// over the whole clip (render/view/camera_framing.h). The track depends only on
// the scene, never on the frames a run renders, so every chunk of a
// parallel or farm run sees the same camera.
#pragma once

#include "pipeline/scene/scene.h"
#include "render/view/camera_framing.h"
#include "sim/strands/head.h"

#include <map>

namespace hp {

class CameraTrack {
  public:
    /// The same camera on every frame.
    explicit CameraTrack(Camera fixed) : fallback_(std::move(fixed)) {}
    /// One camera per listed frame; other frames get `fallback`.
    CameraTrack(std::map<int, Camera> perFrame, Camera fallback)
        : perFrame_(std::move(perFrame)), fallback_(std::move(fallback)) {}

    /// The camera of `frame`.
    const Camera& at(int frame) const {
        const auto it = perFrame_.find(frame);
        return it == perFrame_.end() ? fallback_ : it->second;
    }
    /// True when the camera moves with the head (auto or follow).
    bool framed() const { return !perFrame_.empty(); }

  private:
    std::map<int, Camera> perFrame_;
    Camera fallback_;
};

/// @brief What camera auto must keep in the picture at each frame: every
/// vertex of the posed head (radius 0) and every scalp vertex grown by
/// `hairReach` (the hair's greatest arc length from its root).
/// @param scalp per rest triangle, 1 = grows hair (may be empty: no hair).
std::vector<FramingSample> sampleHeadForFraming(const HeadMotion& head, const std::vector<uint8_t>& scalp,
                                                float hairReach, const std::vector<int>& frames, double fps);

/// @brief Upper bound on how far any hair point lies from its root: the
/// longest strand's rest length (hair.guides.length, or hair.curly.length for
/// the curly model) plus 10% for stretch and follower interpolation, plus
/// the collision radius; 0 when the scene grows no hair.
float hairReach(const Scene& scene);

/// render.camera.azimuth/elevation/margin/facing/up and the cut thresholds
/// (simulation.cut_distance/cut_angle). makeCameraTrack finds the shot's
/// cuts as the simulation does (pipeline/head/clip_cuts.h).
FramingSettings framingSettings(const Scene& scene);

/// True when camera auto/follow frames the hair read from the strand cache
/// (render.camera.hair: cache), so the whole clip must be simulated before
/// the first frame is rendered.
bool cameraReadsStrandCache(const Scene& scene);

/// @brief Checks the camera keys across each other (render.camera.position
/// or .target given with auto/follow, where they would be ignored), at the
/// offending key. makeCameraTrack does it too; the stages call it at set-up.
void checkCameraKeys(const Scene& scene);

/// @brief The shot's camera track. `lens` is makeView(scene).camera. The mode
/// is render.camera.mode, or when not given: `fixed` if the scene gives
/// render.camera.position, else `auto`. Auto without a head (nothing to
/// frame) keeps the fixed camera. With render.camera.hair: cache (and
/// `allowCache`), the hair of every clip frame is read from the strand cache
/// under `outputDir`; a missing cache file throws FrameError naming it.
/// Without, the hair is bounded by its reach (hairReach).
CameraTrack makeCameraTrack(const Scene& scene, const Camera& lens, const std::filesystem::path& outputDir,
                            bool allowCache = true);

}  // namespace hp
