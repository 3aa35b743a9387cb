// @brief The view transform from scene-referred linear radiance to display
// images (PNG / JPEG previews and references). EXRs never pass through it:
// they stay linear, scene-referred, with their alpha.
//
// Two paths, both through OpenImageIO's ImageBufAlgo:
// - an OpenColorIO config (`ocioConfig`): ImageBufAlgo::ociodisplay from the
//   config's `inputSpace` to (display, view), with OIIO's ColorConfig;
// - without one, the built-in views. "filmic" (default) is an analytic
//   filmic curve, Narkowicz's 2015 fit of the ACES reference rendering and
//   output transforms,
//       f(x) = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14),  clamped to [0, 1],
//   (toe below ~0.05, mid grey 0.18 -> 0.267, shoulder reaching 1 at x ~ 7.2)
//   followed by the sRGB transfer function; "standard" is the sRGB
//   transfer function alone (clips at 1).
// Exposure (stops) scales the linear values first. The backdrop, when set,
// is composited under the image in linear light after the exposure (so it
// looks the same at every exposure), and the result is opaque.
#pragma once

#include "render/image/image_io.h"
#include "sim/strands/strand.h"

#include <string>

namespace hp {

/// What fills the display image where the render is transparent.
struct Backdrop {
    enum class Kind { None, Color, Gradient };
    Kind kind = Kind::None;
    Vec3f top{0.05f, 0.05f, 0.05f};     ///< linear RGB; the colour itself for Kind::Color
    Vec3f bottom{0.02f, 0.02f, 0.02f};  ///< Gradient: linear RGB at the bottom row
};

struct DisplaySettings {
    std::string ocioConfig;                   ///< OCIO config file; empty = built-in views
    std::string inputSpace = "scene_linear";  ///< OCIO: colour space (or role) of the renders
    std::string display;                      ///< OCIO display; empty = the config's default
    std::string view;                         ///< view; empty = "filmic" built in, or the display's default
    float exposure = 0.f;                     ///< stops
    Backdrop backdrop;
};

/// The built-in filmic curve f(x) of the file comment, for one scene-linear
/// value (before the sRGB transfer function). Documentation and tests.
float filmicCurve(float x);

/// Checks that the settings can be applied (the config loads, the display
/// and view exist, a built-in view name is known). Throws hp::Error saying
/// what is wrong.
void checkDisplaySettings(const DisplaySettings& settings);

/// R, G, B (and A) of `linear` (premultiplied, scene-referred) turned into
/// display-encoded values in [0, 1], still premultiplied by A, ready for an
/// 8-bit file (ImageWriteOptions::srgbFor8Bit = false). With a backdrop A is
/// 1 everywhere. Other channels are dropped. Throws hp::Error.
Image toDisplay(const Image& linear, const DisplaySettings& settings);

/// Writes `image` to `path`: EXR (and other float formats) as they are,
/// PNG / JPEG through toDisplay(). Throws IoError / hp::Error.
void writeImageWithDisplay(const std::string& path, const Image& image, const DisplaySettings& display,
                           ImageWriteOptions options = {});

}  // namespace hp
