// Definitions are in Metrics.h; this file adds the LDR-FLIP pipeline's constants and the choices the paper
// leaves open. FLIP is written from the paper's description (Andersson et al., HPG 2020), not from any code.
#include "analysis/Metrics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "core/Error.h"

namespace gis {
namespace {

// ---- Display transform (shaders/render/composite.frag) ----
// Narkowicz's fit reaches 1 at x ~ 7.24; clamping the argument far above that keeps x * x finite for any
// exposure without changing a result.
constexpr double kFilmicArgumentLimit = 64.0;

// ---- SSIM (Wang et al. 2004) ----
constexpr int kSsimRadius = 5; // 11x11 window
constexpr double kSsimSigma = 1.5;
constexpr double kSsimC1 = (0.01 * 1.0) * (0.01 * 1.0); // (K1 L)^2
constexpr double kSsimC2 = (0.03 * 1.0) * (0.03 * 1.0); // (K2 L)^2

// ---- LDR-FLIP (Andersson et al. 2020) ----
// Viewing conditions of the paper's default set-up.
constexpr double kFlipDistanceM = 0.7;
constexpr double kFlipMonitorWidthM = 0.7;
constexpr int kFlipMonitorPixels = 3840;
// Spatial contrast sensitivity per opponent channel as a sum of two Gaussians in the spatial domain:
// S(x) = a1 sqrt(pi / b1) exp(-pi^2 x^2 / b1) + a2 sqrt(pi / b2) exp(-pi^2 x^2 / b2), x in degrees.
struct CsfTerms {
    double a1, b1, a2, b2;
};
constexpr std::array<CsfTerms, 3> kFlipCsf = {{
    {1.0, 0.0047, 0.0, 1e-5},  // achromatic (Yy)
    {1.0, 0.0053, 0.0, 1e-5},  // red-green (Cx)
    {34.1, 0.04, 13.5, 0.025}, // blue-yellow (Cz)
}};
// All three CSF filters share one radius: three standard deviations of the widest Gaussian (b = 0.04).
constexpr double kFlipCsfWidestB = 0.04;
constexpr double kFlipQc = 0.7;                // colour-difference exponent
constexpr double kFlipPc = 0.4;                // re-mapping knee, as a fraction of cmax
constexpr double kFlipPt = 0.95;               // error value at the knee
constexpr double kFlipQf = 0.5;                // feature-difference exponent
constexpr double kFlipFeatureWidthDeg = 0.082; // w: sigma = 0.5 w ppd for the feature filters
constexpr double kFlipHuntFactor = 0.01;       // a*_h = 0.01 L* a*, b*_h = 0.01 L* b*

// ---- Colour spaces: sRGB primaries, D65 white ----
using Mat3 = std::array<std::array<double, 3>, 3>;
constexpr Mat3 kLinearRgbToXyz = {{
    {0.4124564, 0.3575761, 0.1804375},
    {0.2126729, 0.7151522, 0.0721750},
    {0.0193339, 0.1191920, 0.9503041},
}};

constexpr Mat3 invert(const Mat3& m) {
    const double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
    const double c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
    const double c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
    const double invDet = 1.0 / (m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02);
    return {{
        {c00 * invDet, (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * invDet,
         (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * invDet},
        {c01 * invDet, (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * invDet,
         (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * invDet},
        {c02 * invDet, (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * invDet,
         (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * invDet},
    }};
}
// Computed from the forward matrix rather than typed in, so RGB -> XYZ -> RGB round-trips to rounding error.
constexpr Mat3 kXyzToLinearRgb = invert(kLinearRgbToXyz);
// Reference white = XYZ of linear RGB (1, 1, 1), so white maps to exactly L* = 100, a* = b* = 0.
constexpr std::array<double, 3> kWhite = {
    kLinearRgbToXyz[0][0] + kLinearRgbToXyz[0][1] + kLinearRgbToXyz[0][2],
    kLinearRgbToXyz[1][0] + kLinearRgbToXyz[1][1] + kLinearRgbToXyz[1][2],
    kLinearRgbToXyz[2][0] + kLinearRgbToXyz[2][1] + kLinearRgbToXyz[2][2],
};

using Vec3 = std::array<double, 3>;

Vec3 mul(const Mat3& m, const Vec3& v) {
    return {m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
            m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
            m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2]};
}

double clamp01(double v) {
    return std::clamp(v, 0.0, 1.0);
}

double srgbEncode(double c) {
    c = clamp01(c);
    return c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
}

double srgbDecode(double c) {
    c = clamp01(c);
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

double filmic(double x) {
    x = std::clamp(x, 0.0, kFilmicArgumentLimit);
    return clamp01(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)); // denominator >= 0.14
}

// CIELAB's companding function; the linear segment below (6/29)^3 keeps it defined at 0.
double labF(double t) {
    constexpr double kDelta = 6.0 / 29.0;
    return t > kDelta * kDelta * kDelta ? std::cbrt(t) : t / (3.0 * kDelta * kDelta) + 4.0 / 29.0;
}

// Linear RGB -> CIELAB -> Hunt-adjusted (L*, 0.01 L* a*, 0.01 L* b*).
Vec3 huntLab(const Vec3& rgb) {
    const Vec3 xyz = mul(kLinearRgbToXyz, rgb);
    const double fx = labF(xyz[0] / kWhite[0]);
    const double fy = labF(xyz[1] / kWhite[1]);
    const double fz = labF(xyz[2] / kWhite[2]);
    const double l = 116.0 * fy - 16.0;
    return {l, kFlipHuntFactor * l * 500.0 * (fx - fy), kFlipHuntFactor * l * 200.0 * (fy - fz)};
}

// HyAB (Abasi et al. 2020): city-block in lightness, Euclidean in chroma.
double hyab(const Vec3& p, const Vec3& q) {
    const double da = p[1] - q[1];
    const double db = p[2] - q[2];
    return std::abs(p[0] - q[0]) + std::sqrt(da * da + db * db);
}

std::string sizeText(int w, int h) {
    return std::to_string(w) + "x" + std::to_string(h);
}

// ---- Validation ----

void checkShape(int width, int height, const char* where) {
    if (width <= 0 || height <= 0)
        throw InputError(where, "image size must be positive, got " + sizeText(width, height));
}

void checkImage(const ImageView& image, const char* where) {
    checkShape(image.width, image.height, where);
    if (image.channels != 3 && image.channels != 4)
        throw InputError(where, "channels must be 3 or 4, got " + std::to_string(image.channels));
    const std::size_t expected =
        std::size_t(image.width) * std::size_t(image.height) * std::size_t(image.channels);
    if (image.pixels.data() == nullptr) throw InputError(where, "no pixel data");
    if (image.pixels.size() != expected)
        throw InputError(where, "buffer holds " + std::to_string(image.pixels.size()) + " floats, " +
                                    sizeText(image.width, image.height) + "x" +
                                    std::to_string(image.channels) + " needs " + std::to_string(expected));
    // A NaN or Inf would poison every mean; the renderer never writes one, so one here is a bug upstream.
    const std::size_t pixels = std::size_t(image.width) * std::size_t(image.height);
    for (std::size_t p = 0; p < pixels; ++p) {
        for (int c = 0; c < 3; ++c) {
            if (!std::isfinite(image.pixels[p * std::size_t(image.channels) + std::size_t(c)]))
                throw InputError(where, "pixel (" + std::to_string(p % std::size_t(image.width)) + ", " +
                                            std::to_string(p / std::size_t(image.width)) + ") channel " +
                                            std::to_string(c) + " is not finite");
        }
    }
}

// Returns the number of included pixels.
std::size_t checkMask(const PixelMask& mask, int width, int height) {
    const std::size_t pixels = std::size_t(width) * std::size_t(height);
    if (mask.empty()) return pixels;
    if (mask.size() != pixels)
        throw InputError("mask", "has " + std::to_string(mask.size()) + " entries, " +
                                     sizeText(width, height) + " needs " + std::to_string(pixels));
    const auto included =
        std::size_t(std::count_if(mask.begin(), mask.end(), [](std::uint8_t m) { return m != 0; }));
    if (included == 0) throw InputError("mask", "selects no pixel");
    return included;
}

std::size_t checkPair(const ImageView& test, const ImageView& reference, const PixelMask& mask) {
    checkImage(test, "test");
    checkImage(reference, "reference");
    if (test.width != reference.width || test.height != reference.height)
        throw InputError("test", "size mismatch: test is " + sizeText(test.width, test.height) +
                                     ", reference is " + sizeText(reference.width, reference.height));
    return checkMask(mask, test.width, test.height);
}

void checkExposure(double exposureEv) {
    if (!std::isfinite(exposureEv)) throw InputError("exposure", "must be a finite EV value");
}

bool included(const PixelMask& mask, std::size_t p) {
    return mask.empty() || mask[p] != 0;
}

// ---- Pixel statistics shared by RMSE, relative RMSE, PSNR and max error ----

struct DiffStats {
    double sumSquaredError = 0;
    double sumSquaredReference = 0;
    double maxAbsError = 0;
    double peak = -std::numeric_limits<double>::infinity();
    std::size_t pixels = 0;
};

DiffStats diffStats(const ImageView& test, const ImageView& reference, const PixelMask& mask) {
    DiffStats s;
    s.pixels = checkPair(test, reference, mask);
    const std::size_t count = std::size_t(test.width) * std::size_t(test.height);
    const auto tc = std::size_t(test.channels);
    const auto rc = std::size_t(reference.channels);
    for (std::size_t p = 0; p < count; ++p) {
        if (!included(mask, p)) continue;
        for (std::size_t c = 0; c < 3; ++c) {
            const double t = test.pixels[p * tc + c];
            const double r = reference.pixels[p * rc + c];
            const double d = t - r;
            s.sumSquaredError += d * d;
            s.sumSquaredReference += r * r;
            s.maxAbsError = std::max(s.maxAbsError, std::abs(d));
            s.peak = std::max(s.peak, r);
        }
    }
    return s;
}

double rmseOf(const DiffStats& s) {
    return std::sqrt(s.sumSquaredError / (3.0 * double(s.pixels)));
}

double relativeRmseOf(const DiffStats& s) {
    if (s.sumSquaredError == 0) return 0;
    if (s.sumSquaredReference == 0) return kRelativeRmseUndefined;
    // The ratio of sums equals the ratio of means; both are finite doubles of float data.
    return std::min(std::sqrt(s.sumSquaredError / s.sumSquaredReference), kRelativeRmseUndefined);
}

double psnrOf(const DiffStats& s) {
    if (s.sumSquaredError == 0) return kPsnrLimitDb;
    if (!(s.peak > 0)) return -kPsnrLimitDb;
    const double value = 20.0 * std::log10(s.peak / rmseOf(s));
    return std::clamp(value, -kPsnrLimitDb, kPsnrLimitDb);
}

// ---- Separable filtering with edge replication ----

using Kernel = std::vector<double>; // odd length 2r + 1, centred

// Correlation along rows: out(x) = sum_i k[i] src(clamp(x + i - r)).
std::vector<double> filterRows(const std::vector<double>& src, int width, int height, const Kernel& k) {
    const int r = int(k.size() / 2);
    std::vector<double> out(src.size());
    std::vector<double> padded(std::size_t(width + 2 * r));
    for (int y = 0; y < height; ++y) {
        const double* row = src.data() + std::size_t(y) * std::size_t(width);
        for (int x = -r; x < width + r; ++x) padded[std::size_t(x + r)] = row[std::clamp(x, 0, width - 1)];
        double* dst = out.data() + std::size_t(y) * std::size_t(width);
        for (int x = 0; x < width; ++x) {
            double sum = 0;
            for (std::size_t i = 0; i < k.size(); ++i) sum += k[i] * padded[std::size_t(x) + i];
            dst[x] = sum;
        }
    }
    return out;
}

// Correlation along columns, row by row so the inner loop runs over contiguous memory.
std::vector<double> filterColumns(const std::vector<double>& src, int width, int height, const Kernel& k) {
    const int r = int(k.size() / 2);
    std::vector<double> out(src.size(), 0.0);
    for (int y = 0; y < height; ++y) {
        double* dst = out.data() + std::size_t(y) * std::size_t(width);
        for (int i = -r; i <= r; ++i) {
            const double w = k[std::size_t(i + r)];
            const double* row =
                src.data() + std::size_t(std::clamp(y + i, 0, height - 1)) * std::size_t(width);
            for (int x = 0; x < width; ++x) dst[x] += w * row[x];
        }
    }
    return out;
}

std::vector<double> filterSeparable(const std::vector<double>& src, int width, int height, const Kernel& kx,
                                    const Kernel& ky) {
    return filterColumns(filterRows(src, width, height, kx), width, height, ky);
}

Kernel gaussianKernel(int radius, double sigma) {
    Kernel k(std::size_t(2 * radius + 1));
    double sum = 0;
    for (int i = -radius; i <= radius; ++i) {
        k[std::size_t(i + radius)] = std::exp(-double(i * i) / (2.0 * sigma * sigma));
        sum += k[std::size_t(i + radius)];
    }
    for (double& v : k) v /= sum; // sum >= 1 (the centre tap)
    return k;
}

// ---- SSIM core ----

double ssimCore(const std::vector<double>& t, const std::vector<double>& r, int width, int height,
                const PixelMask& mask, std::size_t includedPixels) {
    const Kernel g = gaussianKernel(kSsimRadius, kSsimSigma);
    const std::size_t n = t.size();
    std::vector<double> tt(n), rr(n), tr(n);
    for (std::size_t i = 0; i < n; ++i) {
        tt[i] = t[i] * t[i];
        rr[i] = r[i] * r[i];
        tr[i] = t[i] * r[i];
    }
    const auto muT = filterSeparable(t, width, height, g, g);
    const auto muR = filterSeparable(r, width, height, g, g);
    const auto eTT = filterSeparable(tt, width, height, g, g);
    const auto eRR = filterSeparable(rr, width, height, g, g);
    const auto eTR = filterSeparable(tr, width, height, g, g);
    double sum = 0;
    for (std::size_t i = 0; i < n; ++i) {
        if (!included(mask, i)) continue;
        const double varT = std::max(0.0, eTT[i] - muT[i] * muT[i]); // rounding can dip below 0
        const double varR = std::max(0.0, eRR[i] - muR[i] * muR[i]);
        const double cov = eTR[i] - muT[i] * muR[i];
        // Both denominator factors are >= C1 resp. C2 > 0.
        sum += ((2 * muT[i] * muR[i] + kSsimC1) * (2 * cov + kSsimC2)) /
               ((muT[i] * muT[i] + muR[i] * muR[i] + kSsimC1) * (varT + varR + kSsimC2));
    }
    return sum / double(includedPixels);
}

std::vector<double> lumaOf(const std::vector<float>& srgb) {
    std::vector<double> luma(srgb.size() / 3);
    for (std::size_t p = 0; p < luma.size(); ++p)
        luma[p] = 0.2126 * srgb[3 * p] + 0.7152 * srgb[3 * p + 1] + 0.0722 * srgb[3 * p + 2];
    return luma;
}

// ---- LDR-FLIP ----

struct FlipKernels {
    // CSF: per channel, up to two separable Gaussian terms with their share of the normalised 2D filter.
    struct Term {
        Kernel g;
        double weight;
    };
    std::array<std::vector<Term>, 3> csf;
    Kernel featureGauss, edge, point;
};

FlipKernels makeFlipKernels(double ppd) {
    FlipKernels k;
    const double pi2 = std::numbers::pi * std::numbers::pi;
    const int csfRadius = int(std::ceil(3.0 * std::sqrt(kFlipCsfWidestB / (2.0 * pi2)) * ppd));
    for (std::size_t ch = 0; ch < 3; ++ch) {
        const CsfTerms& c = kFlipCsf[ch];
        double total = 0;
        for (const auto& [a, b] : {std::pair{c.a1, c.b1}, std::pair{c.a2, c.b2}}) {
            if (a == 0) continue;
            // Each term a sqrt(pi/b) exp(-pi^2 (x^2 + y^2) / b) factors into g(x) g(y); its 2D sum is
            // a sqrt(pi/b) (sum g)^2, which normalises the whole filter to unit sum.
            Kernel g(std::size_t(2 * csfRadius + 1));
            double gSum = 0;
            for (int i = -csfRadius; i <= csfRadius; ++i) {
                const double xDeg = double(i) / ppd;
                g[std::size_t(i + csfRadius)] = std::exp(-pi2 * xDeg * xDeg / b);
                gSum += g[std::size_t(i + csfRadius)];
            }
            const double amplitude = a * std::sqrt(std::numbers::pi / b);
            for (double& v : g) v /= gSum;
            k.csf[ch].push_back({std::move(g), amplitude * gSum * gSum});
            total += amplitude * gSum * gSum;
        }
        for (auto& term : k.csf[ch]) term.weight /= total; // total > 0: every channel has a1 > 0
    }

    const double sigma = 0.5 * kFlipFeatureWidthDeg * ppd;
    const int radius = int(std::ceil(3.0 * sigma));
    k.featureGauss = gaussianKernel(radius, sigma);
    // Edge: first derivative of the Gaussian (sign irrelevant, only magnitudes are used), scaled so its
    // positive taps sum to 1 and its negative taps to -1. Point: second derivative, positive and negative
    // parts scaled separately the same way, so a flat region gives exactly zero response.
    k.edge.resize(std::size_t(2 * radius + 1));
    k.point.resize(std::size_t(2 * radius + 1));
    double edgePos = 0, pointPos = 0, pointNeg = 0;
    for (int i = -radius; i <= radius; ++i) {
        const double x = double(i);
        const double g = std::exp(-x * x / (2.0 * sigma * sigma));
        const double e = -x / (sigma * sigma) * g;
        const double p = (x * x / (sigma * sigma) - 1.0) / (sigma * sigma) * g;
        k.edge[std::size_t(i + radius)] = e;
        k.point[std::size_t(i + radius)] = p;
        if (e > 0) edgePos += e;
        if (p > 0) pointPos += p;
        if (p < 0) pointNeg -= p;
    }
    // radius >= 1 for any ppd > 0, so each part has at least one tap; the guards only protect degenerate ppd.
    for (double& v : k.edge) v = edgePos > 0 ? v / edgePos : 0.0;
    for (double& v : k.point)
        v = v > 0 ? (pointPos > 0 ? v / pointPos : 0.0) : (pointNeg > 0 ? v / pointNeg : 0.0);
    return k;
}

// Per image: the CSF-filtered Hunt-adjusted L*a*b* and the feature magnitudes.
struct FlipPrepared {
    std::vector<Vec3> lab;
    std::vector<double> edge, point;
};

FlipPrepared prepareFlip(std::span<const float> srgb, int width, int height, const FlipKernels& k) {
    const std::size_t n = std::size_t(width) * std::size_t(height);
    std::array<std::vector<double>, 3> opponent;
    for (auto& plane : opponent) plane.resize(n);
    std::vector<double> achromatic(n);
    for (std::size_t p = 0; p < n; ++p) {
        const Vec3 rgb = {srgbDecode(srgb[3 * p]), srgbDecode(srgb[3 * p + 1]), srgbDecode(srgb[3 * p + 2])};
        const Vec3 xyz = mul(kLinearRgbToXyz, rgb);
        const double yr = xyz[1] / kWhite[1];
        // YyCxCz: CIELAB without the cube root (Kolpatzik & Bouman), linear so it can be filtered.
        opponent[0][p] = 116.0 * yr - 16.0;
        opponent[1][p] = 500.0 * (xyz[0] / kWhite[0] - yr);
        opponent[2][p] = 200.0 * (yr - xyz[2] / kWhite[2]);
        achromatic[p] = yr; // (Yy + 16) / 116, the achromatic channel normalised to [0, 1]
    }

    std::array<std::vector<double>, 3> filtered;
    for (std::size_t ch = 0; ch < 3; ++ch) {
        filtered[ch].assign(n, 0.0);
        for (const auto& term : k.csf[ch]) {
            const auto part = filterSeparable(opponent[ch], width, height, term.g, term.g);
            for (std::size_t p = 0; p < n; ++p) filtered[ch][p] += term.weight * part[p];
        }
    }

    FlipPrepared out;
    out.lab.resize(n);
    for (std::size_t p = 0; p < n; ++p) {
        const double yr = (filtered[0][p] + 16.0) / 116.0;
        const Vec3 xyz = {(filtered[1][p] / 500.0 + yr) * kWhite[0], yr * kWhite[1],
                          (yr - filtered[2][p] / 200.0) * kWhite[2]};
        Vec3 rgb = mul(kXyzToLinearRgb, xyz);
        // Filtering can leave the gamut; the paper clamps to [0, 1] in linear RGB before L*a*b*.
        for (double& c : rgb) c = clamp01(c);
        out.lab[p] = huntLab(rgb);
    }

    const auto rowsGauss = filterRows(achromatic, width, height, k.featureGauss);
    const auto rowsEdge = filterRows(achromatic, width, height, k.edge);
    const auto rowsPoint = filterRows(achromatic, width, height, k.point);
    const auto edgeX = filterColumns(rowsEdge, width, height, k.featureGauss);
    const auto edgeY = filterColumns(rowsGauss, width, height, k.edge);
    const auto pointX = filterColumns(rowsPoint, width, height, k.featureGauss);
    const auto pointY = filterColumns(rowsGauss, width, height, k.point);
    out.edge.resize(n);
    out.point.resize(n);
    for (std::size_t p = 0; p < n; ++p) {
        out.edge[p] = std::hypot(edgeX[p], edgeY[p]);
        out.point[p] = std::hypot(pointX[p], pointY[p]);
    }
    return out;
}

// cmax: the largest colour difference FLIP expects, that between pure green and pure blue.
double flipCmax() {
    return std::pow(hyab(huntLab({0.0, 1.0, 0.0}), huntLab({0.0, 0.0, 1.0})), kFlipQc);
}

double flipPixel(const FlipPrepared& t, const FlipPrepared& r, std::size_t p, double cmax) {
    const double colour = std::pow(hyab(t.lab[p], r.lab[p]), kFlipQc); // hyab >= 0
    const double knee = kFlipPc * cmax;
    // Piecewise-linear re-mapping: [0, pc cmax] -> [0, pt], [pc cmax, cmax] -> [pt, 1]. Differences above
    // cmax (possible after filtering) are clamped to 1.
    const double deltaC =
        clamp01(colour < knee ? kFlipPt * colour / knee
                              : kFlipPt + (colour - knee) / (cmax - knee) * (1.0 - kFlipPt));
    const double feature = std::max(std::abs(t.edge[p] - r.edge[p]), std::abs(t.point[p] - r.point[p]));
    const double deltaF = clamp01(std::pow(clamp01(feature / std::numbers::sqrt2), kFlipQf));
    return clamp01(std::pow(deltaC, 1.0 - deltaF)); // 0^0 = 1 by std::pow's definition: no NaN
}

double flipCore(std::span<const float> testSrgb, std::span<const float> referenceSrgb, int width, int height,
                const PixelMask& mask, std::size_t includedPixels, std::vector<float>* errorMap, double ppd) {
    if (!std::isfinite(ppd) || ppd <= 0)
        throw InputError("pixels_per_degree", "must be positive and finite, got " + std::to_string(ppd));
    const FlipKernels kernels = makeFlipKernels(ppd);
    const FlipPrepared t = prepareFlip(testSrgb, width, height, kernels);
    const FlipPrepared r = prepareFlip(referenceSrgb, width, height, kernels);
    const double cmax = flipCmax();
    const std::size_t n = std::size_t(width) * std::size_t(height);
    if (errorMap) errorMap->assign(n, 0.0f);
    double sum = 0;
    for (std::size_t p = 0; p < n; ++p) {
        if (!included(mask, p)) continue;
        const double e = flipPixel(t, r, p, cmax);
        sum += e;
        if (errorMap) (*errorMap)[p] = float(e);
    }
    return sum / double(includedPixels);
}

void checkSpan(std::span<const float> data, std::size_t expected, const char* where) {
    if (data.size() != expected)
        throw InputError(where, "buffer holds " + std::to_string(data.size()) + " floats, needs " +
                                    std::to_string(expected));
    for (float v : data)
        if (!std::isfinite(v)) throw InputError(where, "holds a non-finite value");
}

std::vector<float> toneMapUnchecked(const ImageView& linear, double exposureEv) {
    const double scale = std::exp2(exposureEv); // may be 0 or Inf for extreme EV; filmic() clamps its input
    const std::size_t n = std::size_t(linear.width) * std::size_t(linear.height);
    const auto channels = std::size_t(linear.channels);
    std::vector<float> out(3 * n);
    for (std::size_t p = 0; p < n; ++p) {
        for (std::size_t c = 0; c < 3; ++c) {
            const double v = linear.pixels[p * channels + c];
            // Negative radiance is clamped first (as the composite pass does), so 0 * Inf never happens.
            out[3 * p + c] = float(srgbEncode(filmic(v > 0 ? v * scale : 0.0)));
        }
    }
    return out;
}

} // namespace

ImageView::ImageView(const float* data, int w, int h, int c) : width(w), height(h), channels(c) {
    if (data && w > 0 && h > 0 && c > 0) pixels = {data, std::size_t(w) * std::size_t(h) * std::size_t(c)};
}

double rmse(const ImageView& test, const ImageView& reference, const PixelMask& mask) {
    return rmseOf(diffStats(test, reference, mask));
}

double relativeRmse(const ImageView& test, const ImageView& reference, const PixelMask& mask) {
    return relativeRmseOf(diffStats(test, reference, mask));
}

double psnr(const ImageView& test, const ImageView& reference, const PixelMask& mask) {
    return psnrOf(diffStats(test, reference, mask));
}

double maxAbsError(const ImageView& test, const ImageView& reference, const PixelMask& mask) {
    return diffStats(test, reference, mask).maxAbsError;
}

std::vector<float> toneMapForMetrics(const ImageView& linear, double exposureEv) {
    checkImage(linear, "image");
    checkExposure(exposureEv);
    return toneMapUnchecked(linear, exposureEv);
}

std::vector<std::uint8_t> toneMapToRgba8(const ImageView& linear, double exposureEv) {
    const std::vector<float> srgb = toneMapForMetrics(linear, exposureEv);
    std::vector<std::uint8_t> rgba8(srgb.size() / 3 * 4, 255);
    for (std::size_t i = 0, n = srgb.size() / 3; i < n; ++i)
        for (int c = 0; c < 3; ++c)
            rgba8[i * 4 + c] =
                static_cast<std::uint8_t>(std::lround(std::clamp(srgb[i * 3 + c], 0.0f, 1.0f) * 255.0f));
    return rgba8;
}

double ssim(const ImageView& test, const ImageView& reference, const PixelMask& mask, double exposureEv) {
    const std::size_t pixels = checkPair(test, reference, mask);
    checkExposure(exposureEv);
    return ssimCore(lumaOf(toneMapUnchecked(test, exposureEv)),
                    lumaOf(toneMapUnchecked(reference, exposureEv)), test.width, test.height, mask, pixels);
}

double ssimGray(std::span<const float> test, std::span<const float> reference, int width, int height,
                const PixelMask& mask) {
    checkShape(width, height, "test");
    const std::size_t n = std::size_t(width) * std::size_t(height);
    checkSpan(test, n, "test");
    checkSpan(reference, n, "reference");
    const std::size_t pixels = checkMask(mask, width, height);
    return ssimCore(std::vector<double>(test.begin(), test.end()),
                    std::vector<double>(reference.begin(), reference.end()), width, height, mask, pixels);
}

double pixelsPerDegree(double distanceM, double monitorWidthM, int monitorWidthPixels) {
    if (!(distanceM > 0) || !(monitorWidthM > 0) || monitorWidthPixels <= 0 || !std::isfinite(distanceM) ||
        !std::isfinite(monitorWidthM))
        throw InputError("viewing", "distance, monitor width and pixel count must be positive");
    return distanceM * (double(monitorWidthPixels) / monitorWidthM) * std::numbers::pi / 180.0;
}

double defaultPixelsPerDegree() {
    return pixelsPerDegree(kFlipDistanceM, kFlipMonitorWidthM, kFlipMonitorPixels);
}

double flip(const ImageView& test, const ImageView& reference, const PixelMask& mask, double exposureEv,
            std::vector<float>* errorMap, double pixelsPerDegreeValue) {
    const std::size_t pixels = checkPair(test, reference, mask);
    checkExposure(exposureEv);
    return flipCore(toneMapUnchecked(test, exposureEv), toneMapUnchecked(reference, exposureEv), test.width,
                    test.height, mask, pixels, errorMap, pixelsPerDegreeValue);
}

double flipSrgb(std::span<const float> testSrgb, std::span<const float> referenceSrgb, int width, int height,
                const PixelMask& mask, std::vector<float>* errorMap, double pixelsPerDegreeValue) {
    checkShape(width, height, "test");
    const std::size_t n = std::size_t(width) * std::size_t(height);
    checkSpan(testSrgb, 3 * n, "test");
    checkSpan(referenceSrgb, 3 * n, "reference");
    const std::size_t pixels = checkMask(mask, width, height);
    return flipCore(testSrgb, referenceSrgb, width, height, mask, pixels, errorMap, pixelsPerDegreeValue);
}

ImageMetrics compareImages(const ImageView& test, const ImageView& reference, const PixelMask& mask,
                           double exposureEv) {
    checkExposure(exposureEv);
    const DiffStats s = diffStats(test, reference, mask);
    ImageMetrics m;
    m.rmse = rmseOf(s);
    m.relativeRmse = relativeRmseOf(s);
    m.psnr = psnrOf(s);
    m.maxAbsError = s.maxAbsError;
    m.pixels = s.pixels;
    const auto testSrgb = toneMapUnchecked(test, exposureEv);
    const auto referenceSrgb = toneMapUnchecked(reference, exposureEv);
    m.ssim = ssimCore(lumaOf(testSrgb), lumaOf(referenceSrgb), test.width, test.height, mask, s.pixels);
    m.flip = flipCore(testSrgb, referenceSrgb, test.width, test.height, mask, s.pixels, nullptr,
                      defaultPixelsPerDegree());
    return m;
}

ImageMetrics compareImages(const float* test, const float* reference, int width, int height, int channels,
                           const PixelMask& mask, double exposureEv) {
    return compareImages(ImageView(test, width, height, channels),
                         ImageView(reference, width, height, channels), mask, exposureEv);
}

nlohmann::json toJson(const ImageMetrics& m) {
    return {{"rmse", m.rmse},    {"relative_rmse", m.relativeRmse},
            {"psnr_db", m.psnr}, {"max_abs_error", m.maxAbsError},
            {"ssim", m.ssim},    {"flip", m.flip},
            {"pixels", m.pixels}};
}

PixelMask coverageMask(const float* rgba, int width, int height) {
    const ImageView image(rgba, width, height, 4);
    checkShape(width, height, "image");
    if (image.pixels.empty()) throw InputError("image", "no pixel data");
    PixelMask mask(std::size_t(width) * std::size_t(height));
    for (std::size_t p = 0; p < mask.size(); ++p) mask[p] = image.pixels[4 * p + 3] > 0.5f ? 1 : 0;
    return mask;
}

PixelMask maskFromNonZero(const ImageView& reference) {
    checkImage(reference, "reference");
    PixelMask mask(std::size_t(reference.width) * std::size_t(reference.height));
    const auto channels = std::size_t(reference.channels);
    for (std::size_t p = 0; p < mask.size(); ++p) {
        const float* px = reference.pixels.data() + p * channels;
        mask[p] = (px[0] != 0.0f || px[1] != 0.0f || px[2] != 0.0f) ? 1 : 0;
    }
    return mask;
}

PixelMask maskFromNonZero(const float* reference, int width, int height, int channels) {
    return maskFromNonZero(ImageView(reference, width, height, channels));
}

} // namespace gis
