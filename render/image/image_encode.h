// Images encoded in memory (for embedding in reports) and resized previews,
// both through OpenImageIO.
#pragma once

#include "render/image/image_io.h"

#include <string>

namespace hp {

/// PNG file bytes of the R, G, B (and A) channels of `image`, 8-bit. With
/// `srgbEncode` linear values are encoded to sRGB first; without it the values
/// are taken as display values already (e.g. a colour-mapped heat map).
/// Throws IoError ("<memory>") if encoding fails.
std::string encodePng(const Image& image, bool srgbEncode);

/// A `data:image/png;base64,...` URI of encodePng(image, srgbEncode), for
/// embedding in HTML without any external file.
std::string pngDataUri(const Image& image, bool srgbEncode);

/// `image` resized to `width` pixels wide (height keeps the aspect ratio,
/// at least 1), filtered by OpenImageIO's default resampling filter. Images
/// no wider than `width` are returned unchanged.
Image resizeToWidth(const Image& image, int width);

}  // namespace hp
