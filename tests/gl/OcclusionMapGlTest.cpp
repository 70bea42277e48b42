// glTF occlusion maps: they darken the indirect light (not the direct) by the map, where no pass
// computes indirect shadows; with vpl_shadows (or second_order's negative lights) they are left out.
#include <cstdio>

#include <gtest/gtest.h>

#include "GlTestSupport.h"
#include "scene/SceneLoader.h"

using namespace gis;

namespace {

constexpr int kSide = 48;

/// The empty Cornell room whose floor has its own material; `occlusion`: an occlusion map of 64/255
/// (red; the other channels, which glTF leaves to other maps, at 255) over the whole floor.
Scene room(bool occlusion) {
    Scene s = loadScene("builtin:cornell-empty");
    for (Mesh& m : s.meshes)
        if (m.name == "floor") m.material = static_cast<int>(s.materials.size());
    Material floor{.name = "floor", .baseColor = glm::vec4(0.725f, 0.71f, 0.68f, 1.0f)};
    if (occlusion) {
        TextureImage t{.width = 2, .height = 2, .name = "ao", .srgb = false};
        t.rgba = {64, 255, 255, 255, 64, 255, 255, 255, 64, 255, 255, 255, 64, 255, 255, 255};
        floor.occlusionTexture = static_cast<int>(s.textures.size());
        s.textures.push_back(t);
    }
    s.materials.push_back(floor);
    return s;
}

FrameOutput render(const Scene& scene, bool vplShadows) {
    return test::renderScene(scene, "rsm_gather", kSide, kSide,
                             {{"vpl_grid", 8}, {"vpl_shadows", vplShadows}}, {}, true);
}

} // namespace

TEST(OcclusionMap, DarkensTheIndirectLightByTheMap) {
    const FrameOutput plain = render(room(false), false);
    const FrameOutput mapped = render(room(true), false);
    EXPECT_EQ(mapped.stats["counts"]["occlusion_maps_applied"].get<double>(), 1.0);
    EXPECT_EQ(plain.stats["counts"]["occlusion_maps_applied"].get<double>(), 0.0);
    ASSERT_EQ(mapped.linearDirect, plain.linearDirect) << "the direct light is not occluded";
    int quarter = 0, whole = 0, other = 0;
    for (size_t i = 0; i < plain.linear.size(); i += 4) {
        const double before = plain.linear[i + 1] - plain.linearDirect[i + 1];
        const double after = mapped.linear[i + 1] - mapped.linearDirect[i + 1];
        ASSERT_TRUE(std::isfinite(after) && after >= -1e-6) << i;
        if (!(before > 1e-4)) continue;
        const double ratio = after / before;
        if (std::abs(ratio - 64.0 / 255.0) < 0.01)
            ++quarter;
        else if (std::abs(ratio - 1.0) < 1e-4)
            ++whole;
        else
            ++other;
        EXPECT_LE(ratio, 1.0 + 1e-4);
        EXPECT_GE(ratio, 64.0 / 255.0 - 0.01);
    }
    std::printf("indirect scaled by the map's 0.251: %d pixels, by 1: %d, between: %d\n", quarter, whole,
                other);
    EXPECT_GT(quarter, 100);
    EXPECT_GT(whole, 500); // the walls and the ceiling
    EXPECT_EQ(other, 0);
}

TEST(OcclusionMap, LeftOutWhereTheTechniqueComputesIndirectShadows) {
    const FrameOutput plain = render(room(false), true);
    const FrameOutput mapped = render(room(true), true);
    EXPECT_EQ(mapped.stats["counts"]["occlusion_maps_applied"].get<double>(), 0.0);
    EXPECT_EQ(mapped.linear, plain.linear) << "vpl_shadows computes the occlusion: the map is not applied";
}
