#include <cmath>

#include <gtest/gtest.h>

#include "scene/TextureMips.h"

namespace gis {
namespace {

TextureImage filled(int width, int height, bool srgb, std::uint8_t r, std::uint8_t g, std::uint8_t b,
                    std::uint8_t a) {
    TextureImage image;
    image.width = width;
    image.height = height;
    image.srgb = srgb;
    image.rgba.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4);
    for (std::size_t i = 0; i < image.rgba.size(); i += 4) {
        image.rgba[i] = r;
        image.rgba[i + 1] = g;
        image.rgba[i + 2] = b;
        image.rgba[i + 3] = a;
    }
    return image;
}

TEST(TextureMips, LevelSizesHalveDownToOneTexelAsGlDoes) {
    EXPECT_EQ(mipLevelCount(1, 1), 1);
    EXPECT_EQ(mipLevelCount(2048, 2048), 12);
    EXPECT_EQ(mipLevelCount(5, 3), 3);
    EXPECT_EQ(mipLevelCount(1, 9), 4);

    const std::vector<MipLevel> chain = mipChain(filled(5, 3, true, 10, 20, 30, 40));
    ASSERT_EQ(chain.size(), 2u);
    EXPECT_EQ(chain[0].width, 2);
    EXPECT_EQ(chain[0].height, 1);
    EXPECT_EQ(chain[1].width, 1);
    EXPECT_EQ(chain[1].height, 1);
    for (const MipLevel& level : chain)
        EXPECT_EQ(level.rgba.size(), static_cast<std::size_t>(level.width * level.height * 4));

    const std::vector<MipLevel> tall = mipChain(filled(1, 9, false, 1, 2, 3, 4));
    ASSERT_EQ(tall.size(), 3u);
    EXPECT_EQ(tall.back().width, 1);
    EXPECT_EQ(tall.back().height, 1);
    EXPECT_TRUE(mipChain(filled(1, 1, true, 0, 0, 0, 0)).empty());
}

TEST(TextureMips, AConstantImageStaysConstantOnEveryLevel) {
    for (const bool srgb : {true, false}) {
        for (const MipLevel& level : mipChain(filled(16, 8, srgb, 0, 77, 200, 255)))
            for (std::size_t i = 0; i < level.rgba.size(); i += 4) {
                EXPECT_EQ(level.rgba[i], 0);
                EXPECT_EQ(level.rgba[i + 1], 77) << "srgb " << srgb;
                EXPECT_EQ(level.rgba[i + 2], 200) << "srgb " << srgb;
                EXPECT_EQ(level.rgba[i + 3], 255);
            }
    }
}

TEST(TextureMips, ColourIsAveragedInLinearLightAlphaAndDataAsStored) {
    // A black and white checker: half the light. In sRGB that is 188, not the byte mean 128.
    for (const bool srgb : {true, false}) {
        TextureImage checker = filled(2, 2, srgb, 0, 0, 0, 0);
        for (int i : {0, 3}) {
            for (int c = 0; c < 4; ++c) checker.rgba[static_cast<std::size_t>(i * 4 + c)] = 255;
        }
        const std::vector<MipLevel> chain = mipChain(checker);
        ASSERT_EQ(chain.size(), 1u);
        const int expectedColour =
            srgb ? static_cast<int>(std::lround(255.0 * (1.055 * std::pow(0.5, 1 / 2.4) - 0.055))) : 128;
        EXPECT_NEAR(chain[0].rgba[0], expectedColour, 1) << "srgb " << srgb;
        EXPECT_EQ(chain[0].rgba[3], 128) << "alpha is coverage, averaged as stored";
    }
}

TEST(TextureMips, OddSizesReduceTheTexelsAboveEachTexel) {
    // 3 x 1, values 0, 100, 200 (data): level 1 is 1 x 1 and means texels 0 and 1; the last column,
    // beyond floor halving, is left out as GL's box filter leaves it.
    TextureImage row = filled(3, 1, false, 0, 0, 0, 0);
    row.rgba[4] = 100;
    row.rgba[8] = 200;
    const std::vector<MipLevel> chain = mipChain(row);
    ASSERT_EQ(chain.size(), 1u);
    EXPECT_EQ(chain[0].rgba[0], 50);
}

} // namespace
} // namespace gis
