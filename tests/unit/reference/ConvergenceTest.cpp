// Monte Carlo behaviour: error falls as 1/sqrt(spp); images are independent of the thread count; the
// cache key follows the inputs.
#include <cmath>

#include <gtest/gtest.h>

#include "ReferenceTestScenes.h"
#include "reference/ReferenceRenderer.h"

using namespace gis;
using namespace gis::test;

namespace {
FrameState cornellState(const Scene& scene, int w, int h) {
    FrameState s = makeFrameState(scene, "rsm_gather");
    s.width = w;
    s.height = h;
    return s;
}
} // namespace

// An unbiased estimator's RMSE against the converged answer is sigma / sqrt(spp): slope -1/2 in log-log.
// The "converged" image here has 2048 spp, which adds sigma^2 / 2048 to each squared error (at 32 spp it
// flattens the slope by about 0.01).
TEST(ReferenceConvergence, ErrorFallsAsInverseSquareRootOfSamples) {
    const Scene scene = loadScene("builtin:cornell-empty");
    const FrameState state = cornellState(scene, 24, 24);
    ReferenceRenderer renderer(scene);
    const ReferenceImage truth = renderer.render(state, {.mode = "one-bounce", .spp = 2048, .seed = 777});
    std::vector<double> logSpp, logErr;
    for (int spp : {4, 8, 16, 32}) {
        const ReferenceImage img = renderer.render(state, {.mode = "one-bounce", .spp = spp, .seed = 5});
        EXPECT_EQ(img.spp, spp);
        const double err = rmse(img.rgb, truth.rgb);
        std::printf("spp %3d: RMSE %.5f\n", spp, err);
        logSpp.push_back(std::log(spp));
        logErr.push_back(std::log(err));
    }
    const double n = static_cast<double>(logSpp.size());
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (size_t i = 0; i < logSpp.size(); ++i) {
        sx += logSpp[i];
        sy += logErr[i];
        sxx += logSpp[i] * logSpp[i];
        sxy += logSpp[i] * logErr[i];
    }
    const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    std::printf("log-log slope %.3f (ideal -0.5)\n", slope);
    EXPECT_GE(slope, -0.7);
    EXPECT_LE(slope, -0.3);
}

TEST(ReferenceDeterminism, SameSeedSameImageForAnyThreadCount) {
    const Scene scene = loadScene("builtin:cornell");
    const FrameState state = cornellState(scene, 20, 20);
    ReferenceRenderer renderer(scene);
    for (const std::string& mode : referenceModes()) {
        ReferenceOptions o{.mode = mode, .spp = 6, .maxDepth = 6, .seed = 42, .jitter = true};
        o.threads = 1;
        const ReferenceImage a = renderer.render(state, o);
        o.threads = 2;
        const ReferenceImage b = renderer.render(state, o);
        o.threads = 3;
        const ReferenceImage c = renderer.render(state, o);
        EXPECT_EQ(a.rgb, b.rgb) << mode;
        EXPECT_EQ(a.rgb, c.rgb) << mode;
        EXPECT_EQ(a.key, c.key) << mode;
        if (mode != "direct") {
            o.seed = 43;
            EXPECT_NE(renderer.render(state, o).rgb, a.rgb) << mode << ": the seed must matter";
        }
    }
}

TEST(ReferenceDeterminism, ProgressiveSamplesAreTheSameSamples) {
    // Passes only regroup samples: a progress callback sees growing counts and the result equals a
    // render of the same count (the per-sample streams do not depend on the pass layout).
    const Scene scene = loadScene("builtin:cornell-empty");
    const FrameState state = cornellState(scene, 12, 12);
    ReferenceRenderer renderer(scene);
    std::vector<int> seen;
    const ReferenceImage a = renderer.render(state, {.mode = "path", .spp = 20, .seed = 3},
                                             [&](int spp, double) { seen.push_back(spp); });
    ASSERT_FALSE(seen.empty());
    EXPECT_EQ(seen.back(), 20);
    EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
    EXPECT_EQ(a.spp, 20);
}

TEST(ReferenceCacheKey, FollowsEveryInputButNotThreads) {
    const Scene scene = loadScene("builtin:cornell");
    const FrameState state = cornellState(scene, 32, 32);
    const ReferenceOptions o{.mode = "one-bounce", .spp = 16};
    const std::string key = referenceCacheKey(scene, state, o);
    EXPECT_EQ(key.size(), 32u);
    EXPECT_EQ(key, referenceCacheKey(scene, state, o));
    ReferenceOptions threads = o;
    threads.threads = 7;
    EXPECT_EQ(key, referenceCacheKey(scene, state, threads));

    FrameState moved = state;
    moved.camera.position.x += 0.01f;
    EXPECT_NE(key, referenceCacheKey(scene, moved, o));
    FrameState lit = state;
    lit.lights.at(0).light.intensity *= 2.0f;
    EXPECT_NE(key, referenceCacheKey(scene, lit, o));
    FrameState bigger = state;
    bigger.width = 64;
    EXPECT_NE(key, referenceCacheKey(scene, bigger, o));
    for (auto change :
         {+[](ReferenceOptions& r) { r.mode = "path"; }, +[](ReferenceOptions& r) { r.spp = 17; },
          +[](ReferenceOptions& r) { r.seed = 2; }, +[](ReferenceOptions& r) { r.maxDepth = 3; },
          +[](ReferenceOptions& r) { r.timeBudgetSeconds = 1; },
          +[](ReferenceOptions& r) { r.jitter = true; }}) {
        ReferenceOptions r = o;
        change(r);
        EXPECT_NE(key, referenceCacheKey(scene, state, r));
    }
    Scene recoloured = scene;
    recoloured.materials[0].baseColor.r *= 0.5f;
    EXPECT_NE(key, referenceCacheKey(recoloured, state, o));
    Scene moved2 = scene;
    moved2.meshes[0].positions[0].y += 1e-3f;
    EXPECT_NE(key, referenceCacheKey(moved2, state, o));
}

namespace {
// Sums over pixels and channels where the converged image is not black.
struct ErrorAgainstTruth {
    double squaredError = 0, reportedVariance = 0, truthVariance = 0, signal = 0;
};
ErrorAgainstTruth errorAgainst(const ReferenceImage& img, const ReferenceImage& truth) {
    ErrorAgainstTruth e;
    for (size_t i = 0; i < img.rgb.size(); ++i) {
        if (truth.rgb[i] == 0.0f) continue;
        const double d = img.rgb[i] - truth.rgb[i];
        e.squaredError += d * d;
        e.reportedVariance += img.variance[i];
        e.truthVariance += truth.variance[i];
        e.signal += double(truth.rgb[i]) * truth.rgb[i];
    }
    return e;
}
} // namespace

// The variance each render reports for its pixel means predicts its actual squared error against a
// converged render (whose own variance is subtracted), for every random mode.
TEST(ReferenceNoise, ReportedVariancePredictsTheError) {
    const Scene scene = loadScene("builtin:cornell");
    const FrameState state = cornellState(scene, 24, 24);
    ReferenceRenderer renderer(scene);
    for (const std::string mode : {"one-bounce-unoccluded", "one-bounce", "path"}) {
        const ReferenceImage truth = renderer.render(state, {.mode = mode, .spp = 2048, .seed = 99});
        ASSERT_EQ(truth.variance.size(), truth.rgb.size());
        for (int spp : {16, 64}) {
            const ReferenceImage img = renderer.render(state, {.mode = mode, .spp = spp, .seed = 3});
            ASSERT_EQ(img.variance.size(), img.rgb.size());
            const ErrorAgainstTruth e = errorAgainst(img, truth);
            const double ratio = (e.squaredError - e.truthVariance) / e.reportedVariance;
            std::printf(
                "%s %d spp: relative noise reported %.4f, measured error %.4f (ratio of squares %.3f)\n",
                mode.c_str(), spp, std::sqrt(e.reportedVariance / e.signal),
                std::sqrt(std::max(0.0, e.squaredError - e.truthVariance) / e.signal), ratio);
            // Rare bright paths make the sample variance itself noisy, most at few samples.
            EXPECT_GT(ratio, 0.6) << mode << " " << spp;
            EXPECT_LT(ratio, 1.6) << mode << " " << spp;
        }
    }
}

TEST(ReferenceNoise, DeterministicRenderIsExactAndOneRandomSampleIsUnknown) {
    const Scene scene = loadScene("builtin:cornell");
    const FrameState state = cornellState(scene, 12, 12);
    ReferenceRenderer renderer(scene);
    const ReferenceImage direct = renderer.render(state, {.mode = "direct", .spp = 16});
    EXPECT_EQ(direct.spp, 1);
    ASSERT_EQ(direct.variance.size(), direct.rgb.size());
    for (float v : direct.variance) EXPECT_EQ(v, 0.0f);
    EXPECT_TRUE(renderer.render(state, {.mode = "one-bounce", .spp = 1}).variance.empty());
}

// A noise target stops the render once the image's relative noise is below it: a tighter target takes
// more samples, and both stop short of the spp cap.
TEST(ReferenceNoise, NoiseTargetStopsWhenReached) {
    const Scene scene = loadScene("builtin:cornell");
    const FrameState state = cornellState(scene, 24, 24);
    ReferenceRenderer renderer(scene);
    auto noiseOf = [](const ReferenceImage& img, const std::vector<float>* direct) {
        double variance = 0, signal = 0;
        for (size_t i = 0; i < img.rgb.size(); ++i) {
            variance += img.variance[i];
            const double v = direct ? std::max(0.0, double(img.rgb[i]) - (*direct)[i]) : img.rgb[i];
            signal += v * v;
        }
        return std::sqrt(variance / signal);
    };
    ReferenceOptions loose{.mode = "one-bounce", .spp = 100000, .seed = 4};
    loose.noiseTarget = 0.05;
    ReferenceOptions tight = loose;
    tight.noiseTarget = 0.02;
    const ReferenceImage a = renderer.render(state, loose), b = renderer.render(state, tight);
    std::printf("noise target 0.05: %d spp (noise %.4f); 0.02: %d spp (noise %.4f)\n", a.spp,
                noiseOf(a, nullptr), b.spp, noiseOf(b, nullptr));
    EXPECT_GE(a.spp, 32);
    EXPECT_LT(b.spp, 100000);
    EXPECT_GT(b.spp, a.spp);
    EXPECT_LE(noiseOf(a, nullptr), 0.05);
    EXPECT_LE(noiseOf(b, nullptr), 0.02);
    // Against the indirect light alone the same target needs more samples.
    ReferenceOptions indirect = loose;
    indirect.noiseOfIndirect = true;
    const ReferenceImage c = renderer.render(state, indirect);
    const std::vector<float> direct = renderer.render(state, {.mode = "direct"}).rgb;
    std::printf("noise target 0.05 of the indirect light: %d spp (noise %.4f)\n", c.spp, noiseOf(c, &direct));
    EXPECT_GT(c.spp, a.spp);
    EXPECT_LE(noiseOf(c, &direct), 0.05);
    EXPECT_NE(referenceCacheKey(scene, state, loose), referenceCacheKey(scene, state, tight));
    EXPECT_NE(referenceCacheKey(scene, state, loose), referenceCacheKey(scene, state, indirect));
}
