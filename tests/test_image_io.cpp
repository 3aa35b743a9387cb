#include "core/errors.h"
#include "render/image_io.h"
#include "test_support.h"

#include <gtest/gtest.h>

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
