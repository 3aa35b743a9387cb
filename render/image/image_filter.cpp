#include "render/image/image_filter.h"

#include "core/errors.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace hp {

FilterKernel gaussianKernel(double sigma, int radius) {
    if (sigma <= 0 || radius < 0) throw Error(cat("gaussianKernel: bad sigma ", sigma, " or radius ", radius));
    FilterKernel k(size_t(2 * radius + 1));
    double sum = 0;
    for (int i = -radius; i <= radius; ++i) sum += std::exp(-0.5 * i * i / (sigma * sigma));
    for (int i = -radius; i <= radius; ++i) k[size_t(i + radius)] = float(std::exp(-0.5 * i * i / (sigma * sigma)) / sum);
    return k;
}

namespace {

int radiusOf(const FilterKernel& k) {
    if (k.empty() || k.size() % 2 == 0) throw Error(cat("convolution kernel must have odd length, got ", k.size()));
    return int(k.size() / 2);
}

}  // namespace

ImagePlane convolveRows(const ImagePlane& in, const FilterKernel& k) {
    const int r = radiusOf(k);
    const int w = in.width;
    ImagePlane out(in.width, in.height);
    tbb::parallel_for(tbb::blocked_range<int>(0, in.height), [&](const tbb::blocked_range<int>& rows) {
        // One padded copy of the row makes the inner loop branch-free (and
        // vectorisable): taps outside the image read the replicated edge.
        std::vector<float> padded(size_t(w + 2 * r));
        for (int y = rows.begin(); y != rows.end(); ++y) {
            const float* src = &in.data[size_t(y) * w];
            for (int i = 0; i < r; ++i) {
                padded[size_t(i)] = src[0];
                padded[size_t(r + w + i)] = src[w - 1];
            }
            std::copy(src, src + w, padded.begin() + r);
            float* dst = &out.data[size_t(y) * w];
            std::fill(dst, dst + w, 0.f);
            for (int t = 0; t <= 2 * r; ++t) {
                const float kt = k[size_t(t)];
                const float* p = padded.data() + t;
                for (int x = 0; x < w; ++x) dst[x] += kt * p[x];
            }
        }
    });
    return out;
}

ImagePlane convolveColumns(const ImagePlane& in, const FilterKernel& k) {
    const int r = radiusOf(k);
    const int w = in.width;
    const int h = in.height;
    ImagePlane out(in.width, in.height);
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y != rows.end(); ++y) {
            float* dst = &out.data[size_t(y) * w];
            for (int t = 0; t <= 2 * r; ++t) {
                const int sy = std::clamp(y + t - r, 0, h - 1);
                const float kt = k[size_t(t)];
                const float* src = &in.data[size_t(sy) * w];
                for (int x = 0; x < w; ++x) dst[x] += kt * src[x];
            }
        }
    });
    return out;
}

ImagePlane convolveSeparable(const ImagePlane& in, const FilterKernel& kx, const FilterKernel& ky) {
    return convolveColumns(convolveRows(in, kx), ky);
}

}  // namespace hp
