#include <gtest/gtest.h>

#include <set>

#include <glm/glm.hpp>

#include "frame/LightModel.h"
#include "frame/Tiles.h"
#include "scene/SceneLoader.h"

namespace gis {
namespace {

FrameState cornellState(const std::string& technique, int w, int h) {
    static const Scene scene = loadScene("builtin:cornell");
    FrameState s = makeFrameState(scene, technique);
    s.width = w;
    s.height = h;
    return s;
}

// A world point lands on the same full-image pixel through the tile's cropped projection.
TEST(Tiles, CroppedProjectionMapsPointsToTheSamePixels) {
    const FrameState full = cornellState("rsm_gather", 200, 120);
    const TileRect rect{64, 32, 48, 48};
    const FrameState tile = tileState(full, rect, 8);
    EXPECT_EQ(tile.width, 64);
    EXPECT_EQ(tile.height, 64);
    const glm::mat4 a = frameViewProj(full), b = frameViewProj(tile);
    for (glm::vec3 p :
         {glm::vec3(0.1f, 1.0f, 0.2f), glm::vec3(-0.4f, 0.6f, -0.5f), glm::vec3(0.3f, 1.5f, 0.0f)}) {
        const glm::vec4 ca = a * glm::vec4(p, 1.0f), cb = b * glm::vec4(p, 1.0f);
        // Pixel coordinates, rows from the top.
        const double ax = (ca.x / ca.w * 0.5 + 0.5) * full.width,
                     ay = (0.5 - ca.y / ca.w * 0.5) * full.height;
        const double bx = (cb.x / cb.w * 0.5 + 0.5) * tile.width + tile.window.x;
        const double by = (0.5 - cb.y / cb.w * 0.5) * tile.height + tile.window.y;
        EXPECT_NEAR(ax, bx, 1e-3);
        EXPECT_NEAR(ay, by, 1e-3);
        EXPECT_NEAR(ca.z / ca.w, cb.z / cb.w, 1e-6); // depth unchanged
    }
}

TEST(Tiles, PlanCoversEveryPixelWhateverTheRequests) {
    for (double pixels : {500.0, 4096.0, 30000.0, 1e7}) {
        TilePlan plan(203, 157);
        std::vector<int> hits(203 * 157, 0);
        int guardAgainstLoops = 0;
        double request = pixels;
        while (!plan.done() && ++guardAgainstLoops < 100000) {
            const TileRect r = plan.next(request);
            EXPECT_GE(r.width, 1);
            EXPECT_GE(r.height, 1);
            for (int y = r.y; y < std::min(r.y + r.height, 157); ++y)
                for (int x = r.x; x < std::min(r.x + r.width, 203); ++x) ++hits[y * 203 + x];
            request = request * 1.9 > 1e7 ? pixels : request * 1.9; // sizes that keep changing
        }
        int twice = 0;
        for (int h : hits) {
            ASSERT_GE(h, 1) << "request " << pixels;
            if (h > 1) ++twice;
        }
        // Sizes that change every tile are the worst case; measured: at most a quarter twice.
        EXPECT_LE(twice, 203 * 157 / 4) << "request " << pixels;
        EXPECT_DOUBLE_EQ(plan.shareDone(), 1.0);
    }
}

TEST(Tiles, PlanKeepsTheTileSizeWhileRequestsStayClose) {
    TilePlan plan(1024, 1024);
    std::set<std::pair<int, int>> sizes;
    while (!plan.done()) {
        const TileRect r = plan.next(sizes.size() % 2 ? 4096.0 : 5000.0);
        sizes.insert({r.width, r.height});
    }
    EXPECT_EQ(sizes.size(), 1u); // one size: the renderer's targets are allocated once
}

TEST(Tiles, HierarchyTilesKeepThePatchSizeAndGetAGuard) {
    FrameState full = cornellState("multires_gather", 512, 512);
    full.techniqueParams.set("coarsest_size", 16); // 32 px patches
    EXPECT_EQ(tileGuardPx(full), 32);
    const FrameState tile = tileState(full, {0, 0, 64, 64}, 32);
    EXPECT_EQ(tile.techniqueParams.getInt("coarsest_size"), 4); // 128 px / 4 = 32 px patches
    EXPECT_EQ(tileGuardPx(cornellState("rsm_gather", 512, 512)), 0);
}

TEST(Tiles, PasteCopiesTheInnerPartInsideTheImage) {
    std::vector<std::uint8_t> canvas(10 * 6 * 4, 0);
    const int guard = 1;
    const TileRect rect{8, 4, 4, 4}; // reaches past the right and bottom edges
    std::vector<std::uint8_t> tile(6 * 6 * 4);
    for (int y = 0; y < 6; ++y)
        for (int x = 0; x < 6; ++x)
            for (int c = 0; c < 4; ++c) tile[(y * 6 + x) * 4 + c] = static_cast<std::uint8_t>(10 * y + x);
    pasteTile(canvas, 10, 6, tile, 6, 6, rect, guard);
    for (int y = 0; y < 6; ++y)
        for (int x = 0; x < 10; ++x) {
            const bool inside = x >= 8 && y >= 4;
            const int expected = inside ? 10 * (y - 4 + guard) + (x - 8 + guard) : 0;
            EXPECT_EQ(canvas[(y * 10 + x) * 4], expected) << x << "," << y;
        }
}

TEST(Tiles, ResizeKeepsFlatImagesFlat) {
    std::vector<std::uint8_t> src(3 * 2 * 4, 77);
    const auto out = resizeRgba8(src, 3, 2, 17, 9);
    ASSERT_EQ(out.size(), 17u * 9u * 4u);
    for (std::uint8_t v : out) EXPECT_EQ(v, 77);
    EXPECT_EQ(resizeRgba8({}, 0, 0, 4, 4), std::vector<std::uint8_t>(64, 0));
}

TEST(Tiles, RectanglesClipUniteAndCrop) {
    const TileRect clipped = clipToImage({8, 4, 4, 4}, 10, 6);
    EXPECT_EQ(clipped.x, 8);
    EXPECT_EQ(clipped.y, 4);
    EXPECT_EQ(clipped.width, 2);
    EXPECT_EQ(clipped.height, 2);
    const TileRect outside = clipToImage({12, 1, 4, 4}, 10, 6);
    EXPECT_EQ(outside.width * outside.height, 0);
    const TileRect u = unite({}, {2, 3, 4, 1});
    EXPECT_EQ(u.x, 2);
    EXPECT_EQ(u.width, 4);
    const TileRect both = unite(u, {0, 5, 1, 1});
    EXPECT_EQ(both.x, 0);
    EXPECT_EQ(both.y, 3);
    EXPECT_EQ(both.width, 6);
    EXPECT_EQ(both.height, 3);

    std::vector<std::uint8_t> canvas(10 * 6 * 4);
    for (int y = 0; y < 6; ++y)
        for (int x = 0; x < 10; ++x) canvas[(y * 10 + x) * 4] = static_cast<std::uint8_t>(10 * y + x);
    const auto crop = cropRgba8(canvas, 10, 6, {8, 4, 4, 4}); // clipped to 2 x 2
    ASSERT_EQ(crop.size(), 2u * 2u * 4u);
    EXPECT_EQ(crop[0], 48);
    EXPECT_EQ(crop[4], 49);
    EXPECT_EQ(crop[8], 58);
    EXPECT_EQ(crop[12], 59);
}

} // namespace
} // namespace gis
