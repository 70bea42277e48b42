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
