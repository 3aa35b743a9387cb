// The interactive preview viewer: the same GL pass as the preview stage, in a
// GLFW window, with play/pause, frame scrubbing, an orbit camera and toggles
// for Dehlin and Styngberg's shadow variants. A scripted mode (exitAfter) renders a few
// frames, saves a screenshot and quits, for tests and remote checks.
#pragma once

#include "render/preview/preview.h"

#include <functional>
#include <string>
#include <vector>

namespace hp {

/// Geometry of one frame for the viewer; pointers may be null and must stay
/// valid until the provider is called again.
struct ViewerFrame {
    double time = 0.0;
    const StrandFrame* strands = nullptr;
    const TriangleMesh* head = nullptr;
    Eigen::Isometry3f headTransform = Eigen::Isometry3f::Identity();
};

/// Supplies a frame's geometry, called with any frame of ViewerOptions::frames
/// in any order (scrubbing goes backwards). Throws hp::Error on failure.
using ViewerFrameProvider = std::function<ViewerFrame(int frame)>;

struct ViewerOptions {
    std::vector<int> frames{1};  ///< the frames to play and scrub through
    double fps = 24.0;
    int width = 1280;            ///< initial window size; the render follows the window
    int height = 720;
    bool play = true;            ///< start playing
    /// Scripted mode: quit after displaying this many frames (0 = interactive).
    int exitAfter = 0;
    /// Scripted mode: write the last displayed frame (what the window shows) here.
    std::string screenshot;
};

/// Opens the window and runs until it is closed (or exitAfter frames).
/// Keys: space play/pause, left/right step, home/end first/last frame,
/// V voxel shadows, M shadow map, B voxel mode (binary-nearest,
/// additive-nearest, additive-trilinear), S sum along the light, X voxel
/// lookup filter, G generated hair, H head, F per-fragment shading, R reset
/// camera, Q/Esc quit.
/// Mouse: left-drag orbits around the camera target, wheel zooms.
/// Throws hp::Error when no window with OpenGL 4.5 core can be opened (no
/// display: the message says so).
void runViewer(const View& view, const PreviewSettings& settings, const ViewerFrameProvider& frames,
               const ViewerOptions& options);

}  // namespace hp
