// Levels of detail (scene/MeshLod.h, render/SceneGpu.h LodView): with lod_pixels the camera draws big
// meshes simplified where their error spans at most that many pixels, and with light_lod_texels the
// light views where it spans at most that many texels of their maps. The frame must draw far fewer triangles,
// stay close to the full-detail frame, choose finer levels for bigger images, and tiles of a frame
// must choose what the whole frame chooses. GIS_LOD_IMAGES=DIR writes the frames compared.
#include <cstdio>
#include <cstdlib>

#include "GlTestSupport.h"
#include "frame/FrameState.h"
#include "frame/Tiles.h"

namespace gis::test {
namespace {

FrameState atriumState(const Scene& scene, const std::string& technique, int w, int h, double lodPixels,
                       double lightLodTexels = 0.0) {
    FrameState s = makeFrameState(scene, technique);
    s.width = w;
    s.height = h;
    setParam(s, "lod_pixels", lodPixels, "test");
    setParam(s, "light_lod_texels", lightLodTexels, "test");
    return s;
}

/// Mean |a - b| over the RGB channels of two 8-bit images, in 8-bit units.
double meanDifference(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
    double sum = 0.0;
    const std::size_t pixels = a.size() / 4;
    for (std::size_t i = 0; i < pixels; ++i)
        for (int c = 0; c < 3; ++c)
            sum += std::abs(static_cast<int>(a[i * 4 + c]) - static_cast<int>(b[i * 4 + c]));
    return sum / static_cast<double>(pixels * 3);
}

class LodGl : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        sharedContext();
        scene = std::make_shared<const Scene>(loadScene("builtin:atrium-150k"));
        renderer = std::make_unique<FrameRenderer>();
        renderer->setScene(scene);
    }
    static void TearDownTestSuite() {
        renderer.reset();
        scene.reset();
    }
    static inline std::shared_ptr<const Scene> scene;
    static inline std::unique_ptr<FrameRenderer> renderer;
};

TEST_F(LodGl, SimplifiedMeshesDrawFewerTrianglesAndChangeTheImageLittle) {
    const FrameOutput full = renderer->render(atriumState(*scene, "multires_gather", 128, 96, 0.0), true);
    const FrameOutput lod = renderer->render(atriumState(*scene, "multires_gather", 128, 96, 1.0), true);
    EXPECT_GT(counter(lod, "triangles_lod_stored"), 0.0) << "the atrium's columns get levels";
    EXPECT_EQ(counter(full, "triangles_gbuffer_simplified"), 0.0) << "lod_pixels 0 draws every triangle";
    const double drawnFull = counter(full, "triangles_gbuffer"), drawnLod = counter(lod, "triangles_gbuffer");
    const double error = relativeRmseOf(lod, full);
    std::printf("[lod] atrium-150k 128x96: %.0f triangles at full detail, %.0f at 1 px (%.0f simplified); "
                "relative RMSE against full detail %.4f, mean |diff| %.2f / 255\n",
                drawnFull, drawnLod, counter(lod, "triangles_gbuffer_simplified"), error,
                meanDifference(lod.rgba8, full.rgba8));
    if (const char* dir = std::getenv("GIS_LOD_IMAGES")) {
        writePng(std::string(dir) + "/lod_full.png", full.width, full.height, full.rgba8);
        writePng(std::string(dir) + "/lod_1px.png", lod.width, lod.height, lod.rgba8);
    }
    EXPECT_GT(counter(lod, "triangles_gbuffer_simplified"), 0.0);
    EXPECT_LT(drawnLod, 0.5 * drawnFull);
    // Measured 0.087 and 2.3 / 255: the differences lie on the columns and the fountain.
    EXPECT_LT(error, 0.15);
    EXPECT_LT(meanDifference(lod.rgba8, full.rgba8), 4.0);
    EXPECT_EQ(badValues(lod), 0u);

    // The tolerance is in the image's pixels: a bigger image keeps more of each mesh.
    const FrameOutput big = renderer->render(atriumState(*scene, "multires_gather", 512, 384, 1.0), true);
    std::printf("[lod] atrium-150k 512x384 at 1 px: %.0f triangles drawn\n",
                counter(big, "triangles_gbuffer"));
    EXPECT_GT(counter(big, "triangles_gbuffer"), drawnLod);
    EXPECT_LE(counter(big, "triangles_gbuffer"), drawnFull);
}

TEST_F(LodGl, TheSunsViewDrawsSimplifiedMeshesWithinATexel) {
    // The atrium's sun is orthographic: one texel is the same size everywhere in its maps.
    const FrameOutput full = renderer->render(atriumState(*scene, "multires_gather", 96, 72, 0.0, 0.0), true);
    const FrameOutput lod = renderer->render(atriumState(*scene, "multires_gather", 96, 72, 0.0, 1.0), true);
    std::printf("[lod] atrium-150k light views: %.0f triangles at full detail, %.0f at 1 texel (%.0f "
                "simplified)\n",
                counter(full, "triangles_light_views"), counter(lod, "triangles_light_views"),
                counter(lod, "triangles_light_views_simplified"));
    EXPECT_EQ(counter(full, "triangles_light_views_simplified"), 0.0);
    EXPECT_GT(counter(lod, "triangles_light_views_simplified"), 0.0);
    EXPECT_LT(counter(lod, "triangles_light_views"), 0.5 * counter(full, "triangles_light_views"));
    EXPECT_EQ(counter(lod, "triangles_gbuffer_simplified"), 0.0) << "the camera's tolerance is lod_pixels";
    const double error = relativeRmseOf(lod, full);
    std::printf(
        "[lod] atrium-150k 96x72 with simplified light views: relative RMSE against full detail %.4f\n",
        error);
    EXPECT_LT(error, 0.1);
    // ... and the light views' is light_lod_texels alone.
    const FrameOutput eyeOnly = renderer->render(atriumState(*scene, "multires_gather", 96, 72, 8.0, 0.0));
    EXPECT_EQ(counter(eyeOnly, "triangles_light_views"), counter(full, "triangles_light_views"));
    EXPECT_EQ(counter(eyeOnly, "triangles_light_views_simplified"), 0.0);
}

TEST_F(LodGl, FullDetailLightViewsServeASimplifiedFrameButNotTheReverse) {
    // A renderer keeps the light views while the lights stay: kept at full detail they serve a frame
    // that tolerates a texel, but simplified ones must not serve a frame that asks for every triangle
    // (an API render after a live view's light drag).
    FrameRenderer own;
    own.setReuseLightPasses(true);
    own.setScene(scene);
    own.setSceneLevels(SceneGpu::prepareLevels(*scene));
    const auto reused = [](const FrameOutput& f) { return counter(f, "light_views_reused") > 0.0; };
    const FrameOutput dragged = own.render(atriumState(*scene, "multires_gather", 64, 48, 1.0, 1.0));
    EXPECT_FALSE(reused(dragged));
    EXPECT_GT(counter(dragged, "triangles_light_views_simplified"), 0.0);
    const FrameOutput refined = own.render(atriumState(*scene, "multires_gather", 64, 48, 0.0));
    EXPECT_FALSE(reused(refined)) << "simplified maps must not serve a frame that draws every triangle";
    EXPECT_EQ(counter(refined, "triangles_light_views_simplified"), 0.0);
    const FrameOutput orbit = own.render(atriumState(*scene, "multires_gather", 64, 48, 1.0, 1.0));
    EXPECT_TRUE(reused(orbit)) << "full-detail maps serve a simplified frame";
    const FrameOutput again = own.render(atriumState(*scene, "multires_gather", 64, 48, 0.0));
    EXPECT_TRUE(reused(again));
}

TEST(LodGlDense, TheBumpySphereStaysCloseToFullDetail) {
    // cornell-dense's displaced sphere (65k triangles) in a small frame: lit head-on by the spot, so a
    // simplified surface that sank into the full one would shadow itself.
    for (const char* technique : {"none", "multires_gather"}) {
        const nlohmann::json lod0 = {{"lod_pixels", 0.0}},
                             lod1 = {{"lod_pixels", 1.0}, {"light_lod_texels", 1.0}};
        const FrameOutput full = renderScene("builtin:cornell-dense", technique, 96, 96, lod0);
        const FrameOutput lod = renderScene("builtin:cornell-dense", technique, 96, 96, lod1);
        const double error = relativeRmseOf(lod, full);
        std::printf("[lod] cornell-dense 96x96 %s: %.0f -> %.0f triangles, relative RMSE %.4f, mean |diff| "
                    "%.2f / 255\n",
                    technique, counter(full, "triangles_gbuffer"), counter(lod, "triangles_gbuffer"), error,
                    meanDifference(lod.rgba8, full.rgba8));
        if (const char* dir = std::getenv("GIS_LOD_IMAGES")) {
            writePng(std::string(dir) + "/dense_full.png", full.width, full.height, full.rgba8);
            writePng(std::string(dir) + "/dense_1px.png", lod.width, lod.height, lod.rgba8);
        }
        EXPECT_LT(counter(lod, "triangles_gbuffer"), 0.5 * counter(full, "triangles_gbuffer")) << technique;
        // The spot's perspective views simplify too where their texels are big enough: the 256^2 RSM
        // here; the 1024^2 shadow map alone (technique none) keeps the sphere whole.
        if (std::string(technique) != "none") {
            EXPECT_GT(counter(lod, "triangles_light_views_simplified"), 0.0) << technique;
        }
        // Its bumps are smaller than a pixel here, so the full-detail frame aliases them and the
        // simplified one is smoother: a large relative RMSE (measured 0.29-0.36) from scattered pixels,
        // a small mean difference (1.8 / 255 without indirect light; 3.5 / 255 with it, its VPLs drawn
        // from the simplified RSM: against the converged reference the indirect light's error is
        // 0.372 against 0.369 with a full-detail RSM, docs/interactive.md "Level of detail").
        EXPECT_LT(error, 0.5) << technique;
        EXPECT_LT(meanDifference(lod.rgba8, full.rgba8), 5.0) << technique;
        EXPECT_EQ(badValues(lod), 0u) << technique;
    }
}

TEST_F(LodGl, ASessionsRendererWaitsForTheLevelsItIsHanded) {
    // The service builds the levels on a thread of its own: until it hands them in, frames draw every
    // triangle rather than building them on the render thread.
    FrameRenderer own;
    own.setLevelsOnDemand(false);
    own.setScene(scene);
    const FrameState state = atriumState(*scene, "none", 96, 72, 1.0);
    const FrameOutput before = own.render(state);
    EXPECT_FALSE(own.sceneHasLevels());
    EXPECT_EQ(counter(before, "triangles_gbuffer_simplified"), 0.0);
    own.setSceneLevels(SceneGpu::prepareLevels(*scene));
    ASSERT_TRUE(own.sceneHasLevels());
    const FrameOutput after = own.render(state);
    EXPECT_GT(counter(after, "triangles_gbuffer_simplified"), 0.0);
    EXPECT_LT(counter(after, "triangles_gbuffer"), 0.5 * counter(before, "triangles_gbuffer"));
}

TEST(LodGlCorpus, ABlenderExportInMillimetresDrawsItsLevels) {
    // Blender's monkey subdivided twice (15,746 triangles), 2,700 units across, no lights, Draco
    // (tests/data/corpus/generate.py, compress.sh): the tolerance is in pixels, whatever the units.
    const std::string path = std::string(GIS_SOURCE_DIR) + "/tests/data/corpus/dense_monkey_draco.glb";
    const FrameOutput full = renderScene(path, "multires_gather", 160, 120, {{"lod_pixels", 0.0}});
    const FrameOutput lod = renderScene(path, "multires_gather", 160, 120, {{"lod_pixels", 1.0}});
    const double error = relativeRmseOf(lod, full);
    std::printf("[lod] dense_monkey_draco 160x120: %.0f -> %.0f triangles, relative RMSE %.4f, mean |diff| "
                "%.2f / 255\n",
                counter(full, "triangles_gbuffer"), counter(lod, "triangles_gbuffer"), error,
                meanDifference(lod.rgba8, full.rgba8));
    EXPECT_LT(counter(lod, "triangles_gbuffer"), 0.5 * counter(full, "triangles_gbuffer"));
    EXPECT_LT(error, 0.05);
    EXPECT_EQ(badValues(lod), 0u);

    // Its light views (the default rig a file without lights gets: a key spot and a directional fill)
    // within a texel as well.
    const FrameOutput lit =
        renderScene(path, "multires_gather", 160, 120, {{"lod_pixels", 1.0}, {"light_lod_texels", 1.0}});
    const double litError = relativeRmseOf(lit, full);
    std::printf(
        "[lod] dense_monkey_draco 160x120, light views too: %.0f -> %.0f light-view triangles, relative "
        "RMSE %.4f, mean |diff| %.2f / 255\n",
        counter(full, "triangles_light_views"), counter(lit, "triangles_light_views"), litError,
        meanDifference(lit.rgba8, full.rgba8));
    if (const char* dir = std::getenv("GIS_LOD_IMAGES")) {
        writePng(std::string(dir) + "/monkey_full.png", full.width, full.height, full.rgba8);
        writePng(std::string(dir) + "/monkey_lit.png", lit.width, lit.height, lit.rgba8);
    }
    EXPECT_GT(counter(lit, "triangles_light_views_simplified"), 0.0);
    EXPECT_LT(counter(lit, "triangles_light_views"), counter(full, "triangles_light_views"));
    EXPECT_LT(litError, 0.05);
    EXPECT_EQ(badValues(lit), 0u);
}

TEST_F(LodGl, TilesChooseTheLevelsOfTheWholeImage) {
    // rsm_gather is per pixel: tiled and whole frames agree to rounding when they draw the same levels.
    const FrameState whole = atriumState(*scene, "rsm_gather", 160, 128, 2.0);
    const FrameOutput image = renderer->render(whole);
    std::vector<std::uint8_t> canvas(image.rgba8.size(), 0);
    TilePlan plan(whole.width, whole.height);
    double simplified = 0.0;
    while (!plan.done()) {
        const TileRect rect = plan.next(64.0 * 64.0);
        const FrameOutput tile = renderer->render(tileState(whole, rect, 0));
        simplified += counter(tile, "triangles_gbuffer_simplified");
        pasteTile(canvas, whole.width, whole.height, tile.rgba8, tile.width, tile.height, rect, 0);
    }
    EXPECT_GT(simplified, 0.0);
    EXPECT_LT(meanDifference(canvas, image.rgba8), 0.05);
}

} // namespace
} // namespace gis::test
