#include "core/errors.h"
#include "render/image/display_transform.h"
#include "render/image/image_io.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <sys/resource.h>

using namespace hp;

namespace {
Image gradient() {
    Image img(16, 8, {"R", "G", "B", "A", "Z"});
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            img.at(x, y, 0) = x / 15.f;
            img.at(x, y, 1) = y / 7.f;
            img.at(x, y, 2) = 0.25f;
            img.at(x, y, 3) = (x + y) % 2 ? 1.f : 0.5f;
            img.at(x, y, 4) = 1.2345678f + x * 0.001f;
        }
    return img;
}
}  // namespace

TEST(ImageIo, ExrRoundTripKeepsChannelsAndFullPrecisionDepth) {
    test::TempDir dir;
    const Image in = gradient();
    writeImage((dir / "a.exr").string(), in);
    const Image out = readImage((dir / "a.exr").string());
    ASSERT_EQ(out.width, 16);
    ASSERT_EQ(out.height, 8);
    ASSERT_EQ(out.channels, in.channels);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 16; ++x) {
            for (int c = 0; c < 4; ++c) EXPECT_NEAR(out.at(x, y, c), in.at(x, y, c), 1e-3f);  // half
            EXPECT_EQ(out.at(x, y, 4), in.at(x, y, 4)) << "depth is stored as 32-bit float";
        }
}

TEST(ImageIo, PngIsSrgbEncodedRgba) {
    test::TempDir dir;
    Image in(4, 1, {"R", "G", "B", "A", "Z"});
    for (int x = 0; x < 4; ++x) {
        in.at(x, 0, 0) = in.at(x, 0, 1) = in.at(x, 0, 2) = 0.2f;  // linear 0.2 -> sRGB ~0.484
        in.at(x, 0, 3) = 1.f;
    }
    writeImage((dir / "a.png").string(), in);
    const Image raw = readImage((dir / "a.png").string());
    ASSERT_EQ(raw.channelCount(), 4) << "PNG keeps R, G, B, A only";
    EXPECT_NEAR(raw.at(0, 0, 0), 0.484f, 0.01f);
    EXPECT_NEAR(raw.at(0, 0, 3), 1.f, 1e-6f) << "alpha is not colour-converted";
    const Image lin = readImage((dir / "a.png").string(), true);
    EXPECT_NEAR(lin.at(0, 0, 0), 0.2f, 0.01f);
}

TEST(ImageIo, PngOfPartialAlphaEncodesTheUnpremultipliedColour) {
    test::TempDir dir;
    Image in(1, 1, {"R", "G", "B", "A"});
    in.at(0, 0, 0) = in.at(0, 0, 1) = in.at(0, 0, 2) = 0.1f;  // premultiplied: colour 0.5 at alpha 0.2
    in.at(0, 0, 3) = 0.2f;
    writeImage((dir / "p.png").string(), in);
    const Image back = readImage((dir / "p.png").string());  // OIIO associates alpha on read
    ASSERT_NEAR(back.at(0, 0, 3), 0.2f, 0.005f);
    EXPECT_NEAR(back.at(0, 0, 0) / back.at(0, 0, 3), 0.735f, 0.02f) << "sRGB(0.5), stored unassociated";
}

TEST(ImageIo, MissingOrBrokenFileNamesTheFile) {
    test::TempDir dir;
    try {
        readImage((dir / "none.exr").string());
        FAIL();
    } catch (const AssetError& e) {
        EXPECT_NE(std::string(e.what()).find("none.exr"), std::string::npos);
    }
    test::writeFile(dir / "bad.exr", "not an exr");
    EXPECT_THROW(readImage((dir / "bad.exr").string()), AssetError);
}

TEST(ImageIo, UnwritablePathIsAnIoError) {
    EXPECT_THROW(writeImage("/nonexistent-dir/x.exr", gradient()), IoError);
}

TEST(ImageIo, FullDiskIsAnIoErrorForEveryFormat) {
    // A file-size limit with SIGXFSZ ignored makes every write past it fail
    // with EFBIG, as a full disk does with ENOSPC.
    test::TempDir dir;
    Image noise(96, 96, {"R", "G", "B", "A"});
    uint32_t h = 1;
    for (float& v : noise.pixels) v = float((h = h * 1664525u + 1013904223u) >> 8) / 16777216.f;  // incompressible
    struct sigaction ignore = {}, oldAction = {};
    ignore.sa_handler = SIG_IGN;
    ASSERT_EQ(sigaction(SIGXFSZ, &ignore, &oldAction), 0);
    rlimit oldLimit = {};
    ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &oldLimit), 0);
    rlimit tiny = oldLimit;
    tiny.rlim_cur = 4096;
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &tiny), 0);
    std::vector<std::string> missed;
    for (const char* ext : {".png", ".exr", ".tif", ".jpg"}) {
        const std::string path = (dir / (std::string("full") + ext)).string();
        try {
            writeImage(path, noise);
            missed.push_back(ext);
        } catch (const IoError& e) {
            EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("disk full"), std::string::npos) << e.what();
        }
    }
    setrlimit(RLIMIT_FSIZE, &oldLimit);
    sigaction(SIGXFSZ, &oldAction, nullptr);
    EXPECT_TRUE(missed.empty()) << "no error from a truncated write of " << ::testing::PrintToString(missed);
}

// ------------------------------------------------------ display transform --

namespace {
/// The README's built-in filmic view, written out here: Narkowicz's ACES fit
/// then the sRGB transfer function.
float documentedFilmic(float x) {
    const float f = std::clamp(x * (2.51f * x + 0.03f) / (x * (2.43f * x + 0.59f) + 0.14f), 0.f, 1.f);
    return f <= 0.0031308f ? 12.92f * f : 1.055f * std::pow(f, 1.f / 2.4f) - 0.055f;
}

Image flat(const std::vector<float>& values, float alpha) {
    Image img(int(values.size()), 1, {"R", "G", "B", "A"});
    for (int x = 0; x < img.width; ++x) {
        for (int c = 0; c < 3; ++c) img.at(x, 0, c) = values[size_t(x)] * alpha;  // premultiplied
        img.at(x, 0, 3) = alpha;
    }
    return img;
}
}  // namespace

TEST(DisplayTransform, FilmicViewFollowsTheDocumentedCurve) {
    test::TempDir dir;
    const std::vector<float> values{0.f, 0.01f, 0.05f, 0.18f, 0.5f, 1.f, 2.f, 4.f, 16.f, 100.f};
    const std::string png = (dir / "f.png").string();
    writeImageWithDisplay(png, flat(values, 1.f), DisplaySettings{});
    const Image back = readImage(png);
    for (size_t i = 0; i < values.size(); ++i)
        EXPECT_NEAR(back.at(int(i), 0, 0), documentedFilmic(values[i]), 1.f / 255.f) << "scene-linear " << values[i];
    // A filmic shoulder: scene-linear 2 and 4 (which an sRGB clamp clips
    // at 1) still show below white and apart; 100 is white.
    EXPECT_LT(back.at(6, 0, 0), 0.97f);
    EXPECT_LT(back.at(7, 0, 0), 254.5f / 255.f);
    EXPECT_GT(back.at(7, 0, 0), back.at(6, 0, 0));
    EXPECT_EQ(back.at(9, 0, 0), 1.f);
    // Exposure: +1 stop shows 0.09 as 0.18.
    DisplaySettings plus;
    plus.exposure = 1.f;
    const Image shown = toDisplay(flat({0.09f}, 1.f), plus);
    EXPECT_NEAR(shown.at(0, 0, 0), documentedFilmic(0.18f), 1e-4f);
    // The 'standard' view is the sRGB transfer function alone.
    DisplaySettings standard;
    standard.view = "standard";
    EXPECT_NEAR(toDisplay(flat({0.2f}, 1.f), standard).at(0, 0, 0), 0.4845f, 2e-3f);
}

TEST(DisplayTransform, PartialAlphaTransformsTheUnpremultipliedColour) {
    const Image shown = toDisplay(flat({0.5f}, 0.2f), DisplaySettings{});
    ASSERT_EQ(shown.channelCount(), 4);
    EXPECT_NEAR(shown.at(0, 0, 3), 0.2f, 1e-6f);
    EXPECT_NEAR(shown.at(0, 0, 0) / shown.at(0, 0, 3), documentedFilmic(0.5f), 1e-4f);
}

TEST(DisplayTransform, BackdropOnlyInDisplayImagesExrKeepsAlpha) {
    test::TempDir dir;
    Image img(4, 6, {"R", "G", "B", "A", "Z"});  // empty: alpha 0 everywhere but one pixel
    for (int c = 0; c < 3; ++c) img.at(1, 2, c) = 0.3f;
    img.at(1, 2, 3) = 1.f;
    DisplaySettings d;
    d.backdrop.kind = Backdrop::Kind::Gradient;
    d.backdrop.top = Vec3f(0.1f, 0.1f, 0.1f);
    d.backdrop.bottom = Vec3f(0.02f, 0.02f, 0.02f);
    writeImageWithDisplay((dir / "b.png").string(), img, d);
    writeImageWithDisplay((dir / "b.exr").string(), img, d);
    const Image png = readImage((dir / "b.png").string());
    ASSERT_EQ(png.channelCount(), 4);
    for (int y = 0; y < 6; ++y)
        for (int x = 0; x < 4; ++x) EXPECT_EQ(png.at(x, y, 3), 1.f) << "the backdrop makes the PNG opaque";
    EXPECT_NEAR(png.at(0, 0, 0), documentedFilmic(0.1f), 1.f / 255.f) << "top row: the gradient's top";
    EXPECT_NEAR(png.at(0, 5, 0), documentedFilmic(0.02f), 1.f / 255.f) << "bottom row: its bottom";
    EXPECT_GT(png.at(0, 2, 0), png.at(0, 3, 0)) << "a gradient falls from top to bottom";
    EXPECT_NEAR(png.at(1, 2, 0), documentedFilmic(0.3f), 1.f / 255.f) << "covered pixels show the render";
    const Image exr = readImage((dir / "b.exr").string());
    ASSERT_EQ(exr.channels, img.channels);
    EXPECT_EQ(exr.at(0, 0, 3), 0.f) << "EXRs keep their alpha";
    EXPECT_EQ(exr.at(0, 0, 0), 0.f) << "and stay linear, without the backdrop";
    EXPECT_NEAR(exr.at(1, 2, 0), 0.3f, 1e-3f);
}

TEST(DisplayTransform, OcioConfigViewIsApplied) {
    test::TempDir dir;
    // A config whose one view halves scene-linear values.
    const std::string config = (dir / "half.ocio").string();
    test::writeFile(config, R"(ocio_profile_version: 1
roles:
  default: lin
  scene_linear: lin
displays:
  test:
    - !<View> {name: half, colorspace: halved}
active_displays: [test]
active_views: [half]
colorspaces:
  - !<ColorSpace>
    name: lin
  - !<ColorSpace>
    name: halved
    from_reference: !<MatrixTransform> {matrix: [0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 1]}
)");
    DisplaySettings d;
    d.ocioConfig = config;
    checkDisplaySettings(d);
    const Image shown = toDisplay(flat({0.6f, 0.2f}, 1.f), d);
    EXPECT_NEAR(shown.at(0, 0, 0), 0.3f, 1e-4f);
    EXPECT_NEAR(shown.at(1, 0, 2), 0.1f, 1e-4f);
    d.view = "nope";
    try {
        checkDisplaySettings(d);
        FAIL() << "an unknown view must be an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("nope"), std::string::npos) << e.what();
    }
    d.ocioConfig = (dir / "missing.ocio").string();
    EXPECT_THROW(checkDisplaySettings(d), Error);
}
