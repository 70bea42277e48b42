// SSIM and LDR-FLIP: known answers on uniform images (where the filters are the identity and FLIP's feature
// term vanishes, so the result is the colour pipeline's closed form) and behaviour under noise.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "analysis/Metrics.h"

using gis::ImageView;

namespace {
constexpr int kW = 48;
constexpr int kH = 40;

// Deterministic noise in [-1, 1] that does not depend on the standard library's distributions.
std::vector<float> noisePattern(std::size_t n, std::uint32_t seed) {
    std::vector<float> out(n);
    std::uint32_t s = seed;
    for (float& v : out) {
        s = s * 1664525u + 1013904223u;
        v = float(s >> 8) / float(1u << 24) * 2.0f - 1.0f;
    }
    return out;
}

// A smooth sRGB scene: horizontal colour ramp with a brighter disc, values well inside (0, 1).
std::vector<float> sceneSrgb() {
    std::vector<float> img(std::size_t(kW * kH * 3));
    for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) {
            const float u = float(x) / float(kW - 1);
            const float v = float(y) / float(kH - 1);
            const float dx = float(x - kW / 2), dy = float(y - kH / 2);
            const float disc = dx * dx + dy * dy < 100.0f ? 0.25f : 0.0f;
            float* p = &img[std::size_t((y * kW + x) * 3)];
            p[0] = 0.2f + 0.4f * u + disc;
            p[1] = 0.3f + 0.3f * v + disc;
            p[2] = 0.5f - 0.2f * u + disc;
        }
    }
    return img;
}

std::vector<float> addNoise(const std::vector<float>& img, float amplitude, bool clamp01) {
    const auto noise = noisePattern(img.size(), 12345u);
    std::vector<float> out(img.size());
    for (std::size_t i = 0; i < img.size(); ++i) {
        out[i] = img[i] + amplitude * noise[i];
        if (clamp01)
            out[i] = std::fmin(1.0f, std::fmax(0.0f, out[i]));
        else
            out[i] = std::fmax(0.0f, out[i]);
    }
    return out;
}

std::vector<float> uniform(int w, int h, float r, float g, float b) {
    std::vector<float> img(std::size_t(w * h * 3));
    for (std::size_t p = 0; p < img.size(); p += 3) {
        img[p] = r;
        img[p + 1] = g;
        img[p + 2] = b;
    }
    return img;
}

// The same smooth scene read as linear radiance (values 0.1 to 0.95: mid-range after the filmic curve).
std::vector<float> sceneLinear() {
    return sceneSrgb();
}
} // namespace

TEST(Ssim, UniformImagesKnownAnswer) {
    // Zero variance: SSIM = (2 a b + C1) / (a^2 + b^2 + C1) with C1 = 1e-4.
    const std::vector<float> a(16, 0.5f), b(16, 0.25f);
    EXPECT_NEAR(gis::ssimGray(a, b, 4, 4), 0.8000639795265515, 1e-12);
    // Through the display transform: grey linear 1.0 and 0.5 have luma 0.908230 and 0.807319.
    const auto one = uniform(5, 3, 1, 1, 1);
    const auto half = uniform(5, 3, 0.5f, 0.5f, 0.5f);
    EXPECT_NEAR(gis::ssim(ImageView(one, 5, 3, 3), ImageView(half, 5, 3, 3)), 0.9931043340110447, 1e-6);
}

TEST(Ssim, IdenticalIsOneAndNoiseLowersIt) {
    const auto ref = sceneLinear();
    const ImageView r(ref, kW, kH, 3);
    EXPECT_DOUBLE_EQ(gis::ssim(r, r), 1.0);
    double previous = 1.0;
    for (float amplitude : {0.01f, 0.03f, 0.1f, 0.3f}) {
        const auto test = addNoise(ref, amplitude, false);
        const double s = gis::ssim(ImageView(test, kW, kH, 3), r);
        EXPECT_LT(s, previous) << "amplitude " << amplitude;
        EXPECT_GT(s, -1.0);
        previous = s;
    }
    EXPECT_LT(previous, 0.9);
}

TEST(Ssim, MaskAveragesOnlyIncludedPixels) {
    // Left half identical, right half noisy: SSIM over a mask of the left columns far from the seam is 1.
    const auto ref = sceneLinear();
    auto test = addNoise(ref, 0.2f, false);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW / 2; ++x)
            for (int c = 0; c < 3; ++c)
                test[std::size_t((y * kW + x) * 3 + c)] = ref[std::size_t((y * kW + x) * 3 + c)];
    gis::PixelMask mask(std::size_t(kW * kH), 0);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW / 2 - 6; ++x) mask[std::size_t(y * kW + x)] = 1;
    const ImageView t(test, kW, kH, 3), r(ref, kW, kH, 3);
    EXPECT_DOUBLE_EQ(gis::ssim(t, r, mask), 1.0);
    EXPECT_LT(gis::ssim(t, r), 0.95);
}

TEST(Flip, IdenticalIsZero) {
    const auto img = sceneSrgb();
    std::vector<float> map;
    EXPECT_EQ(gis::flipSrgb(img, img, kW, kH, {}, &map), 0.0);
    ASSERT_EQ(map.size(), std::size_t(kW * kH));
    for (float v : map) EXPECT_EQ(v, 0.0f);
    const ImageView lin(img, kW, kH, 3);
    EXPECT_EQ(gis::flip(lin, lin), 0.0);
}

TEST(Flip, UniformColoursMatchTheColourPipeline) {
    // For uniform images the CSF filters (unit sum, replicated borders) change nothing and every feature
    // response is 0, so FLIP = re-mapped HyAB(Hunt(Lab))^0.7, computed independently (cmax = 41.2755).
    const auto black = uniform(8, 8, 0, 0, 0);
    const auto white = uniform(8, 8, 1, 1, 1);
    // 100^0.7 = 25.12 > 0.4 cmax: 0.95 + (25.12 - 16.51) / (41.28 - 16.51) * 0.05.
    EXPECT_NEAR(gis::flipSrgb(black, white, 8, 8), 0.9673805159055133, 1e-5);
    EXPECT_NEAR(gis::flipSrgb(white, black, 8, 8), 0.9673805159055133, 1e-5);
    EXPECT_NEAR(gis::flipSrgb(uniform(8, 8, 0.5f, 0.5f, 0.5f), uniform(8, 8, 0.25f, 0.25f, 0.25f), 8, 8),
                0.5690675339587704, 1e-5);
    EXPECT_NEAR(gis::flipSrgb(uniform(8, 8, 1, 0, 0), uniform(8, 8, 0, 1, 0), 8, 8), 0.9866623109632834,
                1e-5);
    EXPECT_NEAR(gis::flipSrgb(uniform(8, 8, 0.8f, 0.2f, 0.1f), uniform(8, 8, 0.1f, 0.3f, 0.7f), 8, 8),
                0.9513989317593355, 1e-5);
}

TEST(Flip, BlackVersusWhiteLinearIsCloseToOne) {
    // Radiance 1e3 saturates the filmic curve to display white.
    const auto black = uniform(kW, kH, 0, 0, 0);
    const auto white = uniform(kW, kH, 1e3f, 1e3f, 1e3f);
    const double f = gis::flip(ImageView(black, kW, kH, 3), ImageView(white, kW, kH, 3));
    EXPECT_GT(f, 0.95);
    EXPECT_LE(f, 1.0);
}

TEST(Flip, ErrorMapInUnitRangeAndMeanMatches) {
    const auto ref = sceneSrgb();
    const auto test = addNoise(ref, 0.5f, true);
    std::vector<float> map;
    const double mean = gis::flipSrgb(test, ref, kW, kH, {}, &map);
    double sum = 0;
    for (float v : map) {
        EXPECT_GE(v, 0.0f);
        EXPECT_LE(v, 1.0f);
        sum += v;
    }
    EXPECT_NEAR(mean, sum / double(map.size()), 1e-6);
    EXPECT_GT(mean, 0.0);
    EXPECT_LE(mean, 1.0);

    // A hard-edged pattern against its inverse exercises the feature term: still inside [0, 1].
    std::vector<float> checker(std::size_t(kW * kH * 3)), inverse(checker.size());
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x)
            for (int c = 0; c < 3; ++c) {
                const float v = ((x / 3 + y / 3) % 2) ? 1.0f : 0.0f;
                checker[std::size_t((y * kW + x) * 3 + c)] = v;
                inverse[std::size_t((y * kW + x) * 3 + c)] = 1.0f - v;
            }
    const double f = gis::flipSrgb(checker, inverse, kW, kH, {}, &map);
    EXPECT_GT(f, 0.0);
    EXPECT_LE(f, 1.0);
    for (float v : map) EXPECT_TRUE(v >= 0.0f && v <= 1.0f);
}

TEST(Flip, SmallNoiseIsSmallAndErrorGrowsWithAmplitude) {
    const auto ref = sceneSrgb();
    double previous = 0.0;
    for (float amplitude : {0.005f, 0.01f, 0.02f, 0.05f, 0.1f, 0.2f, 0.4f}) {
        const auto test = addNoise(ref, amplitude, true);
        const double f = gis::flipSrgb(test, ref, kW, kH);
        EXPECT_GT(f, previous) << "amplitude " << amplitude;
        if (amplitude <= 0.01f) {
            EXPECT_LT(f, 0.05) << "amplitude " << amplitude;
        }
        previous = f;
    }
    EXPECT_GT(previous, 0.2);
}

TEST(Flip, MaskSelectsTheAverageAndZeroesTheMap) {
    const auto ref = sceneSrgb();
    const auto test = addNoise(ref, 0.1f, true);
    std::vector<float> full;
    (void)gis::flipSrgb(test, ref, kW, kH, {}, &full);
    gis::PixelMask mask(std::size_t(kW * kH), 0);
    double sum = 0;
    std::size_t count = 0;
    for (std::size_t p = 0; p < mask.size(); p += 3) {
        mask[p] = 1;
        sum += full[p];
        ++count;
    }
    std::vector<float> masked;
    EXPECT_NEAR(gis::flipSrgb(test, ref, kW, kH, mask, &masked), sum / double(count), 1e-9);
    for (std::size_t p = 0; p < mask.size(); ++p) EXPECT_EQ(masked[p], mask[p] ? full[p] : 0.0f);
}

TEST(Flip, DefaultViewingConditions) {
    EXPECT_NEAR(gis::defaultPixelsPerDegree(), 67.02064327658226, 1e-9);
    EXPECT_NEAR(gis::pixelsPerDegree(0.7, 0.7, 3840), 67.02064327658226, 1e-9);
}

TEST(CompareImages, CombinesEveryMetric) {
    const auto ref = sceneLinear();
    const auto test = addNoise(ref, 0.05f, false);
    const ImageView t(test, kW, kH, 3), r(ref, kW, kH, 3);
    const auto m = gis::compareImages(t, r, {}, 0.5);
    EXPECT_DOUBLE_EQ(m.rmse, gis::rmse(t, r));
    EXPECT_DOUBLE_EQ(m.relativeRmse, gis::relativeRmse(t, r));
    EXPECT_DOUBLE_EQ(m.psnr, gis::psnr(t, r));
    EXPECT_DOUBLE_EQ(m.maxAbsError, gis::maxAbsError(t, r));
    EXPECT_DOUBLE_EQ(m.ssim, gis::ssim(t, r, {}, 0.5));
    EXPECT_DOUBLE_EQ(m.flip, gis::flip(t, r, {}, 0.5));
    EXPECT_EQ(m.pixels, std::size_t(kW * kH));
    EXPECT_GT(m.psnr, 0.0);
    EXPECT_LT(m.psnr, gis::kPsnrLimitDb);
}
