#include "render/compare/flip.h"

#include "core/errors.h"

#include <Eigen/Dense>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <utility>

namespace hp {

namespace {

using Eigen::Matrix3f;
using Eigen::Vector3f;

// Constants of the paper (section 4): colour and feature exponents, the
// error redistribution breakpoints, and the feature detector's width.
constexpr float kQc = 0.7f;
constexpr float kPc = 0.4f;
constexpr float kPt = 0.95f;
constexpr float kQf = 0.5f;
constexpr double kFeatureWidthDegrees = 0.082;
constexpr double kPi = 3.14159265358979323846;

/// Linear sRGB (D65) ↔ CIE XYZ, and the reference white: XYZ of RGB (1, 1, 1),
/// so that white maps to Y' = 100, Cx = Cz = 0 and L* = 100, a* = b* = 0.
struct ColourSpace {
    Matrix3f rgbToXyz;
    Matrix3f xyzToRgb;
    Vector3f white;
    Vector3f invWhite;
    ColourSpace() {
        Eigen::Matrix3d m;
        m << 0.4124564, 0.3575761, 0.1804375,  //
            0.2126729, 0.7151522, 0.0721750,   //
            0.0193339, 0.1191920, 0.9503041;
        rgbToXyz = m.cast<float>();
        xyzToRgb = m.inverse().cast<float>();
        white = (m * Eigen::Vector3d::Ones()).cast<float>();
        invWhite = white.cwiseInverse();
    }
};

const ColourSpace& space() {
    static const ColourSpace s;
    return s;
}

Vector3f rgbToYcxcz(const Vector3f& rgb) {
    const Vector3f n = (space().rgbToXyz * rgb).cwiseProduct(space().invWhite);
    return {116.f * n.y() - 16.f, 500.f * (n.x() - n.y()), 200.f * (n.y() - n.z())};
}

Vector3f ycxczToRgb(const Vector3f& v) {
    const float ny = (v[0] + 16.f) / 116.f;
    const Vector3f n(ny + v[1] / 500.f, ny, ny - v[2] / 200.f);
    return space().xyzToRgb * n.cwiseProduct(space().white);
}

/// Cube root of t > 0: a bit-level first guess (within 3.5%) refined by two
/// Halley steps x ← x(x³ + 2t)/(2x³ + t) (cubic convergence; relative error
/// < 3e-7 over CIELAB's range), several times faster than std::cbrt, and
/// CIELAB needs three per pixel of both images.
float cubeRoot(float t) {
    std::uint32_t bits;
    std::memcpy(&bits, &t, sizeof bits);
    bits = bits / 3 + 709921077u;  // divides the exponent by 3
    float x;
    std::memcpy(&x, &bits, sizeof x);
    for (int i = 0; i < 2; ++i) {
        const float x3 = x * x * x;
        x *= (x3 + 2.f * t) / (2.f * x3 + t);
    }
    return x;
}

/// CIELAB of a linear RGB colour with the Hunt adjustment (a, b scaled by 0.01·L).
Vector3f rgbToHuntLab(const Vector3f& rgb) {
    const Vector3f n = (space().rgbToXyz * rgb).cwiseProduct(space().invWhite);
    constexpr float d = 6.f / 29.f;
    auto f = [](float t) { return t > d * d * d ? cubeRoot(t) : t / (3.f * d * d) + 4.f / 29.f; };
    const float fx = f(n.x()), fy = f(n.y()), fz = f(n.z());
    const float L = 116.f * fy - 16.f;
    return {L, 0.01f * L * 500.f * (fx - fy), 0.01f * L * 200.f * (fy - fz)};
}

float hyab(const Vector3f& p, const Vector3f& q) {
    const float da = p[1] - q[1], db = p[2] - q[2];
    return std::abs(p[0] - q[0]) + std::sqrt(da * da + db * db);
}

/// Maps the exponentiated HyAB distance to [0, 1] (paper eq. 5).
float redistribute(float e, float cmax) {
    const float knee = kPc * cmax;
    return e < knee ? kPt / knee * e : kPt + (e - knee) / (cmax - knee) * (1.f - kPt);
}

/// One Gaussian term a·sqrt(π/b)·exp(−π²r²/b) of a contrast sensitivity function.
struct CsfTerm {
    double a, b;
};

/// A 2-D filter that is a weighted sum of separable Gaussians.
struct GaussianSum {
    std::vector<std::pair<float, FilterKernel>> terms;  ///< (weight, normalised 1-D kernel)

    ImagePlane apply(const ImagePlane& in) const {
        ImagePlane out(in.width, in.height);
        for (const auto& [weight, k] : terms) {
            const ImagePlane part = convolveSeparable(in, k, k);
            for (size_t i = 0; i < out.size(); ++i) out.data[i] += weight * part.data[i];
        }
        return out;
    }
};

/// The sampled CSF filter of one channel, normalised to sum 1. Each 2-D
/// Gaussian factorises into 1-D ones, so the filter is a weighted sum of
/// separable passes; the weights are the terms' sampled 2-D sums.
GaussianSum csfFilter(std::initializer_list<CsfTerm> terms, double ppd, int radius) {
    const double dx = 1.0 / ppd;  // degrees per pixel
    GaussianSum filter;
    std::vector<double> mass;
    for (const CsfTerm& t : terms) {
        FilterKernel k(size_t(2 * radius + 1));
        double sum = 0;
        for (int i = -radius; i <= radius; ++i) sum += std::exp(-kPi * kPi * (i * dx) * (i * dx) / t.b);
        for (int i = -radius; i <= radius; ++i)
            k[size_t(i + radius)] = float(std::exp(-kPi * kPi * (i * dx) * (i * dx) / t.b) / sum);
        mass.push_back(t.a * std::sqrt(kPi / t.b) * sum * sum);
        filter.terms.emplace_back(0.f, std::move(k));
    }
    double total = 0;
    for (double m : mass) total += m;
    for (size_t i = 0; i < mass.size(); ++i) filter.terms[i].first = float(mass[i] / total);
    return filter;
}

/// 1-D Gaussian derivative kernels of the feature detector: derivative of
/// order 1 (edges) or 2 (points), positive weights summing to 1 and negative
/// ones to −1, so a unit step gives a peak response of 1.
FilterKernel featureKernel(double sigma, int radius, int order) {
    FilterKernel k(size_t(2 * radius + 1));
    double pos = 0, neg = 0;
    for (int i = -radius; i <= radius; ++i) {
        const double g = std::exp(-0.5 * i * i / (sigma * sigma));
        const double v = order == 1 ? -i * g : (i * i / (sigma * sigma) - 1.0) * g;
        k[size_t(i + radius)] = float(v);
        (v > 0 ? pos : neg) += v;
    }
    for (float& v : k) v = float(v > 0 ? v / pos : v / -neg);
    return k;
}

/// Edge and point strength (gradient magnitudes of the 1st and 2nd derivative filters).
struct Features {
    ImagePlane edges, points;
};

Features detectFeatures(const ImagePlane& lum, double ppd) {
    const double sigma = 0.5 * kFeatureWidthDegrees * ppd;
    const int radius = int(std::ceil(3.0 * sigma));
    const FilterKernel g = gaussianKernel(sigma, radius);
    const FilterKernel d1 = featureKernel(sigma, radius, 1);
    const FilterKernel d2 = featureKernel(sigma, radius, 2);
    // 2-D kernels d(x)·g(y) and g(x)·d(y): three horizontal passes shared by four vertical ones.
    const ImagePlane rowG = convolveRows(lum, g);
    const ImagePlane ex = convolveColumns(convolveRows(lum, d1), g);
    const ImagePlane ey = convolveColumns(rowG, d1);
    const ImagePlane px = convolveColumns(convolveRows(lum, d2), g);
    const ImagePlane py = convolveColumns(rowG, d2);
    Features f{ImagePlane(lum.width, lum.height), ImagePlane(lum.width, lum.height)};
    tbb::parallel_for(size_t(0), lum.size(), [&](size_t i) {
        f.edges.data[i] = std::sqrt(ex.data[i] * ex.data[i] + ey.data[i] * ey.data[i]);
        f.points.data[i] = std::sqrt(px.data[i] * px.data[i] + py.data[i] * py.data[i]);
    });
    return f;
}

/// Hunt-adjusted CIELAB planes of the CSF-filtered image, and its unfiltered luminance Y/Yn.
struct Prepared {
    ImagePlane L, A, B, lum;
};

Prepared prepare(const RgbPlanes& img, double ppd) {
    const int w = img.width(), h = img.height();
    const size_t n = size_t(w) * size_t(h);
    ImagePlane y(w, h), cx(w, h), cz(w, h);
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
        const Vector3f v = rgbToYcxcz({img.r.data[i], img.g.data[i], img.b.data[i]});
        y.data[i] = v[0];
        cx.data[i] = v[1];
        cz.data[i] = v[2];
    });
    // One radius for all three filters, from the widest Gaussian (b = 0.04).
    const int radius = int(std::ceil(3.0 * std::sqrt(0.04 / (2.0 * kPi * kPi)) * ppd));
    const ImagePlane yf = csfFilter({{1.0, 0.0047}}, ppd, radius).apply(y);
    const ImagePlane cxf = csfFilter({{1.0, 0.0053}}, ppd, radius).apply(cx);
    const ImagePlane czf = csfFilter({{34.1, 0.04}, {13.5, 0.025}}, ppd, radius).apply(cz);
    Prepared p{ImagePlane(w, h), ImagePlane(w, h), ImagePlane(w, h), ImagePlane(w, h)};
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
        const Vector3f rgb = ycxczToRgb({yf.data[i], cxf.data[i], czf.data[i]}).cwiseMax(0.f).cwiseMin(1.f);
        const Vector3f lab = rgbToHuntLab(rgb);
        p.L.data[i] = lab[0];
        p.A.data[i] = lab[1];
        p.B.data[i] = lab[2];
        p.lum.data[i] = (y.data[i] + 16.f) / 116.f;
    });
    return p;
}

void checkSame(const ImagePlane& a, const ImagePlane& b, const char* what) {
    if (a.width != b.width || a.height != b.height || a.size() != b.size())
        throw Error(cat("flip: ", what, " sizes differ (", a.width, "x", a.height, " vs ", b.width, "x", b.height, ")"));
}

}  // namespace

double pixelsPerDegree(double distanceMetres, double widthMetres, int pixelsX) {
    return distanceMetres * (pixelsX / widthMetres) * kPi / 180.0;
}

ImagePlane flipErrorMap(const RgbPlanes& reference, const RgbPlanes& test, const FlipSettings& settings) {
    const double ppd = settings.pixelsPerDegree;
    if (!(ppd > 0) || !std::isfinite(ppd)) throw Error(cat("flip: pixels per degree must be positive, got ", ppd));
    for (const RgbPlanes* img : {&reference, &test}) {
        checkSame(img->r, img->g, "channel");
        checkSame(img->r, img->b, "channel");
    }
    checkSame(reference.r, test.r, "image");
    const Prepared ref = prepare(reference, ppd);
    const Prepared tst = prepare(test, ppd);
    const Features fr = detectFeatures(ref.lum, ppd);
    const Features ft = detectFeatures(tst.lum, ppd);

    const float cmax = std::pow(hyab(rgbToHuntLab({0, 1, 0}), rgbToHuntLab({0, 0, 1})), kQc);
    ImagePlane out(reference.width(), reference.height());
    tbb::parallel_for(size_t(0), out.size(), [&](size_t i) {
        const float dc = hyab({ref.L.data[i], ref.A.data[i], ref.B.data[i]}, {tst.L.data[i], tst.A.data[i], tst.B.data[i]});
        const float ec = redistribute(std::pow(dc, kQc), cmax);
        const float df = std::max(std::abs(fr.edges.data[i] - ft.edges.data[i]),
                                  std::abs(fr.points.data[i] - ft.points.data[i]));
        static_assert(kQf == 0.5f, "the feature exponent q_f = 0.5 is a square root");
        const float ef = std::min(1.f, std::sqrt(df / std::sqrt(2.f)));
        out.data[i] = std::pow(ec, 1.f - ef);
    });
    return out;
}

}  // namespace hp
