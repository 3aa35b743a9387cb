// The reference renderer's sampler (render/reference/sampling.h,
// render/reference/zsobol.h): every pass of a pixel's samples is a Sobol'
// net (one point in each elementary interval), the four pixels of a Morton
// quad are together a net of four times the points (the ZSobol layout), so
// their errors cancel (blue noise), neighbouring pixels do not repeat each
// other's points, and the independent layout keeps none of that across pixels.
#include "render/reference/sampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace hp;
using namespace hp::sampling;

namespace {

using Points = std::vector<Eigen::Vector2f>;

/// The pair of dimension `pair` (0 = the pixel filter's) of samples
/// [begin, end) of pixel (x, y).
Points points(const SamplerLayout& layout, int x, int y, uint32_t begin, uint32_t end, int pair) {
    PixelSampler s(layout, x, y);
    Points p;
    for (uint32_t i = begin; i < end; ++i) {
        s.start(i);
        for (int d = 0; d < pair; ++d) s.next2D();
        p.push_back(s.next2D());
    }
    return p;
}

/// Whether the 2^k points are a (0, k, 2)-net: for every split a + b = k,
/// each of the 2^a × 2^b elementary intervals holds exactly one point.
bool isNet(const Points& p) {
    int k = 0;
    while ((size_t(1) << k) < p.size()) ++k;
    if ((size_t(1) << k) != p.size()) return false;
    for (int a = 0; a <= k; ++a) {
        const int nx = 1 << a, ny = 1 << (k - a);
        std::vector<int> cells(size_t(nx) * size_t(ny), 0);
        for (const Eigen::Vector2f& q : p) ++cells[size_t(int(q.y() * ny)) * size_t(nx) + size_t(int(q.x() * nx))];
        for (int c : cells)
            if (c != 1) return false;
    }
    return true;
}

/// The points of a block of w × h pixels from (x0, y0), samples [0, n).
Points block(const SamplerLayout& layout, int x0, int y0, int w, int h, uint32_t n, int pair) {
    Points all;
    for (int y = y0; y < y0 + h; ++y)
        for (int x = x0; x < x0 + w; ++x)
            for (const Eigen::Vector2f& q : points(layout, x, y, 0, n, pair)) all.push_back(q);
    return all;
}

}  // namespace

TEST(Sampling, EveryPassOfAPixelIsANet) {
    // Adaptive passes: the first `first` samples, then blocks that double
    // the count. Each must be stratified on its own (the two half-buffers
    // of the error estimate), for even and odd log2(first), in the pixel
    // filter's pair and a later one, with ZSobol and the independent layout.
    for (SamplerType type : {SamplerType::ZSobol, SamplerType::Independent})
        for (uint32_t first : {16u, 8u}) {
            const SamplerLayout layout = SamplerLayout::make(type, 5, 3, 37, 23, first);
            for (const auto& [x, y] : {std::pair{0, 0}, {5, 7}, {36, 22}, {17, 2}})
                for (int pair : {0, 3}) {
                    SCOPED_TRACE(::testing::Message() << samplerName(type) << " first " << first << " pixel " << x
                                                      << "," << y << " pair " << pair);
                    EXPECT_TRUE(isNet(points(layout, x, y, 0, first, pair)));
                    for (uint32_t b = first; b < 16 * first; b *= 2)
                        EXPECT_TRUE(isNet(points(layout, x, y, b, 2 * b, pair)));
                }
        }
}

TEST(Sampling, ZSobolQuadsOfPixelsAreNetsTogether) {
    // The 2×2 pixels of a Morton quad take the four blocks of one net of 4n
    // points, and 4×4 pixels one of 16n: what makes their errors cancel.
    // Pixels with independent sequences are each a net but not together.
    const SamplerLayout z = SamplerLayout::make(SamplerType::ZSobol, 9, 1, 40, 30, 16);
    const SamplerLayout w = SamplerLayout::make(SamplerType::Independent, 9, 1, 40, 30, 16);
    int independentNets = 0;
    for (const auto& [x, y] : {std::pair{0, 0}, {2, 0}, {10, 6}, {38, 28}})
        for (int pair : {0, 2}) {
            SCOPED_TRACE(::testing::Message() << "quad " << x << "," << y << " pair " << pair);
            EXPECT_TRUE(isNet(block(z, x, y, 2, 2, 16, pair)));
            independentNets += isNet(block(w, x, y, 2, 2, 16, pair));
        }
    EXPECT_EQ(independentNets, 0);
    EXPECT_TRUE(isNet(block(z, 4, 8, 4, 4, 16, 0)));
    EXPECT_TRUE(isNet(block(z, 4, 8, 4, 4, 16, 1)));
    // A later pass (samples 16..31 of each pixel) is its own ZSobol level.
    Points later;
    for (int y = 10; y < 12; ++y)
        for (int x = 6; x < 8; ++x)
            for (const Eigen::Vector2f& q : points(z, x, y, 16, 32, 0)) later.push_back(q);
    EXPECT_TRUE(isNet(later));
}

TEST(Sampling, NeighbouringPixelsDoNotRepeatTheirPoints) {
    // Every pixel's first sample, in every pair, differs from its
    // neighbours' (a layout that ignored the pixel would repeat them).
    const SamplerLayout z = SamplerLayout::make(SamplerType::ZSobol, 2, 0, 24, 16, 16);
    for (int pair : {0, 1, 4})
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 24; ++x) {
                const Eigen::Vector2f p = points(z, x, y, 0, 1, pair)[0];
                if (x + 1 < 24) {
                    EXPECT_NE(p, points(z, x + 1, y, 0, 1, pair)[0]) << x << "," << y << " pair " << pair;
                }
                if (y + 1 < 16) {
                    EXPECT_NE(p, points(z, x, y + 1, 0, 1, pair)[0]) << x << "," << y << " pair " << pair;
                }
            }
}

TEST(Sampling, ZSobolErrorsOfNeighboursCancel) {
    // Each pixel estimates the area of a disk (π r², exact) with its 16
    // samples of one pair; the disk moves a little from pixel to pixel, as
    // an image's integrands do. The mean error of a 2×2 (4×4) block is what
    // a viewer blurring the image sees: with independent pixels its variance
    // is 1/4 (1/16) of a pixel's; with ZSobol the block's samples are one
    // net and its pixels' errors cancel, so it is well below that, while a
    // pixel's own error is unchanged (each is a 16-point net either way).
    // Averaged over 8 seeds.
    constexpr int n = 64;
    const double r = 0.3, area = M_PI * r * r;
    struct Variances {
        double pixel = 0.0, quad = 0.0, block = 0.0;  // of a pixel's error, of 2×2 and 4×4 means
    };
    auto variances = [&](SamplerType type, int pair) {
        Variances v;
        for (uint64_t seed = 1; seed <= 8; ++seed) {
            const SamplerLayout layout = SamplerLayout::make(type, seed, 0, n, n, 16);
            std::vector<double> err(n * n);
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const double cx = 0.5 + 0.1 * std::sin(0.37 * x), cy = 0.5 + 0.1 * std::cos(0.23 * y);
                    int inside = 0;
                    for (const Eigen::Vector2f& q : points(layout, x, y, 0, 16, pair))
                        inside += std::hypot(q.x() - cx, q.y() - cy) < r;
                    err[size_t(y) * n + size_t(x)] = inside / 16.0 - area;
                }
            auto meanSquare = [&](int side) {
                double sum = 0.0;
                for (int y = 0; y < n; y += side)
                    for (int x = 0; x < n; x += side) {
                        double m = 0.0;
                        for (int k = 0; k < side * side; ++k) m += err[size_t(y + k / side) * n + size_t(x + k % side)];
                        m /= side * side;
                        sum += m * m;
                    }
                return sum / (double(n / side) * double(n / side)) / 8.0;
            };
            v.pixel += meanSquare(1), v.quad += meanSquare(2), v.block += meanSquare(4);
        }
        return v;
    };
    for (int pair : {0, 3}) {
        const Variances z = variances(SamplerType::ZSobol, pair), w = variances(SamplerType::Independent, pair);
        std::printf("pair %d: pixel error variance zsobol %.3g independent %.3g; 2x2 mean x4 / pixel: %.2f / %.2f; "
                    "4x4 mean x16 / pixel: %.2f / %.2f\n",
                    pair, z.pixel, w.pixel, 4 * z.quad / z.pixel, 4 * w.quad / w.pixel, 16 * z.block / z.pixel,
                    16 * w.block / w.pixel);
        EXPECT_NEAR(z.pixel / w.pixel, 1.0, 0.2);           // the same per-pixel error
        EXPECT_NEAR(4 * w.quad / w.pixel, 1.0, 0.15);       // independent: white noise
        EXPECT_NEAR(16 * w.block / w.pixel, 1.0, 0.25);
        EXPECT_LT(4 * z.quad / z.pixel, 0.75);              // ZSobol: neighbours cancel
        EXPECT_LT(16 * z.block / z.pixel, 0.6);
    }
}
