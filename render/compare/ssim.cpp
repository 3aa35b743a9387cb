#include "render/compare/ssim.h"

#include "core/errors.h"

#include <tbb/parallel_for.h>

namespace hp {

ImagePlane ssimMap(const ImagePlane& x, const ImagePlane& y, const SsimSettings& s) {
    if (x.width != y.width || x.height != y.height)
        throw Error(cat("ssim: image sizes differ (", x.width, "x", x.height, " vs ", y.width, "x", y.height, ")"));
    const FilterKernel w = gaussianKernel(s.sigma, s.radius);
    const size_t n = x.size();
    ImagePlane xx(x.width, x.height), yy(x.width, x.height), xy(x.width, x.height);
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
        xx.data[i] = x.data[i] * x.data[i];
        yy.data[i] = y.data[i] * y.data[i];
        xy.data[i] = x.data[i] * y.data[i];
    });
    const ImagePlane mx = convolveSeparable(x, w, w);
    const ImagePlane my = convolveSeparable(y, w, w);
    const ImagePlane exx = convolveSeparable(xx, w, w);
    const ImagePlane eyy = convolveSeparable(yy, w, w);
    const ImagePlane exy = convolveSeparable(xy, w, w);
    const double c1 = (s.k1 * s.range) * (s.k1 * s.range);
    const double c2 = (s.k2 * s.range) * (s.k2 * s.range);
    ImagePlane out(x.width, x.height);
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
        // Double precision here: σ² = E[x²] − μ² cancels, and the constants
        // C1, C2 are small (1e-4, 9e-4) next to it.
        const double ux = mx.data[i], uy = my.data[i];
        const double vx = exx.data[i] - ux * ux;
        const double vy = eyy.data[i] - uy * uy;
        const double cxy = exy.data[i] - ux * uy;
        out.data[i] = float((2 * ux * uy + c1) * (2 * cxy + c2) / ((ux * ux + uy * uy + c1) * (vx + vy + c2)));
    });
    return out;
}

}  // namespace hp
