// The shot's camera at each frame: the scene's fixed camera, or camera auto
// (render.camera.mode: auto / follow), which frames the head and its hair
// over the whole clip (render/view/camera_framing.h). A frame's camera depends
// only on the scene and (render.camera.hair: cache) on the cached hair of that
// frame (follow) or of its cut-free segment (auto), never on the frames a run
// renders, so a one-frame run, every chunk of a parallel or farm run and a
// whole-clip run see the same camera, bit for bit. The head is sampled over
// the whole clip (cheap: posed meshes), but the strand cache is read only for
// the frames a camera needs, so rendering frame 3 needs frame 3 simulated, not
// the clip.
#pragma once

#include "pipeline/scene/scene.h"
#include "render/view/camera_framing.h"
#include "sim/strands/head.h"

#include <memory>
#include <vector>

namespace hp {

class CameraFraming;  // camera auto/follow's state (camera_track.cpp)

class CameraTrack {
  public:
    /// The same camera on every frame.
    explicit CameraTrack(Camera fixed) : fallback_(std::move(fixed)) {}
    /// Camera auto/follow: frames are framed on first use (at()); frames
    /// outside the scene's clip get `fallback`.
    CameraTrack(std::shared_ptr<const CameraFraming> framing, Camera fallback)
        : framing_(std::move(framing)), fallback_(std::move(fallback)) {}

    /// The camera of `frame`. With render.camera.hair: cache it reads the
    /// strand cache of only the frames cacheFramesFor(frame) names, on first
    /// use; a missing cache file throws FrameError naming it.
    const Camera& at(int frame) const { return at(frame, nullptr); }
    /// The same, given the frame's own strands when the caller has them
    /// (the stages' frame data): camera follow then frames them instead of
    /// reading (and rebuilding) the cache file again. Equal bits either way.
    const Camera& at(int frame, const StrandFrame* hair) const;
    /// True when the camera moves with the head (auto or follow).
    bool framed() const { return framing_ != nullptr; }
    /// The strand cache frames at(frame) reads: follow, the frame itself;
    /// auto, every frame of its cut-free segment (framed as a whole); none
    /// when the hair is bounded by its reach or the camera is fixed.
    std::vector<int> cacheFramesFor(int frame) const;

  private:
    std::shared_ptr<const CameraFraming> framing_;
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
/// (render.camera.hair: cache), so a frame's strands must be simulated (and
/// cached) before it is rendered.
bool cameraReadsStrandCache(const Scene& scene);

/// @brief The strand cache frames the cameras of `frames` read (sorted,
/// unique): `frames` themselves in follow mode, the whole cut-free segments
/// holding them in auto mode, none unless cameraReadsStrandCache. What a
/// run must simulate before it renders `frames`.
std::vector<int> cameraCacheFrames(const Scene& scene, const std::vector<int>& frames);

/// @brief Checks the camera keys across each other (render.camera.position
/// or .target given with auto/follow, where they would be ignored), at the
/// offending key. makeCameraTrack does it too; the stages call it at set-up.
void checkCameraKeys(const Scene& scene);

/// @brief The shot's camera track. `lens` is makeView(scene).camera. The mode
/// is render.camera.mode, or when not given: `fixed` if the scene gives
/// render.camera.position, else `auto`. Auto without a head (nothing to
/// frame) keeps the fixed camera. With render.camera.hair: cache (and
/// `allowCache`), the hair is read from the strand cache under `outputDir`,
/// lazily: at(frame) reads cacheFramesFor(frame) and throws FrameError naming
/// a missing file. Without, the hair is bounded by its reach (hairReach).
CameraTrack makeCameraTrack(const Scene& scene, const Camera& lens, const std::filesystem::path& outputDir,
                            bool allowCache = true);

}  // namespace hp
