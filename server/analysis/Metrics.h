// Image error metrics for the accuracy report: a rendered image (test) against a ground truth (reference).
//
// Inputs are linear-radiance RGB images: float, interleaved, `channels` 3 or 4 (alpha is ignored), rows
// top-down, test and reference of the same width and height. An optional mask (one byte per pixel, non-zero
// = include the pixel, empty = every pixel) lets callers leave out background. N below is the number of
// included pixels; sums run over included pixels p and the three colour channels c.
//
// Exact definitions (the report quotes these):
//  - rmse          = sqrt( sum_{p,c} (t - r)^2 / (3N) ).
//  - relativeRmse  = rmse / sqrt( sum_{p,c} r^2 / (3N) ): the error relative to the reference's RMS value.
//                    Paper 001 (Nichols et al., "Hierarchical Image-Space Radiosity", EGSR 2009) reports
//                    "RMS error" in percent without giving its normalisation; we report
//                    percent = 100 * relativeRmse. Zero reference: 0 when the test is zero too, otherwise
//                    kRelativeRmseUndefined (the largest finite double), never Inf or NaN.
//  - psnr          = 20 log10(peak / rmse) dB on linear radiance, peak = the largest reference value over
//                    included pixels and the three channels (an HDR image has no fixed peak, so the
//                    reference's own maximum stands in). rmse = 0 gives +kPsnrLimitDb (999, "identical");
//                    peak = 0 with rmse > 0 gives -kPsnrLimitDb; results are clamped to +-kPsnrLimitDb.
//  - maxAbsError   = max_{p,c} |t - r|.
//  - ssim          = SSIM (Wang, Bovik, Sheikh, Simoncelli, IEEE TIP 13(4), 2004) on the tone-mapped luma
//                    below: 11x11 Gaussian window with sigma 1.5 (weights normalised to 1), K1 = 0.01,
//                    K2 = 0.03, L = 1, so C1 = (K1 L)^2 and C2 = (K2 L)^2;
//                    SSIM(p) = (2 mu_t mu_r + C1)(2 s_tr + C2) / ((mu_t^2 + mu_r^2 + C1)(s_t^2 + s_r^2 +
//                    C2)), averaged over included pixels. At the border the window is kept whole and the
//                    image is extended by clamping coordinates (edge replication), so every pixel has a value
//                    even in images smaller than the window. The window statistics see every pixel (the mask
//                    only selects which SSIM values are averaged).
//  - flip          = mean over included pixels of LDR-FLIP (Andersson, Nilsson, Akenine-Moller, Oskarsson,
//                    Astrom, Fairchild, "FLIP: A Difference Evaluator for Alternating Images", HPG 2020) on
//                    the tone-mapped sRGB images below; the pipeline and every constant are in Metrics.cpp
//                    and in README.md. As with SSIM, the filters see every pixel and the mask selects the
//                    average.
//
// Tone mapping for SSIM and FLIP is the renderer's display transform (shaders/render/composite.frag):
// negative radiance clamped to 0, exposure 2^EV, the ACES filmic fit by Narkowicz (2015) x (2.51 x + 0.03) /
// (x (2.43 x + 0.59) + 0.14) clamped to [0, 1], then the sRGB encoding (IEC 61966-2-1). SSIM's luma = 0.2126
// R' + 0.7152 G' + 0.0722 B' of the sRGB-encoded values in [0, 1].
//
// Errors: bad shapes (sizes <= 0, channels not 3 or 4, a buffer or mask of the wrong size, test and reference
// of different sizes), a mask that selects no pixel, a non-finite exposure and non-finite pixel values throw
// gis::InputError. Every returned number is finite.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <nlohmann/json.hpp>

namespace gis {

/// What psnr() returns for identical images (and the clamp for every PSNR): a finite stand-in for +Inf.
inline constexpr double kPsnrLimitDb = 999.0;
/// What relativeRmse() returns when the reference is zero everywhere but the test is not.
inline constexpr double kRelativeRmseUndefined = std::numeric_limits<double>::max();

/// A read-only view of an interleaved float image; `pixels` must hold width * height * channels values.
struct ImageView {
    std::span<const float> pixels;
    int width = 0;
    int height = 0;
    int channels = 3;

    ImageView() = default;
    ImageView(std::span<const float> data, int w, int h, int c)
        : pixels(data), width(w), height(h), channels(c) {}
    /// For a raw buffer the size is taken on trust from width * height * channels.
    ImageView(const float* data, int w, int h, int c);
};

/// One byte per pixel, row-major like the images; non-zero includes the pixel. Empty = every pixel.
using PixelMask = std::vector<std::uint8_t>;

double rmse(const ImageView& test, const ImageView& reference, const PixelMask& mask = {});
double relativeRmse(const ImageView& test, const ImageView& reference, const PixelMask& mask = {});
double psnr(const ImageView& test, const ImageView& reference, const PixelMask& mask = {});
double maxAbsError(const ImageView& test, const ImageView& reference, const PixelMask& mask = {});
double ssim(const ImageView& test, const ImageView& reference, const PixelMask& mask = {},
            double exposureEv = 0);

/// SSIM of two single-channel images already in [0, 1] (the core of ssim(); exposed for tests and callers
/// that have display-referred data).
double ssimGray(std::span<const float> test, std::span<const float> reference, int width, int height,
                const PixelMask& mask = {});

/// Pixels per degree of visual angle for an observer `distanceM` from a monitor `monitorWidthM` wide with
/// `monitorWidthPixels` columns (FLIP paper, section 3): distance * (pixels / width) * pi / 180.
double pixelsPerDegree(double distanceM, double monitorWidthM, int monitorWidthPixels);
/// FLIP's default viewing conditions: 0.7 m from a 0.7 m wide 3840-pixel monitor, about 67.02.
double defaultPixelsPerDegree();

/// Mean LDR-FLIP over included pixels between two linear-radiance images after the display transform.
/// When `errorMap` is given it receives width * height per-pixel values in [0, 1] (0 at excluded pixels).
double flip(const ImageView& test, const ImageView& reference, const PixelMask& mask = {},
            double exposureEv = 0, std::vector<float>* errorMap = nullptr,
            double pixelsPerDegreeValue = defaultPixelsPerDegree());

/// LDR-FLIP of two display-referred images: 3-channel interleaved sRGB-encoded values (clamped to [0, 1]).
double flipSrgb(std::span<const float> testSrgb, std::span<const float> referenceSrgb, int width, int height,
                const PixelMask& mask = {}, std::vector<float>* errorMap = nullptr,
                double pixelsPerDegreeValue = defaultPixelsPerDegree());

/// The display transform above: returns width * height * 3 sRGB-encoded values in [0, 1].
std::vector<float> toneMapForMetrics(const ImageView& linear, double exposureEv = 0);
/// The same as RGBA8 (alpha 255), rows as in `linear`: how a reference is shown and written (gi-render
/// --reference's .png/.jpg, the HTTP API's reference_base64).
std::vector<std::uint8_t> toneMapToRgba8(const ImageView& linear, double exposureEv = 0);

struct ImageMetrics {
    double rmse = 0;
    double relativeRmse = 0;
    double psnr = 0; ///< dB
    double maxAbsError = 0;
    double ssim = 0;
    double flip = 0;
    std::size_t pixels = 0; ///< included pixels
};

/// Every metric at once (the tone-mapped images are computed once and shared by SSIM and FLIP).
ImageMetrics compareImages(const ImageView& test, const ImageView& reference, const PixelMask& mask = {},
                           double exposureEv = 0);
ImageMetrics compareImages(const float* test, const float* reference, int width, int height, int channels,
                           const PixelMask& mask = {}, double exposureEv = 0);

/// {"rmse", "relative_rmse", "psnr_db", "max_abs_error", "ssim", "flip", "pixels"}.
nlohmann::json toJson(const ImageMetrics& metrics);

/// 1 where alpha > 0.5, for 4-channel images whose alpha marks geometry coverage. Note: the renderer's
/// linear output writes alpha 1 everywhere, so for its images use maskFromNonZero() instead.
PixelMask coverageMask(const float* rgba, int width, int height);
/// 1 where the reference pixel is not exactly 0 in all three colour channels (alpha ignored): leaves out
/// background that the reference renders as black.
PixelMask maskFromNonZero(const float* reference, int width, int height, int channels);
PixelMask maskFromNonZero(const ImageView& reference);

} // namespace gis
