// How a RayScene is built: the fast build the effect planner uses hits what the high-quality build
// hits, and a build can be cancelled before and during Embree's commit.
#include <atomic>
#include <cmath>

#include <gtest/gtest.h>

#include "reference/RayScene.h"
#include "scene/SceneLoader.h"

namespace gis::reference {
namespace {

TEST(RaySceneBuild, FastBuildHitsWhatTheHighQualityBuildHits) {
    const Scene scene = loadScene("builtin:cornell-dense");
    const RayScene high(scene);
    const RayScene fast(scene, {.fastBuild = true});
    EXPECT_EQ(high.epsilon(), fast.epsilon());
    const glm::vec3 centre = scene.bounds.center();
    const float radius = scene.bounds.radius();
    int hits = 0;
    // Rays from points round the box through its middle, fanned out: a deterministic spread.
    for (int i = 0; i < 400; ++i) {
        const float a = 0.7f * static_cast<float>(i), b = 0.3f * static_cast<float>(i % 17);
        const glm::vec3 origin =
            centre + 0.4f * radius * glm::vec3(std::cos(a), 0.5f * std::sin(b), std::sin(a));
        const glm::vec3 dir = glm::normalize(glm::vec3(std::sin(1.3f * a), std::cos(b), std::cos(0.9f * a)));
        SurfaceHit h1, h2;
        const bool hit1 = high.intersect(origin, dir, 1e-3f, 1e30f, h1);
        const bool hit2 = fast.intersect(origin, dir, 1e-3f, 1e30f, h2);
        ASSERT_EQ(hit1, hit2) << "ray " << i;
        if (!hit1) continue;
        ++hits;
        EXPECT_NEAR(glm::length(h1.position - h2.position), 0.0f, 1e-5f * radius) << "ray " << i;
        EXPECT_EQ(high.occluded(origin, dir, 1e-3f, 1e30f), fast.occluded(origin, dir, 1e-3f, 1e30f))
            << "ray " << i;
    }
    EXPECT_GT(hits, 300) << "inside the box nearly every ray hits";
}

TEST(RaySceneBuild, ACancelledBuildThrowsBuildCancelled) {
    const Scene scene = loadScene("builtin:cornell-dense");
    // Before anything is built.
    EXPECT_THROW(RayScene(scene, {.fastBuild = true, .cancelled = [] { return true; }}), BuildCancelled);
    // During Embree's commit: its progress monitor asks, from its own threads.
    std::atomic<int> asked{0};
    RaySceneOptions duringCommit;
    duringCommit.cancelled = [&] { return asked.fetch_add(1) >= 1 + static_cast<int>(scene.meshes.size()); };
    EXPECT_THROW(RayScene(scene, duringCommit), BuildCancelled);
    EXPECT_GT(asked.load(), static_cast<int>(scene.meshes.size()) + 1) << "asked again once the commit began";
    // A cancel that never comes changes nothing.
    EXPECT_NO_THROW(RayScene(scene, {.cancelled = [] { return false; }}));
}

} // namespace
} // namespace gis::reference
