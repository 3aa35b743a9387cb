#include "render/image/display_transform.h"

#include "core/errors.h"

#include <OpenImageIO/color.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

namespace hp {

namespace OIIO = OIIO_NAMESPACE;
namespace IBA = OIIO::ImageBufAlgo;

namespace {

// Narkowicz 2015, "ACES Filmic Tone Mapping Curve": f(x) = x(a x + b) / (x(c x + d) + e).
constexpr float kA = 2.51f, kB = 0.03f, kC = 2.43f, kD = 0.59f, kE = 0.14f;

/// The channel `name` of `image` as a one-channel float buffer; `missing` where the image lacks it.
OIIO::ImageBuf channelBuffer(const Image& image, const char* name, float missing) {
    OIIO::ImageBuf buf(OIIO::ImageSpec(image.width, image.height, 1, OIIO::TypeDesc::FLOAT));
    const int c = image.channelIndex(name);
    if (c < 0) {
        IBA::fill(buf, {missing});
        return buf;
    }
    std::vector<float> values(size_t(image.width) * image.height);
    for (size_t i = 0; i < values.size(); ++i) values[i] = image.pixels[i * image.channels.size() + c];
    buf.set_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, values.data());
    return buf;
}

void check(bool ok, const OIIO::ImageBuf& buf, const char* what) {
    if (!ok || buf.has_error()) throw Error(std::string("display transform: ") + what + " failed: " + buf.geterror());
}

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return s;
}

/// Display-encoded colour of straight (unpremultiplied) linear colour `rgb`.
OIIO::ImageBuf displayEncode(const OIIO::ImageBuf& rgb, const DisplaySettings& s) {
    OIIO::ImageBuf out;
    if (!s.ocioConfig.empty()) {
        if (!OIIO::ColorConfig::supportsOpenColorIO())
            throw Error("render.ocio.config: this OpenImageIO was built without OpenColorIO");
        OIIO::ColorConfig config(s.ocioConfig);
        if (config.has_error()) throw Error("cannot load OCIO config " + s.ocioConfig + ": " + config.geterror());
        const std::string display = s.display.empty() ? config.getDefaultDisplayName() : s.display;
        const std::string view = s.view.empty() ? config.getDefaultViewName(display) : s.view;
        check(IBA::ociodisplay(out, rgb, display, view, s.inputSpace, "", false, "", "", &config), out,
              ("OCIO display '" + display + "' view '" + view + "' from '" + s.inputSpace + "'").c_str());
        check(IBA::clamp(out, out, 0.f, 1.f), out, "clamp");
        return out;
    }
    const std::string view = lower(s.view.empty() ? std::string("filmic") : s.view);
    OIIO::ImageBuf x;
    check(IBA::clamp(x, rgb, 0.f), x, "clamp");
    OIIO::ImageBuf y;
    if (view == "filmic") {
        OIIO::ImageBuf t, num, den;
        check(IBA::mad(t, x, kA, kB), t, "filmic curve");
        check(IBA::mul(num, x, t), num, "filmic curve");
        check(IBA::mad(t, x, kC, kD), t, "filmic curve");
        check(IBA::mad(den, x, t, kE), den, "filmic curve");
        check(IBA::div(y, num, den), y, "filmic curve");
        check(IBA::clamp(y, y, 0.f, 1.f), y, "clamp");
    } else if (view == "standard") {
        check(IBA::clamp(y, x, 0.f, 1.f), y, "clamp");
    } else {
        throw Error("unknown built-in view '" + s.view + "' (built-in views: filmic, standard)");
    }
    check(IBA::colorconvert(out, y, "linear", "sRGB", false), out, "sRGB encoding");
    return out;
}

}  // namespace

float filmicCurve(float x) {
    x = std::max(x, 0.f);
    return std::clamp(x * (kA * x + kB) / (x * (kC * x + kD) + kE), 0.f, 1.f);
}

void checkDisplaySettings(const DisplaySettings& settings) {
    if (!settings.ocioConfig.empty() && !std::filesystem::is_regular_file(settings.ocioConfig))
        throw Error("no OCIO config file " + settings.ocioConfig);
    Image probe(1, 1, {"R", "G", "B"});
    probe.pixels = {0.18f, 0.18f, 0.18f};
    toDisplay(probe, settings);  // throws what a frame would
}

Image toDisplay(const Image& linear, const DisplaySettings& s) {
    if (linear.width <= 0 || linear.height <= 0) throw Error("display transform: empty image");
    const bool hasAlpha = linear.channelIndex("A") >= 0;
    const char* names[3] = {"R", "G", "B"};
    // A single-channel image shows as grey.
    const bool grey = linear.channelIndex("R") < 0;
    OIIO::ImageBuf rgb;
    {
        OIIO::ImageBuf c[3];
        for (int i = 0; i < 3; ++i) {
            c[i] = grey ? channelBuffer(linear, linear.channels[0].c_str(), 0.f) : channelBuffer(linear, names[i], 0.f);
        }
        OIIO::ImageBuf rg;
        check(IBA::channel_append(rg, c[0], c[1]), rg, "channels");
        check(IBA::channel_append(rgb, rg, c[2]), rgb, "channels");
    }
    const OIIO::ImageBuf alpha = channelBuffer(linear, "A", 1.f);
    OIIO::ImageBuf alpha3;
    check(IBA::channels(alpha3, alpha, 3, {0, 0, 0}), alpha3, "channels");

    const float gain = std::exp2(s.exposure);
    if (gain != 1.f) check(IBA::mul(rgb, rgb, gain), rgb, "exposure");

    const bool opaque = s.backdrop.kind != Backdrop::Kind::None;
    OIIO::ImageBuf straight;
    if (opaque) {
        // Premultiplied over: C + (1 − A) · backdrop, in linear light.
        const Vec3f& t = s.backdrop.top;
        const Vec3f& b = s.backdrop.kind == Backdrop::Kind::Gradient ? s.backdrop.bottom : s.backdrop.top;
        OIIO::ImageBuf back(rgb.spec()), uncovered;
        check(IBA::fill(back, {t.x(), t.y(), t.z()}, {b.x(), b.y(), b.z()}), back, "backdrop");
        // 1 − A as A·(−1) + 1: OIIO 2.4's sub(constant, image) computes image − constant.
        check(IBA::mad(uncovered, alpha3, -1.f, 1.f), uncovered, "backdrop");
        check(IBA::mad(straight, uncovered, back, rgb), straight, "backdrop");
    } else {
        // Colour is premultiplied: transform the straight colour (0 where A = 0).
        check(IBA::div(straight, rgb, alpha3), straight, "unpremultiply");
    }
    OIIO::ImageBuf shown = displayEncode(straight, s);

    std::vector<std::string> channels{"R", "G", "B"};
    if (hasAlpha || opaque) channels.push_back("A");
    Image out(linear.width, linear.height, channels);
    std::vector<float> colour(size_t(linear.width) * linear.height * 3);
    std::vector<float> a(size_t(linear.width) * linear.height);
    shown.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, colour.data());
    alpha.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, a.data());
    const size_t n = channels.size();
    for (size_t i = 0; i < a.size(); ++i) {
        const float w = opaque ? 1.f : std::clamp(a[i], 0.f, 1.f);
        for (size_t c = 0; c < 3; ++c) out.pixels[i * n + c] = colour[i * 3 + c] * w;
        if (n == 4) out.pixels[i * n + 3] = w;
    }
    return out;
}

void writeImageWithDisplay(const std::string& path, const Image& image, const DisplaySettings& display,
                           ImageWriteOptions options) {
    std::string ext = std::filesystem::path(path).extension().string();
    ext = lower(ext);
    if (ext != ".png" && ext != ".jpg" && ext != ".jpeg") return writeImage(path, image, options);
    options.srgbFor8Bit = false;  // display-encoded already
    writeImage(path, toDisplay(image, display), options);
}

}  // namespace hp
