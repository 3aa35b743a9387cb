#include "render/image/image_io.h"

#include "core/errors.h"
#include "core/files.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace hp {

namespace OIIO = OIIO_NAMESPACE;

Image::Image(int w, int h, std::vector<std::string> channelNames)
    : width(w), height(h), channels(std::move(channelNames)),
      pixels(size_t(w) * size_t(h) * channels.size(), 0.f) {}

int Image::channelIndex(const std::string& name) const {
    for (size_t i = 0; i < channels.size(); ++i)
        if (channels[i] == name) return static_cast<int>(i);
    return -1;
}

namespace {

std::string lowerExtension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}

OIIO::ImageBuf toBuffer(const Image& image) {
    OIIO::ImageSpec spec(image.width, image.height, image.channelCount(), OIIO::TypeDesc::FLOAT);
    spec.channelnames = image.channels;
    spec.alpha_channel = image.channelIndex("A");
    spec.z_channel = image.channelIndex("Z");
    OIIO::ImageBuf buf(spec);
    buf.set_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, image.pixels.data());
    return buf;
}

/// Keeps R, G, B, A (whichever exist) for formats limited to colour channels.
OIIO::ImageBuf colourOnly(const OIIO::ImageBuf& in, const Image& image) {
    std::vector<int> order;
    std::vector<std::string> names;
    for (const char* name : {"R", "G", "B", "A"}) {
        const int c = image.channelIndex(name);
        if (c >= 0) {
            order.push_back(c);
            names.push_back(name);
        }
    }
    if (order.empty()) order.push_back(0), names.push_back(image.channels[0]);
    return OIIO::ImageBufAlgo::channels(in, static_cast<int>(order.size()), order, {}, names);
}

}  // namespace

void writeImage(const std::string& path, const Image& image, const ImageWriteOptions& options) {
    if (image.width <= 0 || image.height <= 0 || image.channels.empty())
        throw IoError(path, "empty image");
    const std::string ext = lowerExtension(path);
    const bool exr = ext == ".exr";
    OIIO::ImageBuf buf = toBuffer(image);
    OIIO::TypeDesc format = OIIO::TypeDesc::FLOAT;
    std::vector<OIIO::TypeDesc> channelFormats;
    if (exr) {
        if (options.halfFloat) {
            format = OIIO::TypeDesc::HALF;
            // Depth and integer-like layers keep full precision.
            for (const std::string& c : image.channels) {
                const bool precise = c == "Z" || c == "samples" || c.find("id") != std::string::npos;
                channelFormats.push_back(precise ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::HALF);
            }
        }
    } else {
        buf = colourOnly(buf, image);
        const bool eightBit = ext == ".png" || ext == ".jpg" || ext == ".jpeg";
        if (eightBit && options.srgbFor8Bit) {
            const int alpha = buf.spec().alpha_channel;
            OIIO::ROI colour = buf.roi();
            colour.chend = std::min(alpha >= 0 ? alpha : buf.nchannels(), 3);
            // Colour is premultiplied (associated) and the PNG writer divides by
            // alpha: encode the unpremultiplied colour (unpremult = true), or
            // partly covered pixels come out too bright and hue-shifted.
            OIIO::ImageBufAlgo::colorconvert(buf, buf, "linear", "sRGB", true, "", "", nullptr, colour);
        }
        format = eightBit ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT;
    }
    OIIO::ImageSpec spec = buf.spec();
    spec.set_format(format);
    if (!channelFormats.empty()) spec.channelformats = channelFormats;
    if (exr) spec.attribute("compression", "zip");
    spec.attribute("Software", "hairpipe");
    for (const auto& [key, value] : options.metadata) spec.attribute(key, value);
    // Encoded in memory, then written and checked here. On a full disk OIIO
    // 2.4's PNG writer reports nothing (a truncated frame would look finished,
    // and a resumed batch would skip it), and its JPEG writer lets libjpeg
    // call exit(), ending the whole batch.
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput proxy(bytes);
    auto out = OIIO::ImageOutput::create(path, &proxy);
    if (!out) throw IoError(path, "no image writer for this file type: " + OIIO::geterror());
    if (!out->supports("ioproxy")) throw IoError(path, "unsupported image file type " + ext + " (use .exr or .png)");
    if (!out->open(path, spec) || !buf.write(out.get()) || !out->close())
        throw IoError(path, "image encoding failed: " + out->geterror());
    writeFileChecked(path, bytes.data(), bytes.size());
}

Image readImage(const std::string& path, bool linearize) {
    if (!std::filesystem::exists(path)) throw AssetError(path, "no such file");
    OIIO::ImageBuf buf(path);
    if (!buf.read(0, 0, true, OIIO::TypeDesc::FLOAT)) throw AssetError(path, "cannot read image: " + buf.geterror());
    const OIIO::ImageSpec& spec = buf.spec();
    if (linearize && buf.nativespec().format.basetype == OIIO::TypeDesc::UINT8) {
        OIIO::ROI colour = buf.roi();
        colour.chend = std::min(spec.alpha_channel >= 0 ? spec.alpha_channel : spec.nchannels, 3);
        OIIO::ImageBufAlgo::colorconvert(buf, buf, "sRGB", "linear", false, "", "", nullptr, colour);
    }
    Image image(spec.width, spec.height, spec.channelnames);
    if (!buf.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, image.pixels.data()))
        throw AssetError(path, "cannot read pixels: " + buf.geterror());
    return image;
}

}  // namespace hp
