// Pixel metrics (RMSE, relative RMSE, PSNR, max error), masks, input checks and the JSON shape.
// Expected values are computed by hand in the comments.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "analysis/Metrics.h"
#include "core/Error.h"

using gis::ImageView;

namespace {
// Two pixels: reference (1,1,1) (2,2,2); test differs by 3 in the last channel of pixel 1.
const std::vector<float> kRef = {1, 1, 1, 2, 2, 2};
const std::vector<float> kTest = {1, 1, 1, 2, 2, 5};

ImageView view(const std::vector<float>& v, int w, int h, int c = 3) {
    return {v, w, h, c};
}
} // namespace

TEST(PixelMetrics, KnownAnswersWholeImage) {
    const auto t = view(kTest, 2, 1);
    const auto r = view(kRef, 2, 1);
    // Squared errors 0,0,0,0,0,9 -> mean 9/6 = 1.5; mean r^2 = (3 * 1 + 3 * 4) / 6 = 2.5.
    EXPECT_DOUBLE_EQ(gis::rmse(t, r), std::sqrt(1.5));
    EXPECT_DOUBLE_EQ(gis::relativeRmse(t, r), std::sqrt(0.6));
    // peak 2: 20 log10(2 / sqrt(1.5)) = 10 log10(4 / 1.5).
    EXPECT_NEAR(gis::psnr(t, r), 4.259687322722811, 1e-12);
    EXPECT_DOUBLE_EQ(gis::maxAbsError(t, r), 3.0);
}

TEST(PixelMetrics, MaskSelectsPixels) {
    const auto t = view(kTest, 2, 1);
    const auto r = view(kRef, 2, 1);
    // Only the identical pixel.
    EXPECT_EQ(gis::rmse(t, r, {1, 0}), 0.0);
    EXPECT_EQ(gis::relativeRmse(t, r, {1, 0}), 0.0);
    EXPECT_EQ(gis::psnr(t, r, {1, 0}), gis::kPsnrLimitDb);
    EXPECT_EQ(gis::maxAbsError(t, r, {1, 0}), 0.0);
    // Only the second pixel: squared errors 0,0,9 -> mse 3; mean r^2 = 4; peak 2.
    EXPECT_DOUBLE_EQ(gis::rmse(t, r, {0, 1}), std::sqrt(3.0));
    EXPECT_DOUBLE_EQ(gis::relativeRmse(t, r, {0, 1}), std::sqrt(3.0) / 2.0);
    EXPECT_NEAR(gis::psnr(t, r, {0, 1}), 1.2493873660829993, 1e-12);
    // Any non-zero byte includes the pixel.
    EXPECT_DOUBLE_EQ(gis::rmse(t, r, {0, 255}), std::sqrt(3.0));

    const auto m = gis::compareImages(kTest.data(), kRef.data(), 2, 1, 3, {0, 1});
    EXPECT_EQ(m.pixels, 1u);
    EXPECT_DOUBLE_EQ(m.rmse, std::sqrt(3.0));
}

TEST(PixelMetrics, AlphaIsIgnoredAndChannelCountsMayDiffer) {
    const std::vector<float> test4 = {1, 1, 1, 0.25f, 2, 2, 5, -7};
    const std::vector<float> ref4 = {1, 1, 1, 1, 2, 2, 2, 1e6f};
    const auto a = gis::compareImages(test4.data(), ref4.data(), 2, 1, 4);
    const auto b = gis::compareImages(kTest.data(), kRef.data(), 2, 1, 3);
    EXPECT_DOUBLE_EQ(a.rmse, b.rmse);
    EXPECT_DOUBLE_EQ(a.maxAbsError, b.maxAbsError);
    EXPECT_DOUBLE_EQ(a.ssim, b.ssim);
    EXPECT_DOUBLE_EQ(a.flip, b.flip);
    EXPECT_DOUBLE_EQ(gis::rmse(view(test4, 2, 1, 4), view(kRef, 2, 1, 3)), std::sqrt(1.5));
}

TEST(PixelMetrics, ZeroReferenceGuards) {
    const std::vector<float> zero(12, 0.0f);
    const std::vector<float> some = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0.5f};
    const auto same = gis::compareImages(zero.data(), zero.data(), 2, 2, 3);
    EXPECT_EQ(same.rmse, 0.0);
    EXPECT_EQ(same.relativeRmse, 0.0);
    EXPECT_EQ(same.psnr, gis::kPsnrLimitDb);
    EXPECT_EQ(same.maxAbsError, 0.0);
    EXPECT_DOUBLE_EQ(same.ssim, 1.0);
    EXPECT_EQ(same.flip, 0.0);

    const auto diff = gis::compareImages(some.data(), zero.data(), 2, 2, 3);
    EXPECT_EQ(diff.relativeRmse, gis::kRelativeRmseUndefined);
    EXPECT_EQ(diff.psnr, -gis::kPsnrLimitDb);
    for (double v : {diff.rmse, diff.relativeRmse, diff.psnr, diff.maxAbsError, diff.ssim, diff.flip})
        EXPECT_TRUE(std::isfinite(v));
    EXPECT_NO_THROW((void)gis::toJson(diff).dump());
}

TEST(PixelMetrics, IdenticalImages) {
    const std::vector<float> img = {0.1f, 0.2f, 0.3f, 4, 5, 6, 0, 0, 0, 1e3f, 0.5f, 0.25f};
    const auto m = gis::compareImages(img.data(), img.data(), 2, 2, 3);
    EXPECT_EQ(m.rmse, 0.0);
    EXPECT_EQ(m.relativeRmse, 0.0);
    EXPECT_EQ(m.psnr, gis::kPsnrLimitDb);
    EXPECT_EQ(m.maxAbsError, 0.0);
    EXPECT_DOUBLE_EQ(m.ssim, 1.0);
    EXPECT_EQ(m.flip, 0.0);
    EXPECT_EQ(m.pixels, 4u);
}

TEST(PixelMetrics, NegativeReferencePeakGivesLowerLimit) {
    const std::vector<float> ref = {-1, -1, -1};
    const std::vector<float> test = {-1, -1, -0.5f};
    EXPECT_EQ(gis::psnr(view(test, 1, 1), view(ref, 1, 1)), -gis::kPsnrLimitDb);
}

TEST(MetricsInput, SizeMismatchThrowsInputError) {
    const std::vector<float> a(2 * 2 * 3, 0.5f);
    const std::vector<float> b(2 * 3 * 3, 0.5f);
    EXPECT_THROW((void)gis::rmse(view(a, 2, 2), view(b, 2, 3)), gis::InputError);
    EXPECT_THROW((void)gis::compareImages(view(a, 2, 2), view(b, 3, 2)), gis::InputError);
    // Buffer shorter than its declared size.
    EXPECT_THROW((void)gis::rmse(view(a, 2, 2), view(a, 4, 2)), gis::InputError);
    // Mask of the wrong length, and a mask that selects nothing.
    EXPECT_THROW((void)gis::rmse(view(a, 2, 2), view(a, 2, 2), {1, 1, 1}), gis::InputError);
    EXPECT_THROW((void)gis::rmse(view(a, 2, 2), view(a, 2, 2), {0, 0, 0, 0}), gis::InputError);
    try {
        (void)gis::compareImages(view(a, 2, 2), view(b, 2, 3));
        FAIL() << "no exception";
    } catch (const gis::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("2x2"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("2x3"), std::string::npos) << e.what();
    }
}

TEST(MetricsInput, BadShapesAndValuesThrowInputError) {
    const std::vector<float> a(2 * 2 * 3, 0.5f);
    EXPECT_THROW((void)gis::rmse(view(a, 6, 1, 2), view(a, 6, 1, 2)), gis::InputError); // channels 2
    EXPECT_THROW((void)gis::rmse(view(a, 0, 4), view(a, 0, 4)), gis::InputError);
    EXPECT_THROW((void)gis::compareImages(nullptr, a.data(), 2, 2, 3), gis::InputError);
    std::vector<float> bad = a;
    bad[4] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW((void)gis::rmse(view(bad, 2, 2), view(a, 2, 2)), gis::InputError);
    bad[4] = std::numeric_limits<float>::infinity();
    EXPECT_THROW((void)gis::compareImages(view(a, 2, 2), view(bad, 2, 2)), gis::InputError);
    EXPECT_THROW((void)gis::compareImages(view(a, 2, 2), view(a, 2, 2), {}, std::nan("")), gis::InputError);
    EXPECT_THROW((void)gis::ssimGray(std::vector<float>(3), std::vector<float>(4), 2, 2), gis::InputError);
    EXPECT_THROW((void)gis::flipSrgb(a, a, 2, 2, {}, nullptr, 0.0), gis::InputError);
    EXPECT_THROW((void)gis::pixelsPerDegree(0.7, 0.0, 3840), gis::InputError);
}

TEST(MetricsJson, HasTheDocumentedKeys) {
    gis::ImageMetrics m;
    m.rmse = 1;
    m.relativeRmse = 2;
    m.psnr = 3;
    m.maxAbsError = 4;
    m.ssim = 0.5;
    m.flip = 0.25;
    m.pixels = 7;
    const auto j = gis::toJson(m);
    EXPECT_EQ(j.size(), 7u);
    EXPECT_EQ(j.at("rmse"), 1.0);
    EXPECT_EQ(j.at("relative_rmse"), 2.0);
    EXPECT_EQ(j.at("psnr_db"), 3.0);
    EXPECT_EQ(j.at("max_abs_error"), 4.0);
    EXPECT_EQ(j.at("ssim"), 0.5);
    EXPECT_EQ(j.at("flip"), 0.25);
    EXPECT_EQ(j.at("pixels"), 7u);
}

TEST(Masks, MaskFromNonZeroAndCoverage) {
    // Pixels: black, red only, blue only, black with alpha 1.
    const std::vector<float> rgba = {0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 1e-9f, 0.4f, 0, 0, 0, 1};
    EXPECT_EQ(gis::maskFromNonZero(rgba.data(), 2, 2, 4), (gis::PixelMask{0, 1, 1, 0}));
    EXPECT_EQ(gis::coverageMask(rgba.data(), 2, 2), (gis::PixelMask{0, 1, 0, 1}));
    const std::vector<float> rgb = {0, 0, 0, 0, -1, 0};
    EXPECT_EQ(gis::maskFromNonZero(view(rgb, 2, 1)), (gis::PixelMask{0, 1}));
    EXPECT_THROW((void)gis::coverageMask(nullptr, 2, 2), gis::InputError);
}

TEST(ToneMap, MatchesTheDisplayTransform) {
    // filmic(1) = 2.54 / 3.16, then sRGB-encoded: 1.055 * 0.80380^(1/2.4) - 0.055.
    const std::vector<float> one = {1, 1, 1, 0, 0, 0, -5, 1e30f, 0.18f};
    const auto out = gis::toneMapForMetrics(view(one, 3, 1));
    ASSERT_EQ(out.size(), 9u);
    EXPECT_NEAR(out[0], 0.9082304956696972, 1e-6);
    EXPECT_EQ(out[3], 0.0f);
    EXPECT_EQ(out[6], 0.0f); // negative radiance clamps to black
    EXPECT_EQ(out[7], 1.0f); // huge radiance saturates
    // 0.18 at +1 EV is 0.36 at 0 EV.
    const auto plusOne = gis::toneMapForMetrics(view(one, 3, 1), 1.0);
    EXPECT_NEAR(plusOne[8], 0.7377522039317453, 1e-6);
    // Extreme exposures stay finite.
    for (double ev : {-2000.0, 2000.0})
        for (float v : gis::toneMapForMetrics(view(one, 3, 1), ev)) EXPECT_TRUE(v >= 0.0f && v <= 1.0f);
}
