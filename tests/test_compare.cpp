// Image comparison: the metrics (render/compare/compare.h, flip.h, ssim.h), the
// per-frame files and tables (pipeline/compare/compare_job.h), `hairpipe compare`,
// the compare stage of `hairpipe run`, and the HTML report in headless Chromium
// (the tables and the report's labels: test_compare_report.cpp).
#include "core/errors.h"
#include "pipeline/compare/compare_job.h"
#include "pipeline/compare/compare_table.h"
#include "pipeline/batch/path_template.h"
#include "render/image/colormap.h"
#include "render/compare/compare.h"
#include "render/image/image_io.h"
#include "render/compare/ssim.h"
#include "test_support.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <regex>

using namespace hp;
namespace fs = std::filesystem;

namespace {

/// A test picture: smooth gradients, stripes of several frequencies and a
/// disc, values within [0.1, 0.8] so small perturbations never clip.
Image texture(int w = 160, int h = 120, bool alpha = true) {
    Image img(w, h, alpha ? std::vector<std::string>{"R", "G", "B", "A"} : std::vector<std::string>{"R", "G", "B"});
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float stripes = 0.15f * std::sin(x * 0.35f) * std::cos(y * 0.12f);
            const float disc = (x - 100) * (x - 100) + (y - 60) * (y - 60) < 400 ? 0.25f : 0.f;
            img.at(x, y, 0) = 0.35f + 0.25f * x / w + stripes + disc * 0.5f;
            img.at(x, y, 1) = 0.30f + 0.20f * y / h + stripes + disc;
            img.at(x, y, 2) = 0.45f - 0.2f * x / w - 0.5f * stripes;
            if (alpha) img.at(x, y, 3) = 1.f;
        }
    return img;
}

Image constant(float r, float g, float b, int w = 64, int h = 48) {
    Image img(w, h, {"R", "G", "B"});
    for (size_t i = 0; i < img.pixels.size(); i += 3) img.pixels[i] = r, img.pixels[i + 1] = g, img.pixels[i + 2] = b;
    return img;
}

/// Adds Gaussian noise of standard deviation sigma to R, G, B (fixed seed).
Image withNoise(Image img, float sigma, unsigned seed = 7) {
    std::mt19937 rng(seed);
    std::normal_distribution<float> n(0.f, sigma);
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            for (int c = 0; c < 3; ++c) img.at(x, y, c) += n(rng);
    return img;
}

Image brighter(Image img, float delta) {
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            for (int c = 0; c < 3; ++c) img.at(x, y, c) += delta;
    return img;
}

/// Shifted right by dx pixels (the left columns repeat the first one).
Image shifted(const Image& img, int dx) {
    Image out = img;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            for (int c = 0; c < img.channelCount(); ++c) out.at(x, y, c) = img.at(std::max(0, x - dx), y, c);
    return out;
}

FrameMetrics metrics(const Image& a, const Image& b, MaskMode mask = MaskMode::None) {
    CompareSettings s;
    s.mask = mask;
    return compareImages(a, b, s).metrics;
}

}  // namespace

// ---------------------------------------------------------------- metrics

TEST(CompareMetrics, IdenticalImagesHaveNoError) {
    const Image a = texture();
    const Comparison c = compareImages(a, a);
    EXPECT_EQ(c.metrics.rmse, 0.0);
    EXPECT_TRUE(std::isinf(c.metrics.psnr) && c.metrics.psnr > 0);
    EXPECT_EQ(c.metrics.maxError, 0.0);
    EXPECT_EQ(c.metrics.ssim, 1.0);
    EXPECT_EQ(c.metrics.flip, 0.0);
    EXPECT_EQ(c.metrics.pixels, long(a.width) * a.height);
    for (float v : c.flipMap.data) ASSERT_EQ(v, 0.f);
    for (float v : c.absDiff.pixels) ASSERT_EQ(v, 0.f);
}

TEST(CompareMetrics, PsnrOfGaussianNoiseMatchesSigma) {
    // PSNR = 20·log10(1/RMSE) and the RMSE of noise of σ is σ.
    const Image a = texture();
    for (float sigma : {0.01f, 0.03f, 0.05f}) {
        const FrameMetrics m = metrics(a, withNoise(a, sigma));
        EXPECT_NEAR(m.rmse, sigma, 0.05 * sigma) << sigma;
        EXPECT_NEAR(m.psnr, 20.0 * std::log10(1.0 / sigma), 0.5) << sigma;
        EXPECT_GT(m.maxError, 2.5 * sigma) << "the largest of ~57600 normal samples lies beyond 2.5σ";
    }
}

TEST(CompareMetrics, EachMetricWorsensAsNoiseGrows) {
    const Image a = texture();
    FrameMetrics prev = metrics(a, a);
    for (float sigma : {0.005f, 0.02f, 0.08f}) {
        const FrameMetrics m = metrics(a, withNoise(a, sigma));
        EXPECT_GT(m.rmse, prev.rmse) << sigma;
        EXPECT_LT(m.psnr, prev.psnr) << sigma;
        EXPECT_LT(m.ssim, prev.ssim) << sigma;
        EXPECT_GT(m.flip, prev.flip) << sigma;
        prev = m;
    }
    // Orders of magnitude at σ = 0.08: clearly visible noise.
    EXPECT_LT(prev.ssim, 0.6);
    EXPECT_GT(prev.flip, 0.1);
    EXPECT_LT(prev.flip, 0.6);
}

TEST(CompareMetrics, SsimPenalisesNoiseFarMoreThanABrightnessShiftOfEqualRmse) {
    const Image a = texture();
    const FrameMetrics noise = metrics(a, withNoise(a, 0.05f));
    const FrameMetrics shift = metrics(a, brighter(a, 0.05f));
    EXPECT_NEAR(shift.rmse, 0.05, 1e-4) << "a uniform offset of 0.05 (no clipping)";
    EXPECT_NEAR(shift.psnr, 20.0 * std::log10(1.0 / 0.05), 0.01);
    EXPECT_NEAR(noise.rmse, shift.rmse, 0.005) << "same RMSE...";
    EXPECT_GT(shift.ssim, 0.98) << "...but structure is intact under a brightness change";
    EXPECT_LT(noise.ssim, 0.9);
    EXPECT_GT(shift.flip, 0.05) << "a 0.05 brightness step is visible when flipping";
}

TEST(CompareMetrics, ShiftMovesEveryMetricWithTheDistance) {
    const Image a = texture();
    const FrameMetrics one = metrics(a, shifted(a, 1));
    const FrameMetrics four = metrics(a, shifted(a, 4));
    EXPECT_GT(one.rmse, 0.005);
    EXPECT_GT(four.rmse, 1.5 * one.rmse);
    EXPECT_LT(one.ssim, 1.0);
    EXPECT_LT(four.ssim, one.ssim - 0.05);
    EXPECT_GT(one.flip, 0.01);
    EXPECT_GT(four.flip, 1.5 * one.flip);
}

TEST(CompareMetrics, MetricsAreSymmetric) {
    const Image a = texture(), b = withNoise(shifted(a, 2), 0.02f);
    const FrameMetrics ab = metrics(a, b), ba = metrics(b, a);
    EXPECT_DOUBLE_EQ(ab.rmse, ba.rmse);
    EXPECT_NEAR(ab.ssim, ba.ssim, 1e-9);
    EXPECT_NEAR(ab.flip, ba.flip, 1e-6);
}

TEST(CompareMetrics, ThreadCountDoesNotChangeResults) {
    const Image a = texture(), b = withNoise(shifted(a, 1), 0.03f);
    Comparison one, two;
    tbb::task_arena(1).execute([&] { one = compareImages(a, b); });
    tbb::task_arena(2).execute([&] { two = compareImages(a, b); });
    EXPECT_EQ(one.metrics.rmse, two.metrics.rmse);
    EXPECT_EQ(one.metrics.ssim, two.metrics.ssim);
    EXPECT_EQ(one.metrics.flip, two.metrics.flip);
    EXPECT_EQ(one.flipMap.data, two.flipMap.data);
}

TEST(CompareMetrics, HdrValuesCompareAsTheirDisplayValues) {
    // Above 1 both saturate the display: no difference; NaN reads as black.
    Image a = constant(3.f, 2.f, 1.5f), b = constant(1.f, 1.f, 1.f);
    EXPECT_EQ(metrics(a, b).rmse, 0.0);
    a.pixels[0] = std::nanf("");
    EXPECT_NEAR(metrics(a, b).maxError, 1.0, 1e-6) << "NaN reads as 0, against 1";
    EXPECT_TRUE(std::isfinite(metrics(a, b).flip));
}

// ---------------------------------------------------------------- FLIP

// Constant images have no features (every derivative is 0), so the error is
// the colour term alone, which the paper's formulas give by hand:
// Hunt-adjusted CIELAB of linear RGB, HyAB distance, power q_c = 0.7 and the
// redistribution with p_c = 0.4, p_t = 0.95. With green (0,1,0) → L 87.73,
// a 75.61·(-1), b 72.98 and blue (0,0,1) → L 32.30, a 25.58, b -34.84 after
// the Hunt adjustment, HyAB(green, blue) = 203.30 and c_max = 203.30^0.7 = 41.28.
TEST(CompareFlip, ConstantColoursMatchThePapersFormulas) {
    auto flip = [](const Image& a, const Image& b) { return compareImages(a, b).metrics.flip; };
    // Green vs blue is the largest colour difference: exactly 1 by construction.
    EXPECT_NEAR(flip(constant(0, 1, 0), constant(0, 0, 1)), 1.0, 1e-4);
    // Black vs white: HyAB = 100, 100^0.7 = 25.12 > p_c·c_max = 16.51, so
    // e = 0.95 + (25.12 − 16.51)/(41.28 − 16.51)·0.05 = 0.96738.
    EXPECT_NEAR(flip(constant(0, 0, 0), constant(1, 1, 1)), 0.96738, 2e-4);
    // Red vs green: HyAB = 158.46 → 0.98666.
    EXPECT_NEAR(flip(constant(1, 0, 0), constant(0, 1, 0)), 0.98666, 2e-4);
    // Grey 0.5 vs 0.55 (linear): ΔL* = 2.972, below the knee: 0.95/16.51 · 2.972^0.7 = 0.12334.
    EXPECT_NEAR(flip(constant(0.5f, 0.5f, 0.5f), constant(0.55f, 0.55f, 0.55f)), 0.12334, 2e-4);
    // Dark grey 0.2 vs 0.21: ΔL* = 1.112 → 0.06199.
    EXPECT_NEAR(flip(constant(0.2f, 0.2f, 0.2f), constant(0.21f, 0.21f, 0.21f)), 0.06199, 2e-4);
}

TEST(CompareFlip, FeatureTermConcentratesErrorAtAMovedEdge) {
    // A vertical edge at x = 40 moved by one pixel.
    Image a = constant(0.1f, 0.1f, 0.1f, 96, 32), b = a;
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 96; ++x)
            for (int c = 0; c < 3; ++c) {
                a.at(x, y, c) = x >= 40 ? 0.8f : 0.1f;
                b.at(x, y, c) = x >= 41 ? 0.8f : 0.1f;
            }
    const ImagePlane map = compareImages(a, b).flipMap;
    int argmax = 0;
    for (int x = 0; x < 96; ++x)
        if (map.at(x, 16) > map.at(argmax, 16)) argmax = x;
    EXPECT_NEAR(argmax, 40, 2);
    EXPECT_GT(map.at(argmax, 16), 0.3f) << "a moved high-contrast edge is clearly visible";
    EXPECT_LT(map.at(5, 16), 1e-3f) << "far from the edge both images are the same flat grey";
    EXPECT_LT(map.at(90, 16), 1e-3f);
}

TEST(CompareFlip, FineNoiseMattersLessFromFurtherAway) {
    // More pixels per degree = a smaller angle per pixel: the contrast
    // sensitivity filters blur pixel-level noise more.
    const Image a = texture(), b = withNoise(a, 0.05f);
    CompareSettings near, far;
    near.flip.pixelsPerDegree = 20;
    far.flip.pixelsPerDegree = 120;
    EXPECT_GT(compareImages(a, b, near).metrics.flip, 1.2 * compareImages(a, b, far).metrics.flip);
    EXPECT_THROW(compareImages(a, b, [] { CompareSettings s; s.flip.pixelsPerDegree = 0; return s; }()), Error);
    // The paper's setup: a 0.7 m wide 3840-pixel display seen from 0.7 m gives its 67 PPD.
    EXPECT_NEAR(pixelsPerDegree(0.7, 0.7, 3840), 67.02, 0.01);
}

TEST(CompareFlip, MagmaIsDarkToLightAndMonotoneInLuminance) {
    float prev = -1.f;
    for (int i = 0; i <= 64; ++i) {
        const auto c = magma(i / 64.f);
        const float lum = 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
        EXPECT_GT(lum, prev) << i;
        prev = lum;
    }
    EXPECT_LT(magma(0)[0], 0.01f);
    EXPECT_GT(magma(1)[1], 0.98f);
    EXPECT_EQ(magma(-5)[2], magma(0)[2]);
    EXPECT_EQ(magma(std::nanf(""))[2], magma(0)[2]);
}

// ---------------------------------------------------------------- mask

TEST(CompareMask, AveragesOnlyOverPixelsWithAlpha) {
    // Hair (alpha > 0) only in x < 40; the images differ only at x ≥ 80, more
    // than every filter radius (SSIM 5, FLIP ≤ 10 px at 67 PPD) away.
    Image a = texture(), b = a;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            a.at(x, y, 3) = b.at(x, y, 3) = x < 40 ? 1.f : 0.f;
            if (x >= 80) b.at(x, y, 1) += 0.2f;
        }
    const FrameMetrics all = metrics(a, b), hair = metrics(a, b, MaskMode::Hair);
    EXPECT_GT(all.rmse, 0.05);
    EXPECT_GT(all.flip, 0.1);
    EXPECT_EQ(hair.pixels, 40L * a.height);
    EXPECT_EQ(hair.rmse, 0.0);
    EXPECT_TRUE(std::isinf(hair.psnr));
    EXPECT_EQ(hair.ssim, 1.0);
    EXPECT_EQ(hair.flip, 0.0);
}

TEST(CompareMask, RmseOverTheMaskIsTheRmseOfThosePixels) {
    // Differences only inside the mask: the masked mean squared error is the
    // whole frame's scaled by (all pixels / mask pixels).
    Image a = texture(), b = a;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            b.at(x, y, 3) = 0.f;  // B has no hair: the union with A decides
            a.at(x, y, 3) = y < 30 ? 0.5f : 0.f;
            if (y < 30) b.at(x, y, 0) += 0.1f;
        }
    const FrameMetrics all = metrics(a, b), hair = metrics(a, b, MaskMode::Hair);
    EXPECT_EQ(hair.pixels, 30L * a.width);
    EXPECT_NEAR(hair.rmse, 0.1 / std::sqrt(3.0), 1e-5) << "one channel of three off by 0.1";
    EXPECT_NEAR(hair.rmse, all.rmse * std::sqrt(double(a.width * a.height) / hair.pixels), 1e-6);
    EXPECT_GT(hair.flip, all.flip);
}

TEST(CompareMask, NeedsAnAlphaChannel) {
    try {
        metrics(texture(160, 120, false), texture(160, 120, false), MaskMode::Hair);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("alpha"), std::string::npos) << e.what();
    }
    EXPECT_EQ(metrics(texture(160, 120, false), texture(), MaskMode::Hair).pixels, 160L * 120)
        << "one image's alpha is enough";
}

// ---------------------------------------------------------------- files

TEST(CompareFiles, MismatchedResolutionNamesBothFiles) {
    EXPECT_THROW(compareImages(texture(160, 120), texture(80, 60)), Error);
    test::TempDir dir;
    writeImage((dir / "a.0001.exr").string(), texture(160, 120));
    writeImage((dir / "b.0001.exr").string(), texture(80, 60));
    CompareJob job;
    job.a = (dir / "a.####.exr").string();
    job.b = (dir / "b.####.exr").string();
    job.outputDir = dir / "out";
    job.reportWidth = 64;
    try {
        compareFrame(job, 1);
        FAIL() << "expected an error";
    } catch (const FrameError& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("a.0001.exr is 160x120"), std::string::npos) << msg;
        EXPECT_NE(msg.find("b.0001.exr is 80x60"), std::string::npos) << msg;
    }
    try {
        compareFrame(job, 2);
        FAIL() << "expected an error";
    } catch (const AssetError& e) {
        EXPECT_NE(std::string(e.what()).find("a.0002.exr: no such file"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(frameMetricsPath(job, 1)));
}

TEST(CompareFiles, FrameRecordRoundTripsThroughJson) {
    test::TempDir dir;
    writeImage((dir / "a.0003.png").string(), texture());
    writeImage((dir / "b.0003.exr").string(), withNoise(texture(), 0.02f));
    CompareJob job;
    job.a = (dir / "a.####.png").string();
    job.b = (dir / "b.####.exr").string();
    job.outputDir = dir / "out";
    job.reportWidth = 64;
    const FrameRecord r = compareFrame(job, 3);
    for (const fs::path& p : frameOutputs(job, 3)) EXPECT_TRUE(fs::exists(p)) << p;
    const FrameRecord back = loadFrameRecord(job, 3);
    EXPECT_TRUE(back.compared);
    EXPECT_EQ(back.a, r.a);
    EXPECT_EQ(back.width, 160);
    EXPECT_NEAR(back.metrics.flip, r.metrics.flip, 1e-9);
    EXPECT_NEAR(back.metrics.psnr, r.metrics.psnr, 1e-7);
    // An 8-bit sRGB PNG against the float EXR: quantisation is far below the noise.
    EXPECT_NEAR(r.metrics.rmse, 0.02, 0.004);
    FrameRecord inf = r;
    inf.metrics.psnr = INFINITY;
    EXPECT_TRUE(std::isinf(parseFrameRecord(frameRecordJson(inf), "x").metrics.psnr));
    EXPECT_FALSE(loadFrameRecord(job, 4).compared);
    EXPECT_THROW(parseFrameRecord("{\"frame\": 1}", "m.json"), AssetError);
}

TEST(CompareFiles, FramesInBothSequences) {
    test::TempDir dir;
    for (const char* f : {"a.0001.exr", "a.0002.exr", "a.0010.exr", "a.01.exr", "a.0003.exr.tmp", "b.0002.exr",
                          "b.0010.exr", "b.0011.exr"})
        test::writeFile(dir / f, "x");
    EXPECT_EQ(framesInBoth((dir / "a.####.exr").string(), (dir / "b.%04d.exr").string()), (std::vector<int>{2, 10}));
    int frame = 0;
    EXPECT_TRUE(matchFrame("x.####.exr", "x.12345.exr", &frame));
    EXPECT_EQ(frame, 12345);
    EXPECT_TRUE(matchFrame("x.####.exr", "x.-0001.exr", &frame));
    EXPECT_EQ(frame, -1);
    EXPECT_FALSE(matchFrame("x.####.exr", "x.12.exr", &frame));
    EXPECT_FALSE(matchFrame("x.####.exr", "y.0012.exr", &frame));
}

// ---------------------------------------------------------------- command line

namespace {

/// Writes frames of a sequence `pattern` (relative to `dir`) made by `make(frame)`.
template <typename Make>
void writeSequence(const fs::path& dir, const std::string& pattern, const std::vector<int>& frames, Make make) {
    for (int f : frames) {
        const fs::path p = dir / expandFrame(pattern, f);
        fs::create_directories(p.parent_path());
        writeImage(p.string(), make(f));
    }
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST(CompareCli, IdenticalSequencesPassAndOutputsAreDeterministic) {
    test::TempDir dir;
    writeSequence(dir.path(), "a/img.####.exr", {1, 2, 3}, [](int) { return texture(); });
    writeSequence(dir.path(), "b/img.%04d.exr", {2, 3, 4}, [](int) { return texture(); });
    const test::ProcessResult r = test::runHairpipe("compare a/img.####.exr b/img.%04d.exr --out out", dir.path());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "all 2 frames pass")) << "frames 2 and 3 are in both: " << r.output;
    for (const char* f : {"flip.0002.png", "absdiff.0003.exr", "metrics.0002.json", "metrics.csv", "metrics.json",
                          "report.html"})
        EXPECT_TRUE(fs::exists(dir / "out" / f)) << f;
    EXPECT_FALSE(fs::exists(dir / "out/flip.0001.png"));
    const std::string json = test::readFile(dir / "out/metrics.json");
    EXPECT_TRUE(contains(json, "\"pass\": true")) << json;
    EXPECT_TRUE(contains(json, "\"psnr\": null")) << "identical frames: infinite PSNR";
    // Same inputs, another output folder, two threads: byte-identical tables and report.
    ASSERT_EQ(test::runHairpipe("compare a/img.####.exr b/img.%04d.exr --out out2 --threads 1", dir.path()).exitCode, 0);
    EXPECT_EQ(test::readFile(dir / "out/report.html"), test::readFile(dir / "out2/report.html"));
    EXPECT_EQ(test::readFile(dir / "out/metrics.csv"), test::readFile(dir / "out2/metrics.csv"));
}

TEST(CompareCli, ThresholdFailureExitsWith2AndListsTheFrames) {
    test::TempDir dir;
    writeSequence(dir.path(), "a/img.####.exr", {1, 2}, [](int) { return texture(); });
    writeSequence(dir.path(), "b/img.####.exr", {1, 2}, [](int f) { return f == 2 ? withNoise(texture(), 0.05f) : texture(); });
    const std::string args = "compare a/img.####.exr b/img.####.exr --out out ";
    test::ProcessResult r = test::runHairpipe(args + "--max-flip 0.05", dir.path());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "1 of 2 frames FAIL")) << r.output;
    EXPECT_TRUE(std::regex_search(r.output, std::regex("frame 2: FLIP 0\\.0\\d+ > 0\\.05"))) << r.output;
    EXPECT_TRUE(contains(test::readFile(dir / "out/metrics.json"), "\"pass\": false"));
    r = test::runHairpipe(args + "--min-psnr 30", dir.path());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "frame 2: PSNR 26.")) << r.output;
    EXPECT_EQ(test::runHairpipe(args + "--min-ssim 0.5 --max-rmse 0.06 --report none", dir.path()).exitCode, 0);
}

TEST(CompareCli, MissingOrMismatchedFramesFailOnlyThoseFrames) {
    test::TempDir dir;
    writeSequence(dir.path(), "a/img.####.exr", {1, 2, 3}, [](int) { return texture(); });
    writeSequence(dir.path(), "b/img.####.exr", {1, 3}, [](int f) { return f == 3 ? texture(80, 60) : texture(); });
    const test::ProcessResult r =
        test::runHairpipe("compare a/img.####.exr b/img.####.exr --frames 1-3 --out out", dir.path());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "b/img.0002.exr: no such file")) << r.output;
    EXPECT_TRUE(contains(r.output, "a/img.0003.exr is 160x120")) << r.output;
    EXPECT_TRUE(contains(r.output, "b/img.0003.exr is 80x60")) << r.output;
    // The report still gets written; the image it cannot show is named, not dropped silently.
    EXPECT_TRUE(std::regex_search(r.output, std::regex("no thumbnail of [^\n]*b/img.0002.exr"))) << r.output;
    EXPECT_TRUE(fs::exists(dir / "out/metrics.0001.json")) << "frame 1 is still compared";
    const std::string csv = test::readFile(dir / "out/metrics.csv");
    EXPECT_TRUE(contains(csv, "\n1,")) << csv;
    EXPECT_TRUE(std::regex_search(csv, std::regex("\n2,[^\n]*,error,[^\n]*no such file"))) << csv;
}

TEST(CompareCli, UsageErrorsExitWith1) {
    test::TempDir dir;
    writeSequence(dir.path(), "a/img.####.exr", {1}, [](int) { return texture(); });
    writeSequence(dir.path(), "b/img.####.exr", {2}, [](int) { return texture(); });
    auto run = [&](const std::string& args) { return test::runHairpipe("compare " + args, dir.path()); };
    test::ProcessResult r = run("a/img.####.exr b/img.####.exr");
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_TRUE(contains(r.output, "no frames to compare")) << r.output;
    r = run("a/img.####.exr");
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_TRUE(contains(r.output, "expected two image sequences")) << r.output;
    r = run("a/img.0001.exr b/img.####.exr");
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_TRUE(contains(r.output, "A 'a/img.0001.exr' has no frame number")) << r.output;
    EXPECT_EQ(run("a/img.####.exr b/img.####.exr --mask fur").exitCode, 1);
    EXPECT_EQ(run("a/img.####.exr b/img.####.exr --max-flip 2").exitCode, 1);
    EXPECT_EQ(run("a/img.####.exr b/img.####.exr --set x=1").exitCode, 1) << "no scene options";
    r = run("--help");
    EXPECT_EQ(r.exitCode, 0);
    EXPECT_TRUE(contains(r.output, "--max-flip")) << r.output;
}

// ---------------------------------------------------------------- the run stage

TEST(CompareStage, RunComparesPreviewAgainstReferenceAndGatesOnThresholds) {
    test::TempDir dir;
    test::writeFile(dir / "shot.yaml",
                    "frames: 1-2\noutput:\n  directory: out\ncompare:\n  enabled: true\n  max_flip: 0.2\n");
    writeSequence(dir / "out", "preview/preview.####.exr", {1, 2}, [](int) { return texture(); });
    writeSequence(dir / "out", "reference/reference.####.exr", {1, 2},
                  [](int f) { return withNoise(texture(), 0.01f * f); });
    test::ProcessResult r = test::runHairpipe("run shot.yaml", dir.path());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(fs::exists(dir / "out/compare/report.html"));
    EXPECT_TRUE(fs::exists(dir / "out/compare/flip.0002.png"));
    EXPECT_TRUE(contains(test::readFile(dir / "out/compare/metrics.json"), "\"mask\": \"hair\""));
    // A stricter threshold on the rerun: the frames are already compared (skipped),
    // yet the end-of-run check still reads every frame's metrics and fails the run.
    r = test::runHairpipe("run shot.yaml --set compare.max_flip=0.02", dir.path());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "2 stage outputs already present")) << r.output;
    EXPECT_TRUE(contains(r.output, "compare: 2 of 2 frames fail the comparison thresholds")) << r.output;
    EXPECT_TRUE(std::regex_search(r.output, std::regex("frame 1: FLIP 0\\.\\d+ > 0\\.02"))) << r.output;
    EXPECT_TRUE(contains(test::readFile(dir / "out/compare/report.html"), "FAIL"));
    // A missing reference frame fails that frame of the run.
    fs::remove(dir / "out/reference/reference.0002.exr");
    r = test::runHairpipe("run shot.yaml --force", dir.path());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "frame 2 compare:")) << r.output;
    EXPECT_TRUE(contains(r.output, "reference.0002.exr: no such file")) << r.output;
    // `hairpipe compare --scene` re-checks the shot with the scene's templates and thresholds.
    EXPECT_EQ(test::runHairpipe("compare --scene shot.yaml --frames 1", dir.path()).exitCode, 0);
    r = test::runHairpipe("compare --scene shot.yaml --frames 1 --max-flip 0.001 --out recheck", dir.path());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_TRUE(fs::exists(dir / "recheck/report.html"));
}

TEST(CompareStage, OffByDefaultAndTemplatesAreChecked) {
    test::TempDir dir;
    test::writeFile(dir / "shot.yaml", "frames: 1\n");
    test::ProcessResult r = test::runHairpipe("run shot.yaml --out out", dir.path());
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_FALSE(fs::exists(dir / "out/compare"));
    r = test::runHairpipe("run shot.yaml --out out --set compare.enabled=true --set compare.a=preview.exr",
                          dir.path());
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_TRUE(contains(r.output, "'compare.a': 'preview.exr' has no frame number")) << r.output;
}

// ---------------------------------------------------------------- the HTML report

namespace {

std::string shell(const std::string& command) {
    std::string out;
    FILE* pipe = ::popen(command.c_str(), "r");
    if (!pipe) return out;
    char buf[4096];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) out.append(buf, n);
    ::pclose(pipe);
    return out;
}

std::string findChromium() {
    for (const char* name : {"chromium", "chromium-browser", "google-chrome"}) {
        std::string path = shell(std::string("command -v ") + name + " 2>/dev/null");
        while (!path.empty() && std::isspace(static_cast<unsigned char>(path.back()))) path.pop_back();
        if (!path.empty()) return path;
    }
    return {};
}

/// The DOM of `page` after load in headless Chromium with every network
/// request sent to a closed port (127.0.0.1:9), or empty if it did not start.
std::string loadedDom(const std::string& chromium, const fs::path& page, const fs::path& profile) {
    return shell("timeout 90 '" + chromium +
                 "' --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
                 "--disable-background-networking --disable-component-update --disable-sync "
                 "--proxy-server=127.0.0.1:9 --virtual-time-budget=10000 --user-data-dir='" +
                 profile.string() + "' --dump-dom 'file://" + page.string() + "' 2>/dev/null");
}

std::string bodyAttribute(const std::string& dom, const std::string& name) {
    std::smatch m;
    if (std::regex_search(dom, m, std::regex("<body[^>]*\\s" + name + "=\"([^\"]*)\""))) return m[1];
    return "(missing)";
}

}  // namespace

TEST(CompareReport, IsSelfContainedAndRendersInHeadlessChromium) {
    test::TempDir dir;
    writeSequence(dir.path(), "a/img.####.exr", {1, 2, 3}, [](int) { return texture(); });
    writeSequence(dir.path(), "b/img.####.exr", {1, 2, 3}, [](int f) { return shifted(texture(), f - 1); });
    const test::ProcessResult r =
        test::runHairpipe("compare a/img.####.exr b/img.####.exr --out out --report-width 96", dir.path());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const std::string html = test::readFile(dir / "out/report.html");

    // Nothing to fetch: every src is an embedded PNG; no links, URLs or imports.
    const std::regex src("src=\"([^\"]*)\"");
    int images = 0;
    for (auto it = std::sregex_iterator(html.begin(), html.end(), src); it != std::sregex_iterator(); ++it, ++images)
        EXPECT_EQ(it->str(1).rfind("data:image/png;base64,", 0), 0u) << it->str(1).substr(0, 60);
    EXPECT_EQ(images, 12) << "A, B, FLIP and |A-B| for 3 frames";
    for (const char* bad : {"http:", "https:", "href=", "url(", "@import", "src=\"//"})
        EXPECT_FALSE(contains(html, bad)) << bad;
    EXPECT_EQ(std::count(html.begin(), html.end(), '\n') > 0, true);
    EXPECT_TRUE(contains(html, "default-src 'none'")) << "a CSP forbids any other source";

    const std::string chromium = findChromium();
    if (chromium.empty()) GTEST_SKIP() << "chromium not installed (Debian package 'chromium'); report not rendered";
    const std::string dom = loadedDom(chromium, dir / "out/report.html", dir / "profile");
    if (!contains(dom, "<body")) GTEST_SKIP() << "chromium did not start headless; report not rendered";
    EXPECT_EQ(bodyAttribute(dom, "data-status"), "ok") << dom.substr(0, 400);
    EXPECT_EQ(bodyAttribute(dom, "data-images"), "12");
    EXPECT_EQ(bodyAttribute(dom, "data-broken"), "0");
    EXPECT_EQ(bodyAttribute(dom, "data-plots"), "4");
    EXPECT_EQ(bodyAttribute(dom, "data-plots-drawn"), "4");
    EXPECT_TRUE(contains(dom, "frame 1 (1/3)")) << "the flip-book script ran";

    // Control: the same page with one corrupted image must not pass the check.
    std::string broken = html;
    const size_t at = broken.find("base64,") + 7;
    broken.replace(at, 40, std::string(40, '!'));
    test::writeFile(dir / "out/broken.html", broken);
    const std::string bad = loadedDom(chromium, dir / "out/broken.html", dir / "profile2");
    EXPECT_EQ(bodyAttribute(bad, "data-status"), "error");
    EXPECT_EQ(bodyAttribute(bad, "data-broken"), "1");
}
