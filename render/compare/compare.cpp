#include "render/compare/compare.h"

#include "core/errors.h"
#include "render/image/colormap.h"
#include "render/compare/ssim.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <tbb/parallel_for.h>

#include <array>
#include <cmath>
#include <limits>

namespace hp {

namespace OIIO = OIIO_NAMESPACE;

namespace {

float displayValue(float v) {
    if (std::isnan(v)) return 0.f;
    return v < 0.f ? 0.f : (v > 1.f ? 1.f : v);
}

/// Channel indices of R, G, B; images without them are grey in their first channel.
std::array<int, 3> rgbChannels(const Image& image) {
    const int r = image.channelIndex("R"), g = image.channelIndex("G"), b = image.channelIndex("B");
    if (r >= 0 && g >= 0 && b >= 0) return {r, g, b};
    const int y = image.channelIndex("Y");
    if (y >= 0) return {y, y, y};
    if (image.channelCount() >= 3) return {0, 1, 2};
    return {0, 0, 0};
}

RgbPlanes displayPlanes(const Image& image) {
    if (image.channelCount() == 0 || image.width <= 0 || image.height <= 0) throw Error("empty image");
    const std::array<int, 3> ch = rgbChannels(image);
    RgbPlanes p{ImagePlane(image.width, image.height), ImagePlane(image.width, image.height), ImagePlane(image.width, image.height)};
    const size_t stride = image.channels.size();
    tbb::parallel_for(size_t(0), p.r.size(), [&](size_t i) {
        const float* px = &image.pixels[i * stride];
        p.r.data[i] = displayValue(px[ch[0]]);
        p.g.data[i] = displayValue(px[ch[1]]);
        p.b.data[i] = displayValue(px[ch[2]]);
    });
    return p;
}

float srgbEncode(float v) {
    return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
}

ImagePlane luma(const RgbPlanes& p) {
    ImagePlane out(p.width(), p.height());
    tbb::parallel_for(size_t(0), out.size(), [&](size_t i) {
        out.data[i] = srgbEncode(0.2126f * p.r.data[i] + 0.7152f * p.g.data[i] + 0.0722f * p.b.data[i]);
    });
    return out;
}

ImagePlane makeMask(const Image& a, const Image& b, MaskMode mode) {
    ImagePlane mask(a.width, a.height, 1.f);
    if (mode == MaskMode::None) return mask;
    const int aa = a.channelIndex("A"), ba = b.channelIndex("A");
    if (aa < 0 && ba < 0) throw Error("the hair mask needs an alpha channel (A), and neither image has one");
    for (size_t i = 0; i < mask.size(); ++i) {
        const bool inA = aa >= 0 && a.pixels[i * a.channels.size() + size_t(aa)] > 0.f;
        const bool inB = ba >= 0 && b.pixels[i * b.channels.size() + size_t(ba)] > 0.f;
        mask.data[i] = inA || inB ? 1.f : 0.f;
    }
    return mask;
}

/// Interleaved RGB ImageBuf of the display values, zero outside the mask.
OIIO::ImageBuf maskedBuffer(const RgbPlanes& p, const ImagePlane& mask) {
    OIIO::ImageSpec spec(p.width(), p.height(), 3, OIIO::TypeDesc::FLOAT);
    std::vector<float> rgb(p.r.size() * 3);
    for (size_t i = 0; i < p.r.size(); ++i) {
        rgb[3 * i + 0] = p.r.data[i] * mask.data[i];
        rgb[3 * i + 1] = p.g.data[i] * mask.data[i];
        rgb[3 * i + 2] = p.b.data[i] * mask.data[i];
    }
    OIIO::ImageBuf buf(spec);
    buf.set_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, rgb.data());
    return buf;
}

/// Mean of `map` over the mask, summed in a fixed order (thread-count independent).
double maskedMean(const ImagePlane& map, const ImagePlane& mask, long count) {
    if (count == 0) return 0.0;
    double sum = 0;
    for (size_t i = 0; i < map.size(); ++i)
        if (mask.data[i] > 0.f) sum += map.data[i];
    return sum / double(count);
}

}  // namespace

Comparison compareImages(const Image& reference, const Image& test, const CompareSettings& settings) {
    if (reference.width != test.width || reference.height != test.height)
        throw Error(cat("resolutions differ: ", reference.width, "x", reference.height, " vs ", test.width, "x",
                        test.height));
    Comparison c;
    const RgbPlanes a = displayPlanes(reference);
    const RgbPlanes b = displayPlanes(test);
    c.mask = makeMask(reference, test, settings.mask);
    long count = 0;
    for (float m : c.mask.data) count += m > 0.f;
    FrameMetrics& m = c.metrics;
    m.pixels = count;

    // RMSE and the largest difference: OpenImageIO over the masked pixels
    // (zero in both images outside the mask), rescaled from all pixels to the
    // mask's. One thread keeps the sums' order, hence the result, fixed.
    const OIIO::ImageBufAlgo::CompareResults r =
        OIIO::ImageBufAlgo::compare(maskedBuffer(a, c.mask), maskedBuffer(b, c.mask), 1.f, 1.f, OIIO::ROI(), 1);
    if (r.error) throw Error("image comparison failed (OpenImageIO compare)");
    const double all = double(c.mask.size());
    m.rmse = count ? r.rms_error * std::sqrt(all / double(count)) : 0.0;
    m.psnr = m.rmse > 0 ? 20.0 * std::log10(1.0 / m.rmse) : std::numeric_limits<double>::infinity();
    m.maxError = r.maxerror;

    c.ssimMap = ssimMap(luma(a), luma(b));
    m.ssim = count ? maskedMean(c.ssimMap, c.mask, count) : 1.0;
    c.flipMap = flipErrorMap(a, b, settings.flip);
    m.flip = maskedMean(c.flipMap, c.mask, count);

    c.absDiff = Image(reference.width, reference.height, {"R", "G", "B"});
    tbb::parallel_for(size_t(0), a.r.size(), [&](size_t i) {
        c.absDiff.pixels[3 * i + 0] = std::abs(a.r.data[i] - b.r.data[i]);
        c.absDiff.pixels[3 * i + 1] = std::abs(a.g.data[i] - b.g.data[i]);
        c.absDiff.pixels[3 * i + 2] = std::abs(a.b.data[i] - b.b.data[i]);
    });
    return c;
}

Image flipHeatmap(const ImagePlane& flipMap) {
    Image out(flipMap.width, flipMap.height, {"R", "G", "B"});
    tbb::parallel_for(size_t(0), flipMap.size(), [&](size_t i) {
        const std::array<float, 3> c = magma(flipMap.data[i]);
        for (int k = 0; k < 3; ++k) out.pixels[3 * i + size_t(k)] = c[size_t(k)];
    });
    return out;
}

Image displayImage(const Image& image) {
    const RgbPlanes p = displayPlanes(image);
    Image out(image.width, image.height, {"R", "G", "B"});
    for (size_t i = 0; i < p.r.size(); ++i) {
        out.pixels[3 * i + 0] = p.r.data[i];
        out.pixels[3 * i + 1] = p.g.data[i];
        out.pixels[3 * i + 2] = p.b.data[i];
    }
    return out;
}

}  // namespace hp
