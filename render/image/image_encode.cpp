#include "render/image/image_encode.h"

#include "core/errors.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/strutil.h>

#include <algorithm>

namespace hp {

namespace OIIO = OIIO_NAMESPACE;

namespace {

OIIO::ImageBuf toBuffer(const Image& image) {
    OIIO::ImageSpec spec(image.width, image.height, image.channelCount(), OIIO::TypeDesc::FLOAT);
    spec.channelnames = image.channels;
    OIIO::ImageBuf buf(spec);
    buf.set_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, image.pixels.data());
    return buf;
}

Image fromBuffer(const OIIO::ImageBuf& buf) {
    const OIIO::ImageSpec& spec = buf.spec();
    Image image(spec.width, spec.height, spec.channelnames);
    buf.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, image.pixels.data());
    return image;
}

}  // namespace

std::string encodePng(const Image& image, bool srgbEncode) {
    if (image.width <= 0 || image.height <= 0 || image.channels.empty()) throw IoError("<memory>", "empty image");
    std::vector<int> order;
    std::vector<std::string> names;
    for (const char* name : {"R", "G", "B", "A"}) {
        const int c = image.channelIndex(name);
        if (c >= 0) order.push_back(c), names.push_back(name);
    }
    if (order.empty()) order.push_back(0), names.push_back("Y");
    OIIO::ImageBuf buf = OIIO::ImageBufAlgo::channels(toBuffer(image), int(order.size()), order, {}, names);
    const int alpha = image.channelIndex("A") >= 0 ? int(order.size()) - 1 : -1;
    buf.specmod().alpha_channel = alpha;
    if (srgbEncode) {
        OIIO::ROI colour = buf.roi();
        colour.chend = std::min(alpha >= 0 ? alpha : buf.nchannels(), 3);
        OIIO::ImageBufAlgo::colorconvert(buf, buf, "linear", "sRGB", false, "", "", nullptr, colour);
    }
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput proxy(bytes);
    auto out = OIIO::ImageOutput::create("image.png", &proxy);
    if (!out) throw IoError("<memory>", "no PNG writer: " + OIIO::geterror());
    OIIO::ImageSpec spec = buf.spec();
    spec.set_format(OIIO::TypeDesc::UINT8);
    spec.attribute("Software", "hairpipe");
    if (!out->open("image.png", spec) || !buf.write(out.get()) || !out->close())
        throw IoError("<memory>", "PNG encoding failed: " + out->geterror());
    return std::string(bytes.begin(), bytes.end());
}

std::string pngDataUri(const Image& image, bool srgbEncode) {
    return "data:image/png;base64," + OIIO::Strutil::base64_encode(encodePng(image, srgbEncode));
}

Image resizeToWidth(const Image& image, int width) {
    if (width <= 0 || image.width <= width) return image;
    const int height = std::max(1, int(double(image.height) * width / image.width + 0.5));
    OIIO::ImageSpec spec(width, height, image.channelCount(), OIIO::TypeDesc::FLOAT);
    spec.channelnames = image.channels;
    OIIO::ImageBuf dst(spec);
    if (!OIIO::ImageBufAlgo::resize(dst, toBuffer(image), "", 0.f, OIIO::ROI::All(), 1))
        throw Error("resize failed: " + dst.geterror());
    return fromBuffer(dst);
}

}  // namespace hp
