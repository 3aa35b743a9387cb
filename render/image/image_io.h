// Images in memory and on disk. Every read and write goes through OpenImageIO
// (render/image/image_io.cpp is the only file that includes its headers).
#pragma once

#include <string>
#include <vector>

namespace hp {

/// A float image with named, interleaved channels, top row first. Values are
/// linear (scene-referred) unless the image was read from an 8-bit file.
struct Image {
    int width = 0;
    int height = 0;
    std::vector<std::string> channels;  ///< e.g. {"R","G","B","A","Z"}
    std::vector<float> pixels;          ///< width * height * channels.size()

    Image() = default;
    Image(int w, int h, std::vector<std::string> channelNames);

    int channelCount() const { return static_cast<int>(channels.size()); }
    /// Index of a channel by name, or -1.
    int channelIndex(const std::string& name) const;
    float& at(int x, int y, int c) { return pixels[(size_t(y) * width + x) * channels.size() + c]; }
    float at(int x, int y, int c) const { return pixels[(size_t(y) * width + x) * channels.size() + c]; }
};

struct ImageWriteOptions {
    /// EXR only: store colour and alpha as half floats (depth and ids stay 32-bit float).
    bool halfFloat = true;
    /// 8-bit formats (PNG, JPEG): encode linear values to sRGB first.
    bool srgbFor8Bit = true;
    /// Extra string metadata written into the file header.
    std::vector<std::pair<std::string, std::string>> metadata;
};

/// Writes `image` to `path`; the format follows the extension (.exr, .png, ...).
/// Formats without arbitrary channels (PNG) get R, G, B and A only.
/// Throws IoError naming the file.
void writeImage(const std::string& path, const Image& image, const ImageWriteOptions& options = {});

/// Reads any image OpenImageIO can open, as float. 8-bit sRGB files are
/// returned as stored (0..1), not linearised; `linearize` converts them.
/// Throws AssetError naming the file.
Image readImage(const std::string& path, bool linearize = false);

}  // namespace hp
