// Reference noise, the noise-corrected error and the indirect/direct split (analysis/Accuracy.h).
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "analysis/Accuracy.h"
#include "core/Error.h"

using namespace gis;

namespace {
constexpr int kSide = 64;
constexpr size_t kValues = size_t(kSide) * kSide * 3;

// A smooth converged image with a black border (background).
std::vector<float> converged(float scale) {
    std::vector<float> img(kValues, 0.0f);
    for (int y = 4; y < kSide - 4; ++y)
        for (int x = 4; x < kSide - 4; ++x)
            for (int c = 0; c < 3; ++c)
                img[(size_t(y) * kSide + x) * 3 + c] =
                    scale * (0.5f + 0.4f * std::sin(0.2f * x + c) * std::cos(0.1f * y));
    return img;
}

// `truth` plus Gaussian noise of standard deviation `sigma` per covered value, and that variance.
void addNoise(const std::vector<float>& truth, float sigma, unsigned seed, std::vector<float>& noisy,
              std::vector<float>& variance) {
    std::mt19937 rng(seed);
    std::normal_distribution<float> n(0.0f, sigma);
    noisy = truth;
    variance.assign(truth.size(), 0.0f);
    for (size_t i = 0; i < truth.size(); ++i)
        if (truth[i] != 0.0f) {
            noisy[i] = truth[i] + n(rng);
            variance[i] = sigma * sigma;
        }
}

ImageView view(const std::vector<float>& v) {
    return ImageView(v, kSide, kSide, 3);
}
} // namespace

TEST(Accuracy, NoiseIsRelativeToTheReferenceAndCorrectionRecoversTheTrueError) {
    const std::vector<float> truth = converged(1.0f);
    std::vector<float> reference, variance;
    addNoise(truth, 0.05f, 1, reference, variance);
    std::vector<float> test = truth;
    for (float& v : test) v *= 1.03f; // 3% too bright everywhere: the true relative error is 0.03
    const double noise = relativeNoise(view(reference), variance);
    const double measured = relativeRmse(view(test), view(reference), maskFromNonZero(view(reference)));
    const double fixed =
        noiseCorrectedRelativeRmse(view(test), view(reference), variance, maskFromNonZero(view(reference)));
    std::printf("noise %.4f, measured %.4f, corrected %.4f (true 0.03)\n", noise, measured, fixed);
    EXPECT_GT(measured, 0.05); // the noise dominates the raw figure
    EXPECT_NEAR(fixed, 0.03, 0.004);
    EXPECT_LT(relativeNoise(view(reference), {}), 0.0); // unknown
    EXPECT_EQ(noiseCorrectedRelativeRmse(view(test), view(reference), {}),
              relativeRmse(view(test), view(reference)));
    EXPECT_EQ(relativeNoise(view(truth), std::vector<float>(kValues, 0.0f)), 0.0);
    // A test within the noise of the reference is corrected to 0, not to a negative or NaN figure.
    std::vector<float> generous = variance;
    for (float& v : generous) v *= 1.2f;
    EXPECT_EQ(noiseCorrectedRelativeRmse(view(truth), view(reference), generous), 0.0);
    // A reference that is all noise has no signal to be relative to.
    EXPECT_EQ(noiseCorrectedRelativeRmse(view(test), view(reference), std::vector<float>(kValues, 1.0f)),
              kRelativeRmseUndefined);
    EXPECT_THROW(relativeNoise(view(reference), std::vector<float>(7, 0.0f)), InputError);
}

TEST(Accuracy, IndirectLightIsEachTotalLessItsOwnDirectPass) {
    const std::vector<float> indirectTruth = converged(0.3f), directTruth = converged(1.0f);
    // The test's direct pass is 10% too dark (a shadow-map error); its indirect light is exact.
    std::vector<float> testDirect = directTruth, test(kValues);
    for (float& v : testDirect) v *= 0.9f;
    for (size_t i = 0; i < kValues; ++i) test[i] = testDirect[i] + indirectTruth[i];
    std::vector<float> refTotal(kValues), refVariance, referenceNoisy;
    for (size_t i = 0; i < kValues; ++i) refTotal[i] = directTruth[i] + indirectTruth[i];
    addNoise(refTotal, 0.01f, 2, referenceNoisy, refVariance);
    AccuracyInputs in;
    in.test = ImageView(test, kSide, kSide, 3);
    in.testDirect = ImageView(testDirect, kSide, kSide, 3);
    in.reference = view(referenceNoisy);
    in.referenceVariance = refVariance;
    in.referenceDirect = view(directTruth);
    const std::vector<float> exact(kValues, 0.0f);
    in.referenceDirectVariance = exact;
    const nlohmann::json j = compareAccuracy(in);
    std::printf("%s\n", j.dump().c_str());
    EXPECT_GT(j["relative_rmse"].get<double>(), 0.05);
    EXPECT_LT(j["indirect"]["relative_rmse_corrected"].get<double>(), 0.01);
    EXPECT_NEAR(j["indirect"]["mean_ratio"].get<double>(), 1.0, 0.01);
    EXPECT_GT(j["indirect"]["reference_noise"].get<double>(), j["reference_noise"].get<double>());
    EXPECT_NEAR(j["direct"]["relative_rmse"].get<double>(), 0.1, 1e-4);
    EXPECT_EQ(j["direct"]["reference_noise"].get<double>(), 0.0);

    // Without the reference's variance the noise is unknown (null) and nothing is corrected.
    in.referenceVariance = {};
    const nlohmann::json unknown = compareAccuracy(in);
    EXPECT_TRUE(unknown["reference_noise"].is_null());
    EXPECT_TRUE(unknown["indirect"]["reference_noise"].is_null());
    EXPECT_EQ(unknown["indirect"]["relative_rmse_corrected"], unknown["indirect"]["relative_rmse"]);
    // Without the direct images there is no split.
    in.testDirect = {};
    EXPECT_FALSE(compareAccuracy(in).contains("indirect"));
}

TEST(Accuracy, AViewTheLightsDoNotReachIsRefusedWithWhatToDo) {
    const std::vector<float> black(kValues, 0.0f), lit = converged(0.5f);
    AccuracyInputs in;
    in.test = view(lit); // light leaking onto surfaces the reference leaves dark
    in.reference = view(black);
    try {
        compareAccuracy(in);
        FAIL() << "a black reference was compared";
    } catch (const InputError& e) {
        EXPECT_EQ(e.where(), "/compare");
        EXPECT_NE(e.reason().find("black in every pixel"), std::string::npos) << e.what();
        EXPECT_NE(e.reason().find("turn the camera"), std::string::npos) << e.what();
    }
}
