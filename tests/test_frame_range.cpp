#include "core/errors.h"
#include "pipeline/batch/frame_range.h"
#include "pipeline/batch/path_template.h"

#include <gtest/gtest.h>

using namespace hp;

TEST(FrameRange, SingleFrame) { EXPECT_EQ(parseFrameRange("5"), (std::vector<int>{5})); }

TEST(FrameRange, InclusiveRange) {
    const auto f = parseFrameRange("1-120");
    ASSERT_EQ(f.size(), 120u);
    EXPECT_EQ(f.front(), 1);
    EXPECT_EQ(f.back(), 120);
}

TEST(FrameRange, Step) { EXPECT_EQ(parseFrameRange("1-9x2"), (std::vector<int>{1, 3, 5, 7, 9})); }

TEST(FrameRange, StepThatDoesNotLandOnEnd) { EXPECT_EQ(parseFrameRange("1-10x4"), (std::vector<int>{1, 5, 9})); }

TEST(FrameRange, ListIsSortedAndUnique) {
    EXPECT_EQ(parseFrameRange("10-12, 3,7,11"), (std::vector<int>{3, 7, 10, 11, 12}));
}

TEST(FrameRange, NegativeFrames) { EXPECT_EQ(parseFrameRange("-2-1"), (std::vector<int>{-2, -1, 0, 1})); }

TEST(FrameRange, InvalidInputsNameTheItem) {
    for (const char* bad : {"", "a", "1-", "5-1", "1-10x0", "1-10x", "1,,2", "1-10y2", "3.5", "1-20000000",
                            "0-9999999"}) {
        try {
            parseFrameRange(bad);
            ADD_FAILURE() << "accepted '" << bad << "'";
        } catch (const UsageError& e) {
            EXPECT_NE(std::string(e.what()).find("frame range"), std::string::npos) << e.what();
        }
    }
}

TEST(FrameRange, FormatRoundTrips) {
    for (const char* text : {"1-120", "1-9x2", "3,7,10-20", "5", "1,2", "-3-3"}) {
        const auto frames = parseFrameRange(text);
        EXPECT_EQ(parseFrameRange(formatFrameRange(frames)), frames) << text << " -> " << formatFrameRange(frames);
    }
    EXPECT_EQ(formatFrameRange(parseFrameRange("1-9x2")), "1-9x2");
    EXPECT_EQ(formatFrameRange(parseFrameRange("3,7,10-20")), "3,7,10-20");
}

TEST(PathTemplate, Hashes) {
    EXPECT_EQ(expandFrame("preview.####.png", 7), "preview.0007.png");
    EXPECT_EQ(expandFrame("a/b.#.exr", 12), "a/b.12.exr");
    EXPECT_EQ(expandFrame("x.####.vdb", 12345), "x.12345.vdb");
}

TEST(PathTemplate, Printf) {
    EXPECT_EQ(expandFrame("hair.%04d.vdb", 42), "hair.0042.vdb");
    EXPECT_EQ(expandFrame("hair.%d.vdb", 42), "hair.42.vdb");
}

TEST(PathTemplate, NegativeFrameKeepsWidth) { EXPECT_EQ(expandFrame("f.####.png", -3), "f.-0003.png"); }

TEST(PathTemplate, MissingOrDoubleTokenIsAnError) {
    EXPECT_THROW(expandFrame("preview.png", 1), UsageError);
    EXPECT_THROW(expandFrame("a.####.b.%04d.png", 1), UsageError);
    EXPECT_FALSE(hasFrameToken("100%.png"));
    EXPECT_TRUE(hasFrameToken("x.%03d.png"));
}
