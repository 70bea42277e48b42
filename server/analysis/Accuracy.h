// Accuracy of a GI frame against a noisy reference: the whole image, the indirect light alone and the
// direct pass alone, each with the reference's own noise beside the error and the error corrected for it.
//
// Definitions (sums over the included pixels p and the three colour channels c; t the test, r the
// reference, v the variance of the reference's pixel mean from ReferenceImage::variance):
//  - relativeNoise             = sqrt( sum v / sum r^2 ): the reference's noise relative to its RMS value,
//                                on the same footing as relativeRmse (Metrics.h).
//  - noiseCorrectedRelativeRmse = sqrt( max(0, sum (t - r)^2 - sum v) ) / sqrt( max(sum r^2 - sum v, 0) ).
//                                E[(t - r)^2] = (t - E r)^2 + v when the test does not depend on the
//                                reference's noise, so the corrected figure estimates the error against
//                                the converged image; 0 when the measured error is within the noise.
//  - indirect light: each side's total minus its own direct pass (the test's direct-light texture; the
//    reference's "direct" mode render of the same view). The reference indirect's variance is the sum of
//    both renders' variances (0 for a pixel-centre direct render, which is exact).
// Unknown variance (an EXR without it, one sample of a random estimator): the noise is reported as null
// and the corrected figure equals the measured one.
#pragma once

#include <span>
#include <vector>

#include <nlohmann/json.hpp>

#include "analysis/Metrics.h"

namespace gis {

/// Negative when `variance` is empty (unknown). Throws InputError for a variance of the wrong size.
double relativeNoise(const ImageView& reference, std::span<const float> variance, const PixelMask& mask = {});
/// relativeRmse when `variance` is empty.
double noiseCorrectedRelativeRmse(const ImageView& test, const ImageView& reference,
                                  std::span<const float> variance, const PixelMask& mask = {});

/// a - b per pixel as an interleaved RGB image (alpha dropped); values may be negative.
std::vector<float> differenceRgb(const ImageView& a, const ImageView& b);

struct AccuracyInputs {
    ImageView test;       ///< the frame's linear radiance
    ImageView testDirect; ///< its direct pass; no pixels = not available (no indirect or direct figures)
    ImageView reference;
    std::span<const float> referenceVariance;
    ImageView referenceDirect; ///< the reference's "direct" render of the same view; no pixels = none
    std::span<const float> referenceDirectVariance;
    double exposureEv = 0;
};

/// compareImages()'s keys for the whole image (pixels black in the reference left out) plus
/// "reference_noise" (null when unknown) and "relative_rmse_corrected"; with both direct images also
///   "indirect": {"relative_rmse", "relative_rmse_corrected", "rmse", "reference_noise", "mean_ratio"
///                (mean test indirect over mean reference indirect), "pixels"},
///   "direct":   compareImages()'s keys for the direct passes, with "reference_noise".
nlohmann::json compareAccuracy(const AccuracyInputs& inputs);

} // namespace gis
