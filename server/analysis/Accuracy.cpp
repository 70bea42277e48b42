// Whole-image, indirect-only and direct-only error with the reference's noise (Accuracy.h).
#include "analysis/Accuracy.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/Error.h"

namespace gis {
namespace {

struct NoiseSums {
    double squaredError = 0, squaredReference = 0, variance = 0, testSum = 0, referenceSum = 0;
};

void checkVariance(std::span<const float> variance, const ImageView& reference) {
    const std::size_t expected = std::size_t(reference.width) * std::size_t(reference.height) * 3;
    if (!variance.empty() && variance.size() != expected)
        throw InputError("variance", "has " + std::to_string(variance.size()) +
                                         " values, the reference needs " + std::to_string(expected));
}

NoiseSums noiseSums(const ImageView* test, const ImageView& reference, std::span<const float> variance,
                    const PixelMask& mask) {
    checkVariance(variance, reference);
    NoiseSums s;
    const std::size_t count = std::size_t(reference.width) * std::size_t(reference.height);
    const auto rc = std::size_t(reference.channels);
    const auto tc = test ? std::size_t(test->channels) : 0;
    for (std::size_t p = 0; p < count; ++p) {
        if (!mask.empty() && mask[p] == 0) continue;
        for (std::size_t c = 0; c < 3; ++c) {
            const double r = reference.pixels[p * rc + c];
            s.squaredReference += r * r;
            s.referenceSum += r;
            if (!variance.empty()) s.variance += std::max(0.0, double(variance[p * 3 + c]));
            if (test) {
                const double t = test->pixels[p * tc + c];
                s.squaredError += (t - r) * (t - r);
                s.testSum += t;
            }
        }
    }
    return s;
}

double corrected(const NoiseSums& s, bool varianceKnown) {
    if (s.squaredError == 0) return 0;
    const double signal = s.squaredReference - (varianceKnown ? s.variance : 0.0);
    if (!(signal > 0)) return kRelativeRmseUndefined;
    const double error = std::max(0.0, s.squaredError - (varianceKnown ? s.variance : 0.0));
    return std::min(std::sqrt(error / signal), kRelativeRmseUndefined);
}

nlohmann::json noiseJson(double noise) {
    return noise < 0 ? nlohmann::json(nullptr) : nlohmann::json(noise);
}

bool hasPixels(const ImageView& v) {
    return !v.pixels.empty();
}

} // namespace

double relativeNoise(const ImageView& reference, std::span<const float> variance, const PixelMask& mask) {
    const NoiseSums s = noiseSums(nullptr, reference, variance, mask);
    if (variance.empty()) return -1.0;
    if (s.variance == 0) return 0.0;
    if (!(s.squaredReference > 0)) return kRelativeRmseUndefined;
    return std::min(std::sqrt(s.variance / s.squaredReference), kRelativeRmseUndefined);
}

double noiseCorrectedRelativeRmse(const ImageView& test, const ImageView& reference,
                                  std::span<const float> variance, const PixelMask& mask) {
    const double measured = relativeRmse(test, reference, mask); // validates the pair and the mask
    if (variance.empty()) return measured;
    return corrected(noiseSums(&test, reference, variance, mask), true);
}

std::vector<float> differenceRgb(const ImageView& a, const ImageView& b) {
    if (a.width != b.width || a.height != b.height || a.width <= 0 || a.height <= 0)
        throw InputError("image", "the two images of a difference must have the same size");
    const std::size_t count = std::size_t(a.width) * std::size_t(a.height);
    if (a.pixels.size() != count * std::size_t(a.channels) ||
        b.pixels.size() != count * std::size_t(b.channels))
        throw InputError("image", "pixel data does not match the image size");
    std::vector<float> out(count * 3);
    for (std::size_t p = 0; p < count; ++p)
        for (std::size_t c = 0; c < 3; ++c)
            out[p * 3 + c] =
                a.pixels[p * std::size_t(a.channels) + c] - b.pixels[p * std::size_t(b.channels) + c];
    return out;
}

nlohmann::json compareAccuracy(const AccuracyInputs& in) {
    // Background is black in the reference; leaving it out keeps the figures about the scene.
    const PixelMask mask = maskFromNonZero(in.reference);
    // A view of unlit surfaces only (the outside of a box whose light is inside) has no relative
    // error: the metrics below would refuse the empty mask with words about masks.
    if (std::none_of(mask.begin(), mask.end(), [](std::uint8_t m) { return m != 0; }))
        throw InputError("/compare", "the reference is black in every pixel of this view: nothing a light "
                                     "reaches is in sight, so there is no error to measure; turn the camera "
                                     "toward a lit part of the scene");
    nlohmann::json out = toJson(compareImages(in.test, in.reference, mask, in.exposureEv));
    const bool wholeKnown = !in.referenceVariance.empty();
    out["reference_noise"] = noiseJson(relativeNoise(in.reference, in.referenceVariance, mask));
    out["relative_rmse_corrected"] =
        noiseCorrectedRelativeRmse(in.test, in.reference, in.referenceVariance, mask);
    if (!hasPixels(in.testDirect) || !hasPixels(in.referenceDirect)) return out;

    const std::vector<float> testIndirect = differenceRgb(in.test, in.testDirect);
    const std::vector<float> referenceIndirect = differenceRgb(in.reference, in.referenceDirect);
    const ImageView ti(testIndirect, in.test.width, in.test.height, 3);
    const ImageView ri(referenceIndirect, in.reference.width, in.reference.height, 3);
    std::vector<float> indirectVariance;
    const bool directKnown = !in.referenceDirectVariance.empty();
    if (wholeKnown && directKnown) {
        checkVariance(in.referenceDirectVariance, in.referenceDirect);
        indirectVariance.resize(in.referenceVariance.size());
        for (std::size_t i = 0; i < indirectVariance.size(); ++i)
            indirectVariance[i] = in.referenceVariance[i] + in.referenceDirectVariance[i];
    }
    const NoiseSums s = noiseSums(&ti, ri, indirectVariance, mask);
    const double measured = relativeRmse(ti, ri, mask);
    nlohmann::json indirect;
    indirect["relative_rmse"] = measured;
    indirect["relative_rmse_corrected"] = indirectVariance.empty() ? measured : corrected(s, true);
    indirect["rmse"] = rmse(ti, ri, mask);
    indirect["reference_noise"] = noiseJson(relativeNoise(ri, indirectVariance, mask));
    indirect["mean_ratio"] = s.referenceSum > 0 ? s.testSum / s.referenceSum : 0.0;
    indirect["pixels"] = std::count_if(mask.begin(), mask.end(), [](std::uint8_t m) { return m != 0; });
    out["indirect"] = std::move(indirect);

    nlohmann::json direct = toJson(compareImages(in.testDirect, in.referenceDirect, mask, in.exposureEv));
    direct["reference_noise"] =
        noiseJson(relativeNoise(in.referenceDirect, in.referenceDirectVariance, mask));
    out["direct"] = std::move(direct);
    return out;
}

} // namespace gis
