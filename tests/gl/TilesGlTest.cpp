// Tiled refinement (frame/Tiles.h): a frame assembled from tiles must be the frame rendered whole, for
// every technique (exactly for per-pixel ones; the screen-space hierarchy and bias compensation within
// the bounds measured here), and reusing the light views across frames must change nothing.
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include "GlTestSupport.h"
#include "frame/FrameState.h"
#include "frame/Tiles.h"
#include "gi/Catalog.h"
#include "gi/common/EyeHierarchy.h"
#include "gi/common/VplGrid.h"
#include "gi/hier_isr/HierIsr.h"

namespace gis::test {
namespace {

struct Difference {
    double mean = 0;  ///< mean |a - b| over RGB, 8-bit units
    double over8 = 0; ///< fraction of pixels with a channel off by more than 8
};

Difference compare(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
    Difference d;
    const std::size_t pixels = a.size() / 4;
    std::size_t over = 0;
    for (std::size_t i = 0; i < pixels; ++i) {
        int worst = 0;
        for (int c = 0; c < 3; ++c) {
            const int e = std::abs(static_cast<int>(a[i * 4 + c]) - static_cast<int>(b[i * 4 + c]));
            d.mean += e;
            worst = std::max(worst, e);
        }
        if (worst > 8) ++over;
    }
    d.mean /= static_cast<double>(pixels * 3);
    d.over8 = static_cast<double>(over) / static_cast<double>(pixels);
    return d;
}

FrameState stateFor(const Scene& scene, const std::string& technique, int w, int h) {
    FrameState s = makeFrameState(scene, technique);
    s.width = w;
    s.height = h;
    return s;
}

// Tests that count a frame's checks make its storage in the frame: a background making asks the check
// once a millisecond until it is done (FrameRenderer::setBackgroundBytes).
constexpr double kNoBackground = 1e15;

// A frame of `state` rendered by a plain renderer (expected) and by one whose interrupt check never
// stops (checked, its checks counted), as refinement renders it.
struct CheckedFrame {
    FrameOutput expected, checked;
    int checks = 0;
    FrameRenderer counting;
    CheckedFrame(const std::shared_ptr<const Scene>& scene, const FrameState& state) {
        FrameRenderer plain;
        plain.setScene(scene);
        expected = plain.render(state);
        counting.setScene(scene);
        counting.setBackgroundBytes(kNoBackground);
        counting.setInterruptCheck([this] {
            ++checks;
            return false;
        });
        checked = counting.render(state);
    }
    // Stopped at the check two before the last (inside the gather's pieces), the frame returns
    // interrupted, and the next frame without a check is the whole one.
    void expectAStopKeepsNothing(const FrameState& state) {
        int asked = 0;
        const int stopAt = checks - 2;
        counting.setInterruptCheck([&] { return ++asked >= stopAt; });
        EXPECT_TRUE(counting.render(state).interrupted);
        counting.setInterruptCheck({});
        EXPECT_EQ(counting.render(state).rgba8, expected.rgba8);
    }
};

std::vector<std::uint8_t> renderTiled(FrameRenderer& renderer, const FrameState& full, double tilePixels) {
    std::vector<std::uint8_t> canvas(static_cast<std::size_t>(full.width) * full.height * 4, 0);
    const int guard = tileGuardPx(full);
    TilePlan plan(full.width, full.height);
    while (!plan.done()) {
        const TileRect rect = plan.next(tilePixels);
        const FrameOutput tile = renderer.render(tileState(full, rect, guard));
        pasteTile(canvas, full.width, full.height, tile.rgba8, tile.width, tile.height, rect, guard);
    }
    return canvas;
}

TEST(TilesGl, TiledFramesMatchWholeFramesForEveryTechnique) {
    sharedContext();
    const Scene scene = loadScene("builtin:cornell");
    FrameRenderer renderer;
    renderer.setScene(std::make_shared<const Scene>(scene));
    for (const TechniqueInfo& info : techniqueCatalog()) {
        FrameState full = stateFor(scene, info.name, 160, 128);
        const FrameOutput whole = renderer.render(full);
        const auto tiled = renderTiled(renderer, full, 48.0 * 48.0);
        const Difference d = compare(whole.rgba8, tiled);
        std::printf("[tiles] %-16s guard %2d px: mean |diff| %.3f / 255, pixels off by > 8: %.2f %%\n",
                    info.name.c_str(), tileGuardPx(full), d.mean, 100.0 * d.over8);
        // Per-pixel techniques: the same pixels up to float rounding in the cropped projection; the
        // screen-space hierarchy differs near tile seams (measured 0.4-0.5 / 255 mean, about 1 % of the
        // pixels off by more than 8), view-sampled lights more (second_order: 1.3 / 255, 3.1 %).
        const double meanBound = info.viewSampled ? 2.0 : tileGuardPx(full) > 0 ? 1.0 : 0.05;
        const double overBound = info.viewSampled ? 0.05 : tileGuardPx(full) > 0 ? 0.025 : 0.001;
        EXPECT_LE(d.mean, meanBound) << info.name;
        EXPECT_LE(d.over8, overBound) << info.name;
    }
}

// Two renderers of one scene, one reusing light views; the reusing one has rendered the state once.
struct ReusePair {
    explicit ReusePair(const std::string& name, const std::string& technique = "rsm_gather")
        : scene(std::make_shared<const Scene>(loadScene(name))) {
        fresh.setScene(scene);
        reusing.setScene(scene);
        reusing.setReuseLightPasses(true);
        reusing.setBackgroundBytes(kNoBackground);
        state = stateFor(*scene, technique, 96, 80);
        (void)reusing.render(state);
    }
    gl::Context& context = sharedContext(); // first: the renderers below need it
    std::shared_ptr<const Scene> scene;
    FrameRenderer fresh, reusing;
    FrameState state;
};

TEST(TilesGl, ReusedLightViewsRenderTheSameFrame) {
    ReusePair pair("builtin:cornell-point");
    FrameRenderer &fresh = pair.fresh, &reusing = pair.reusing;
    FrameState s = pair.state;
    s.camera.position += glm::vec3(0.3f, 0.0f, 0.0f); // the camera moves, the light does not
    const FrameOutput a = fresh.render(s), b = reusing.render(s);
    EXPECT_EQ(counter(b, "light_views_reused"), 6.0); // the point light's six faces
    EXPECT_EQ(counter(a, "light_views_reused"), 0.0);
    EXPECT_EQ(counter(b, "vpls_reused"), 1.0); // and the VPLs extracted from them
    EXPECT_EQ(counter(a, "vpls_reused"), 0.0);
    EXPECT_EQ(a.rgba8, b.rgba8);
    // A moved light renders its views again, and extracts its VPLs again.
    s.lights[0].light.position += glm::vec3(0.0f, -0.2f, 0.0f);
    const FrameOutput c = reusing.render(s), d = fresh.render(s);
    EXPECT_EQ(counter(c, "light_views_reused"), 0.0);
    EXPECT_EQ(counter(c, "vpls_reused"), 0.0);
    EXPECT_EQ(c.rgba8, d.rgba8);
}

// isr's and hier_isr's light tree depends on the RSMs alone: frames that reuse the light views (an
// orbit, the tiles of a refinement step) keep it instead of building it again.
TEST(TilesGl, ReusedLightViewsKeepTheLightTree) {
    for (const char* technique : {"hier_isr", "isr"}) {
        SCOPED_TRACE(technique);
        ReusePair pair("builtin:cornell-point", technique); // six views in one tree
        FrameRenderer &fresh = pair.fresh, &reusing = pair.reusing;
        FrameState s = pair.state;
        s.camera.position += glm::vec3(0.3f, 0.0f, 0.0f);
        const FrameOutput a = fresh.render(s), b = reusing.render(s);
        ASSERT_EQ(counter(b, "light_views_reused"), 6.0);
        EXPECT_EQ(counter(b, "vpl_tree_reused"), 1.0);
        EXPECT_FALSE(hasPass(b, "light_tree"));
        EXPECT_EQ(counter(a, "vpl_tree_reused"), 0.0);
        EXPECT_TRUE(hasPass(a, "light_tree"));
        EXPECT_EQ(counter(b, "vpl_tree_nodes"), counter(a, "vpl_tree_nodes"));
        EXPECT_EQ(a.rgba8, b.rgba8);
        // A dimmer light renders its views again, and builds the tree again from them.
        s.lights[0].light.intensity *= 0.5f;
        const FrameOutput c = reusing.render(s), d = fresh.render(s);
        EXPECT_EQ(counter(c, "vpl_tree_reused"), 0.0);
        EXPECT_TRUE(hasPass(c, "light_tree"));
        EXPECT_EQ(c.rgba8, d.rgba8);
        // Switched off and on again: no stale tree serves the frame after.
        s.lights[0].enabled = false;
        (void)reusing.render(s);
        s.lights[0].enabled = true;
        const FrameOutput e = reusing.render(s), f = fresh.render(s);
        EXPECT_TRUE(hasPass(e, "light_tree"));
        EXPECT_EQ(e.rgba8, f.rgba8);
    }
}

// An interactive frame's cap on the light views (FrameState::LightViewCap): a frame that draws them
// again draws them smaller, exactly as a frame asking for those sides would; kept maps of any side
// between the cap and the asked serve; a frame without a cap draws the asked sides again.
TEST(TilesGl, CappedLightViewsAreDrawnSmallerAndServeUntilTheAskedSidesAreWanted) {
    ReusePair pair("builtin:cornell", "hier_isr"); // RSMs, and the light tree built over them
    FrameRenderer &fresh = pair.fresh, &reusing = pair.reusing;
    FrameState asked = pair.state;
    asked.frameParams.set("shadow_map_size", 2048);
    asked.frameParams.set("rsm_size", 512);
    (void)reusing.render(asked);
    const auto sides = [](const FrameOutput& f) {
        const nlohmann::json& l = f.stats["lighting"];
        return std::to_string(l.value("shadow_side", 0)) + "/" + std::to_string(l.value("rsm_side", 0)) +
               (l.contains("shadow_side_asked") ? " of " + std::to_string(l.value("shadow_side_asked", 0)) +
                                                      "/" + std::to_string(l.value("rsm_side_asked", 0))
                                                : std::string());
    };
    // A light drag's frame under a cap: drawn at the cap.
    FrameState drag = asked;
    drag.lights[0].light.intensity *= 0.8f;
    drag.lightViewCap = {1024, 128};
    const FrameOutput dragged = reusing.render(drag);
    EXPECT_EQ(sides(dragged), "1024/128 of 2048/512");
    EXPECT_EQ(counter(dragged, "light_views_reused"), 0.0);
    EXPECT_TRUE(hasPass(dragged, "light_tree"));
    FrameState small = drag;
    small.lightViewCap = {};
    small.frameParams.set("shadow_map_size", 1024);
    small.frameParams.set("rsm_size", 128);
    const FrameOutput smallFrame = fresh.render(small);
    EXPECT_EQ(sides(smallFrame), "1024/128");
    EXPECT_EQ(dragged.rgba8, smallFrame.rgba8) << "the capped maps are the maps of those sides";
    // An orbit after the drag, still capped: the small maps serve.
    FrameState orbit = drag;
    orbit.camera.position += glm::vec3(0.2f, 0.0f, 0.0f);
    const FrameOutput orbited = reusing.render(orbit);
    EXPECT_GT(counter(orbited, "light_views_reused"), 0.0);
    EXPECT_EQ(sides(orbited), "1024/128 of 2048/512");
    // A refinement step's frame (no cap) draws the asked sides; capped frames after it keep them.
    FrameState refine = orbit;
    refine.lightViewCap = {};
    const FrameOutput refined = reusing.render(refine);
    EXPECT_EQ(counter(refined, "light_views_reused"), 0.0);
    EXPECT_EQ(sides(refined), "2048/512");
    orbit.camera.position += glm::vec3(0.1f, 0.0f, 0.0f);
    const FrameOutput after = reusing.render(orbit);
    EXPECT_GT(counter(after, "light_views_reused"), 0.0);
    EXPECT_EQ(sides(after), "2048/512");
    // The next drag takes back the capped arrays kept meanwhile, and the refinement after it the
    // asked ones: nothing is allocated again, and the frames equal a fresh renderer's.
    drag.lights[0].light.intensity *= 0.8f;
    const FrameOutput dragAgain = reusing.render(drag);
    EXPECT_EQ(sides(dragAgain), "1024/128 of 2048/512");
    EXPECT_EQ(counter(dragAgain, "light_view_arrays_created"), 0.0);
    small.lights = drag.lights;
    EXPECT_EQ(dragAgain.rgba8, fresh.render(small).rgba8);
    refine.lights = drag.lights;
    const FrameOutput refinedAgain = reusing.render(refine);
    EXPECT_EQ(sides(refinedAgain), "2048/512");
    EXPECT_EQ(counter(refinedAgain, "light_view_arrays_created"), 0.0);
    FrameState whole = refine;
    EXPECT_EQ(refinedAgain.rgba8, fresh.render(whole).rgba8);
    // What the frame budget asks before a frame: whether it would keep the maps drawn before.
    EXPECT_TRUE(reusing.keepsLightViews(refine)) << "the same lights, the asked sides kept";
    EXPECT_TRUE(reusing.keepsLightViews(drag)) << "a capped frame keeps larger maps up to the asked sides";
    FrameState movedLight = refine;
    movedLight.lights[0].light.intensity *= 0.5f;
    EXPECT_FALSE(reusing.keepsLightViews(movedLight)) << "another light";
    FrameState smallerAsked = refine;
    smallerAsked.frameParams.set("rsm_size", 256);
    EXPECT_FALSE(reusing.keepsLightViews(smallerAsked)) << "maps larger than asked do not serve";
    // A cap above the asked sides changes nothing.
    FrameState loose = asked;
    loose.lights[0].light.intensity *= 0.5f;
    loose.lightViewCap = {4096, 1024};
    EXPECT_EQ(sides(reusing.render(loose)), "2048/512");
}

// Refinement (an interrupt check set) draws light views larger than the defaults' in bands of rows,
// asking between them: the same maps as drawn in one piece, one more check per band, and a stop
// among the bands keeps nothing for the next frame.
TEST(TilesGl, LargeLightViewsAreDrawnInBandsThatInputCanStop) {
    ReusePair pair("builtin:cornell");
    FrameRenderer &whole = pair.fresh, &banded = pair.reusing;
    int checks = 0;
    banded.setInterruptCheck([&] {
        ++checks;
        return false;
    });
    const auto checksFor = [&](FrameState s) {
        s.lights[0].light.intensity *= 0.9f; // the light views are drawn again
        checks = 0;
        const FrameOutput out = banded.render(s);
        EXPECT_EQ(counter(out, "light_views_reused"), 0.0);
        return std::pair{checks, out};
    };
    const auto [defaultChecks, atDefaults] = checksFor(pair.state);
    FrameState large = pair.state;
    large.frameParams.set("shadow_map_size", 2048); // two bands
    large.frameParams.set("rsm_size", 1024);        // four bands
    const auto [largeChecks, inBands] = checksFor(large);
    EXPECT_EQ(largeChecks - defaultChecks, 1 + 3) << "one check between each two bands";
    FrameState same = large;
    same.lights[0].light.intensity *= 0.9f;
    EXPECT_EQ(inBands.rgba8, whole.render(same).rgba8) << "the bands draw the maps drawn in one piece";

    // A stop at the first check between bands: the frame ends, and its maps are not kept.
    int calls = 0;
    banded.setInterruptCheck([&] { return ++calls == 1; });
    FrameState moved = large;
    moved.lights[0].light.position += glm::vec3(0.0f, -0.1f, 0.0f);
    const FrameOutput stopped = banded.render(moved);
    EXPECT_TRUE(stopped.interrupted);
    banded.setInterruptCheck({});
    const FrameOutput next = banded.render(moved);
    EXPECT_EQ(counter(next, "light_views_reused"), 0.0) << "half-drawn maps must not serve";
    EXPECT_EQ(next.rgba8, whole.render(moved).rgba8);
}

// Where input may stop the frame, light maps too large to make within a slice are made on a helper
// thread, input asked meanwhile (llvmpipe made 13 views' 512^2 RSMs in one 85-97 ms call): a stop
// leaves them being made, the next frame takes them (no second making) and is the frame a renderer
// making them in the frame draws. Without a check they are made in the frame.
TEST(TilesGl, LargeLightMapsAreMadeInTheBackgroundWhileInputIsAsked) {
    ReusePair pair("builtin:cornell");
    FrameRenderer& renderer = pair.reusing;
    renderer.setBackgroundBytes(1); // every new map in the background
    FrameState large = pair.state;
    large.frameParams.set("rsm_size", 512);
    int asked = 0;
    renderer.setInterruptCheck([&] { return ++asked == 1; });
    EXPECT_TRUE(renderer.render(large).interrupted);
    EXPECT_EQ(asked, 1) << "stopped while the RSMs were made, before any pass";
    EXPECT_EQ(renderer.lightMapsStartedInBackground(), 1) << "the RSMs; the shadow maps are unchanged";

    renderer.setInterruptCheck([] { return false; });
    const FrameOutput taken = renderer.render(large);
    ASSERT_FALSE(taken.interrupted);
    EXPECT_EQ(renderer.lightMapsStartedInBackground(), 1) << "the making the stop left going on";
    EXPECT_EQ(counter(taken, "light_view_arrays_created"), 1.0);
    EXPECT_EQ(taken.stats["lighting"].value("rsm_side", 0), 512);
    EXPECT_EQ(taken.rgba8, pair.fresh.render(large).rgba8);

    // Both maps new, input waiting all along: each frame stops while one is made, the shadow maps
    // are put in place once made, and each making starts once.
    FrameState both = pair.state;
    both.frameParams.set("shadow_map_size", 2048);
    both.frameParams.set("rsm_size", 1024);
    renderer.setInterruptCheck([] { return true; });
    // (A session answers the input between two tries; a millisecond stands for that frame here.)
    for (int frame = 0; frame < 2000 && renderer.lightMapsStartedInBackground() < 3; ++frame) {
        EXPECT_TRUE(renderer.render(both).interrupted);
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    EXPECT_EQ(renderer.lightMapsStartedInBackground(), 3) << "the shadow maps', then the RSMs'";
    renderer.setInterruptCheck([] { return false; });
    const FrameOutput bothTaken = renderer.render(both);
    ASSERT_FALSE(bothTaken.interrupted);
    EXPECT_EQ(renderer.lightMapsStartedInBackground(), 3);
    EXPECT_EQ(bothTaken.rgba8, pair.fresh.render(both).rgba8);

    // Without a check (a live frame, a render request): made in the frame.
    renderer.setInterruptCheck({});
    FrameState other = pair.state;
    other.frameParams.set("rsm_size", 384);
    const FrameOutput made = renderer.render(other);
    EXPECT_EQ(counter(made, "light_view_arrays_created"), 1.0);
    EXPECT_EQ(renderer.lightMapsStartedInBackground(), 3);
}

// The asked light maps stay kept through an interactive frame's capped ones whatever their size: 13
// point-lamp views' 512^2 RSMs (164 MB, past the other side's 128 MiB) were made again in each
// refinement after a drag. Asked for smaller maps, they go.
TEST(TilesGl, TheAskedLightMapsAreKeptThroughCappedFrames) {
    ReusePair pair(std::string(GIS_SOURCE_DIR) + "/tests/data/corpus/point_lamps.glb");
    FrameRenderer& renderer = pair.reusing;
    FrameState asked = pair.state;
    asked.frameParams.set("rsm_size", 1024);
    const FrameOutput still = renderer.render(asked);
    ASSERT_EQ(still.stats["lighting"].value("rsm_side", 0), 512) << "13 views share 512-texel sides";
    const int views = still.stats["lighting"].value("views", 0);
    ASSERT_GE(views, 13);
    ASSERT_GT(48.0 * 512 * 512 * views, 128.0 * 1024 * 1024) << "past the other side's limit";

    FrameState drag = asked;
    drag.lights[0].light.intensity *= 0.8f;
    drag.lightViewCap = {0, 256};
    const FrameOutput capped = renderer.render(drag);
    EXPECT_EQ(capped.stats["lighting"].value("rsm_side", 0), 256);
    EXPECT_EQ(counter(capped, "light_view_arrays_created"), 0.0) << "the first frame's 256 RSMs, kept";
    FrameState back = drag;
    back.lightViewCap = {};
    const FrameOutput refined = renderer.render(back);
    EXPECT_EQ(refined.stats["lighting"].value("rsm_side", 0), 512);
    EXPECT_EQ(counter(refined, "light_view_arrays_created"), 0.0) << "the asked RSMs, kept";
    EXPECT_EQ(refined.rgba8, pair.fresh.render(back).rgba8);

    // Asked for 256 maps: the 512 ones go, and coming back to 1024 makes them again.
    FrameState small = back;
    small.frameParams.set("rsm_size", 256);
    (void)renderer.render(small);
    EXPECT_EQ(counter(renderer.render(back), "light_view_arrays_created"), 1.0);
}

// The same on a Blender export whose two point lamps and sun make 13 views (the asked 4096 and 1024
// become 2048 and 512 shared sides, lightViewSide): two bands per view and map, checks between
// every two; the bands draw the maps drawn in one piece, and a capped frame the maps of those sides.
TEST(TilesGl, LightViewsInBandsAndUnderACapOnBlenderLamps) {
    ReusePair pair(std::string(GIS_SOURCE_DIR) + "/tests/data/corpus/point_lamps.glb");
    FrameRenderer &whole = pair.fresh, &banded = pair.reusing;
    FrameState large = pair.state;
    large.frameParams.set("shadow_map_size", 4096);
    large.frameParams.set("rsm_size", 1024);
    int checks = 0;
    banded.setInterruptCheck([&] {
        ++checks;
        return false;
    });
    const FrameOutput inBands = banded.render(large);
    ASSERT_EQ(inBands.stats["lighting"]["views"], 13);
    EXPECT_EQ(inBands.stats["lighting"]["shadow_side"], 2048);
    EXPECT_EQ(inBands.stats["lighting"]["rsm_side"], 512);
    EXPECT_GE(checks, 2 * (13 * 2 - 1)) << "a check between every two bands of both arrays";
    EXPECT_EQ(inBands.rgba8, whole.render(large).rgba8);
    banded.setInterruptCheck({});
    // An interactive frame's cap at the defaults' sides (lightViewSide: 1024 and 256 for 13 views).
    FrameState capped = large;
    capped.lights[0].light.intensity *= 0.5f;
    capped.lightViewCap = {1024, 256};
    const FrameOutput small = banded.render(capped);
    EXPECT_EQ(small.stats["lighting"]["shadow_side"], 1024);
    EXPECT_EQ(small.stats["lighting"]["rsm_side_asked"], 512);
    FrameState asked = capped;
    asked.lightViewCap = {};
    asked.frameParams.set("shadow_map_size", 1024);
    asked.frameParams.set("rsm_size", 256);
    EXPECT_EQ(small.rgba8, whole.render(asked).rgba8);
}

TEST(TilesGl, ReusedEnvironmentProbesRenderTheSameFrame) {
    ReusePair pair("builtin:gallery"); // a room probe and a local one
    FrameRenderer &fresh = pair.fresh, &reusing = pair.reusing;
    FrameState s = pair.state;
    s.camera.position += glm::vec3(0.2f, 0.1f, 0.0f);
    const FrameOutput a = fresh.render(s), b = reusing.render(s);
    ASSERT_EQ(counter(b, "env_probe"), 1.0);
    EXPECT_EQ(counter(b, "env_cubes_reused"), 1.0);
    EXPECT_EQ(counter(a, "env_cubes_reused"), 0.0);
    EXPECT_EQ(a.rgba8, b.rgba8);
    s.lights[0].light.intensity *= 0.5f; // the probes see the light: rendered again
    const FrameOutput c = reusing.render(s), d = fresh.render(s);
    EXPECT_EQ(counter(c, "env_cubes_reused"), 0.0);
    EXPECT_EQ(c.rgba8, d.rgba8);
}

/// Largest |a - b| over the RGB of covered pixels, relative to the largest value of `b`.
double maxRelativeDifference(const std::vector<float>& a, const std::vector<float>& b) {
    double worst = 0.0, peak = 1e-12;
    for (std::size_t i = 0; i < b.size(); ++i) {
        if (i % 4 == 3) continue;
        worst = std::max(worst, static_cast<double>(std::fabs(a[i] - b[i])));
        peak = std::max(peak, static_cast<double>(std::fabs(b[i])));
    }
    return worst / peak;
}

bool hasPass(const FrameOutput& f, const std::string& name) {
    for (const auto& pass : f.stats.at("passes"))
        if (pass.at("name") == name) return true;
    return false;
}

// VPL parts (FrameState::VplPart): the running mean of the parts of one image ends at the image of
// every VPL, its first parts differ from it, and parts of another image or out of order start again.
// Refinement predicts a step's VPL passes apart from the rest of its frame (AdaptiveQuality): the
// names a technique declares must be passes its frames run.
TEST(TilesGl, EveryTechniquesVplPassesAreRunByItsFrames) {
    sharedContext();
    const Scene scene = loadScene("builtin:cornell");
    FrameRenderer renderer;
    renderer.setScene(std::make_shared<const Scene>(scene));
    int named = 0;
    for (const TechniqueInfo& info : techniqueCatalog()) {
        if (info.vplPasses.empty()) continue;
        ++named;
        const FrameOutput out = renderer.render(stateFor(scene, info.name, 64, 48));
        for (const std::string& pass : info.vplPasses)
            EXPECT_TRUE(hasPass(out, pass)) << info.name << ": " << pass;
    }
    EXPECT_GE(named, 6) << "every technique with VPLs names its VPL passes";
}

TEST(TilesGl, VplPartsAverageToTheWholeVplSet) {
    sharedContext();
    const Scene scene = loadScene("builtin:cornell");
    FrameRenderer renderer;
    renderer.setScene(std::make_shared<const Scene>(scene));
    int techniques = 0;
    for (const TechniqueInfo& info : techniqueCatalog()) {
        FrameState full = stateFor(scene, info.name, 96, 80);
        if (!info.vplParts || !info.vplParts(full.techniqueParams)) continue;
        ++techniques;
        full.techniqueParams.set("vpl_grid", 12); // 144 VPLs: 7 parts do not divide them
        const FrameOutput whole = renderer.render(full, true);
        const int parts = 7;
        std::vector<double> errors;
        for (int p = 0; p < parts; ++p) {
            FrameState part = full;
            part.vplPart = {p, parts};
            const FrameOutput out = renderer.render(part, true);
            EXPECT_EQ(counter(out, "vpl_parts_averaged"), p + 1.0) << info.name;
            EXPECT_EQ(counter(out, "vpl_parts"), parts) << info.name;
            // Parts after the first keep what the G-buffer alone decides (the eye hierarchy's mipmap).
            EXPECT_EQ(counter(out, "vpl_part_same_image"), p > 0 ? 1.0 : 0.0) << info.name;
            if (info.eyeHierarchy) {
                EXPECT_EQ(hasPass(out, "eye_mipmap"), p == 0) << info.name << " part " << p;
            }
            errors.push_back(maxRelativeDifference(out.linear, whole.linear));
        }
        std::printf("[vpl parts] %-16s 144 VPLs in %d parts: max relative difference after part 1 %.3g, "
                    "after all %.3g\n",
                    info.name.c_str(), parts, errors.front(), errors.back());
        EXPECT_GT(errors.front(), 0.01) << info.name << ": one part alone is not the whole set";
        EXPECT_LT(errors.back(), 1e-4) << info.name << ": the mean of all parts is";
    }
    EXPECT_GE(techniques, 2) << "rsm_gather and multires_gather render in parts";

    // As sessions render (light passes reused), later parts of one image also keep the G-buffer and
    // the direct light: the same mean without drawing them again; a changed frame parameter draws them.
    {
        FrameRenderer reusing;
        reusing.setReuseLightPasses(true);
        reusing.setScene(std::make_shared<const Scene>(scene));
        FrameState whole = stateFor(scene, "rsm_gather", 96, 80);
        whole.techniqueParams.set("vpl_grid", 12);
        const FrameOutput reference = reusing.render(whole, true);
        FrameOutput out;
        for (int p = 0; p < 4; ++p) {
            FrameState part = whole;
            part.vplPart = {p, 4};
            out = reusing.render(part, true);
            EXPECT_EQ(counter(out, "vpl_part_kept_gbuffer"), p > 0 ? 1.0 : 0.0) << "part " << p;
            EXPECT_EQ(hasPass(out, "gbuffer"), p == 0) << "part " << p;
            EXPECT_EQ(hasPass(out, "direct"), p == 0) << "part " << p;
        }
        EXPECT_LT(maxRelativeDifference(out.linear, reference.linear), 1e-4);
        FrameState changed = whole;
        changed.vplPart = {0, 2};
        reusing.render(changed);
        changed.vplPart = {1, 2};
        changed.frameParams.set("pcf_radius", 0);
        const FrameOutput redrawn = reusing.render(changed);
        EXPECT_EQ(counter(redrawn, "vpl_part_kept_gbuffer"), 0.0);
        EXPECT_TRUE(hasPass(redrawn, "gbuffer"));
    }

    FrameState full = stateFor(scene, "rsm_gather", 96, 80);
    FrameOutput last;

    // Tiles in parts: a window's parts end at the window of every VPL.
    TilePlan plan(full.width, full.height);
    const TileRect rect = plan.next(40.0 * 40.0);
    const FrameState tile = tileState(full, rect, tileGuardPx(full));
    const FrameOutput tileWhole = renderer.render(tile, true);
    for (int p = 0; p < 3; ++p) {
        FrameState part = tile;
        part.vplPart = {p, 3};
        last = renderer.render(part, true);
    }
    EXPECT_LT(maxRelativeDifference(last.linear, tileWhole.linear), 1e-4);

    // A part that does not follow the ones before (here: part 2 after another image) starts a mean.
    FrameState stray = full;
    stray.vplPart = {2, 3};
    EXPECT_EQ(counter(renderer.render(stray), "vpl_parts_averaged"), 1.0);

    // The next part seen from elsewhere is another image: a new mean, nothing kept from the last part.
    FrameState multires = stateFor(scene, "multires_gather", 96, 80);
    multires.vplPart = {0, 3};
    renderer.render(multires);
    FrameState moved = multires;
    moved.vplPart = {1, 3};
    moved.camera.position += glm::vec3(0.05f, 0.0f, 0.0f);
    const FrameOutput movedPart = renderer.render(moved);
    EXPECT_EQ(counter(movedPart, "vpl_parts_averaged"), 1.0);
    EXPECT_EQ(counter(movedPart, "vpl_part_same_image"), 0.0);
    EXPECT_TRUE(hasPass(movedPart, "eye_mipmap"));

    // Bias compensation filters the sum: no parts, every part renders the whole set.
    FrameState compensated = full;
    compensated.techniqueParams.set("ssbc_iterations", 1);
    const FrameOutput ssbcWhole = renderer.render(compensated);
    compensated.vplPart = {0, 3};
    const FrameOutput ssbcPart = renderer.render(compensated);
    EXPECT_EQ(counter(ssbcPart, "vpl_parts"), 0.0);
    EXPECT_EQ(ssbcPart.rgba8, ssbcWhole.rgba8);
}

// Refinement's gathers in about eight pieces: whole batches of 1,024 VPLs where there are eight or
// more (25,921 VPLs: 26 batches, a check after every 3rd rather than a wait after each), else each
// batch cut.
TEST(TilesGl, AGatherGoesInAboutEightPieces) {
    auto pieces = [](int batches) {
        const GatherCut cut = gatherCut(batches);
        EXPECT_GE(cut.cutsPerBatch, 1);
        EXPECT_GE(cut.batchesPerPiece, 1);
        EXPECT_TRUE(cut.cutsPerBatch == 1 || cut.batchesPerPiece == 1)
            << "cut batches or group them, not both";
        return cut.cutsPerBatch > 1 ? batches * cut.cutsPerBatch
                                    : (batches + cut.batchesPerPiece - 1) / cut.batchesPerPiece;
    };
    EXPECT_EQ(gatherCut(1).cutsPerBatch, 8);
    EXPECT_EQ(gatherCut(3).cutsPerBatch, 3);
    EXPECT_EQ(gatherCut(5).cutsPerBatch, 2);
    EXPECT_EQ(gatherCut(7).cutsPerBatch, 1);
    EXPECT_EQ(gatherCut(26).batchesPerPiece, 3);
    EXPECT_EQ(gatherCut(0).cutsPerBatch, 8) << "no batch: nothing to cut, and no division by zero";
    for (int batches = 1; batches <= 64; ++batches) {
        EXPECT_GE(pieces(batches), 6) << batches;
        EXPECT_LE(pieces(batches), 11) << batches;
    }
}

// A full traversal (hier_isr, tau 0) goes in ranges of the light tree's roots, each a dispatch over
// every receiver: enough that no invocation passes llvmpipe's loop limit (which cut the traversal
// short, silently), and in refinement about a million receiver-leaf pairs each, 8 to 64 of them.
TEST(TilesGl, AFullTraversalGoesInRootRanges) {
    const std::vector<LightLevel> levels = lightTreeLayout(256); // sides 256, 128, ..., 1
    const auto split = [&](int coarsest, double tau, double budget = kTraversalLoopBudget) {
        const TraversalSplit t = traversalSplit(levels, lightCutSettings(levels, coarsest, 256, tau), budget);
        return std::array{t.rootLevel, t.roots, t.ranges};
    };
    EXPECT_EQ(split(16, 0.0), (std::array{4, 256, 2})) << "256 roots x (341 nodes + 1) over the budget";
    EXPECT_EQ(split(16, 0.01), (std::array{4, 256, 2})) << "the test's worst case: every node refined";
    EXPECT_EQ(split(16, 1.0), (std::array{4, 256, 1})) << "never refined: one node a root";
    EXPECT_EQ(split(256, 1.0), (std::array{0, 65536, 3})) << "65,536 roots x 2 iterations";
    // Roots at most kFullTraversalMaxDepth levels above the leaves, below the start level when it
    // is coarser (the ancestors walked once a root): 4 x (1 + 21,845 + 1) iterations.
    EXPECT_EQ(split(1, 0.0), (std::array{kFullTraversalMaxDepth, 4, 2}));
    EXPECT_EQ(split(1, 0.5), (std::array{kFullTraversalMaxDepth, 4, 2}));
    EXPECT_EQ(split(16, 0.0, 100.0), (std::array{3, 1024, 891})) << "1,024 x (1 + 85 + 1) over 100";
    EXPECT_EQ(split(16, 0.0, 1.0), (std::array{0, 65536, 65536})) << "at most one root a range";
    EXPECT_EQ(split(16, 0.0, 1e300), (std::array{4, 256, 1}));
    // The test's start level stays hier_coarsest's whatever tau.
    EXPECT_EQ(lightCutSettings(levels, 1, 256, 0.0).startLevel, 8);
    EXPECT_EQ(lightCutSettings(levels, 1, 256, 0.5).startLevel, 8);

    EXPECT_EQ(traversalRanges(1576, 65536.0, 256), kMaxTraversalRanges) << "a 48 x 48 tile, 65,536 leaves";
    EXPECT_EQ(traversalRanges(3000, 1024.0, 256), 8) << "little work: the usual eight pieces";
    EXPECT_EQ(traversalRanges(6000, 4096.0, 256), 24);
    EXPECT_EQ(traversalRanges(1e9, 1e9, 4), 4) << "at most one root a range";
    EXPECT_EQ(traversalRanges(100, 16.0, 1), 1);
    EXPECT_EQ(traversalRanges(100, std::nan(""), 256), 8) << "unknown work: the usual eight";

    sharedContext();
    const auto scene = std::make_shared<const Scene>(loadScene("builtin:cornell"));
    FrameState s = stateFor(*scene, "hier_isr", 96, 80);
    s.techniqueParams.set("tau", 0.0);
    CheckedFrame frames(scene, s);
    const FrameOutput &expected = frames.expected, &ranged = frames.checked;
    const int checks = frames.checks;
    const double ranges = counter(ranged, "traversal_ranges");
    EXPECT_GE(ranges, 8.0);
    EXPECT_EQ(counter(expected, "traversal_ranges"), 2.0) << "without a check: the loop budget's ranges";
    // Shadow maps, RSMs, eye passes, the geometry levels, the stencil, between the ranges, after it.
    EXPECT_EQ(checks, 5 + static_cast<int>(ranges) - 1 + 1);
    // Each range adds its share of every receiver's sum: the same light, up to float rounding.
    const Difference d = compare(expected.rgba8, ranged.rgba8);
    EXPECT_LE(d.mean, 0.02);
    EXPECT_EQ(d.over8, 0.0);
    // Every node, whichever the ranges (one dispatch visited 65,117 of cornell's 67,848 nodes here).
    EXPECT_EQ(counter(ranged, "nodes_visited_mean"), counter(expected, "nodes_visited_mean"));
    EXPECT_EQ(counter(ranged, "cut_size_mean"), counter(expected, "cut_size_mean"));
    EXPECT_GT(counter(expected, "nodes_visited_mean"), 65535.0);
    // Stopped between two ranges, the next frame is the whole one.
    frames.expectAStopKeepsNothing(s);
}

// A full traversal with fewer roots than its pieces (balanced's hier_coarsest 1: one root over 256
// leaves) goes in receiver chunks for the rest: in refinement no stretch of the gather runs whole
// (one such dispatch held input up to 37 ms), and each receiver's sum is the one dispatch's.
TEST(TilesGl, AFullTraversalWithFewRootsGoesInReceiverChunks) {
    const auto pieces = [](double receivers, double leaves, int roots, int minRanges) {
        const TraversalPieces p = fullTraversalPieces(receivers, leaves, roots, minRanges);
        return std::array{p.ranges, p.chunks};
    };
    EXPECT_EQ(pieces(3000, 256.0, 1, 1), (std::array{1, 8})) << "one root: the usual eight, in chunks";
    EXPECT_EQ(pieces(3000, 256.0, 4, 1), (std::array{4, 2}));
    EXPECT_EQ(pieces(3000, 256.0, 256, 1), (std::array{8, 1})) << "roots enough: ranges alone";
    EXPECT_EQ(pieces(1576, 65536.0, 4, 2), (std::array{4, 16})) << "64 pieces asked over 4 roots";
    EXPECT_EQ(pieces(1576, 65536.0, 256, 2), (std::array{64, 1}));
    EXPECT_EQ(pieces(3000, 1024.0, 256, 32), (std::array{32, 1})) << "the loop budget's ranges stay";
    EXPECT_EQ(pieces(3000, 1024.0, 12, 1), (std::array{6, 2})) << "whole roots a range: 2 each";
    EXPECT_EQ(pieces(100, std::nan(""), 1, 1), (std::array{1, 8})) << "unknown work: the usual eight";
    EXPECT_EQ(pieces(0, 256.0, 0, 1), (std::array{1, 8})) << "no root, no receiver: no division by zero";

    sharedContext();
    const auto scene = std::make_shared<const Scene>(loadScene("builtin:cornell"));
    FrameState s = stateFor(*scene, "hier_isr", 96, 80);
    s.techniqueParams.set("tau", 0.0);
    s.techniqueParams.set("hier_coarsest", 1);
    s.techniqueParams.set("max_depth", 16);
    CheckedFrame frames(scene, s);
    const FrameOutput &expected = frames.expected, &chunked = frames.checked;
    const int checks = frames.checks;
    EXPECT_FALSE(expected.stats["counts"].contains("traversal_receiver_chunks"));
    EXPECT_FALSE(chunked.stats["counts"].contains("traversal_ranges")) << "one root: one range";
    const double chunks = counter(chunked, "traversal_receiver_chunks");
    EXPECT_EQ(chunks, 8.0);
    // Shadow maps, RSMs, eye passes, the geometry levels, the stencil, between the chunks, after it;
    // fewer when the receivers fill fewer groups than the chunks.
    const double receivers = counter(chunked, "receivers_total");
    const double groups = std::ceil(receivers / GIS_EYE_RECEIVER_GROUP);
    const double perChunk = std::ceil(groups / chunks);
    EXPECT_EQ(checks, 5 + static_cast<int>(std::ceil(groups / perChunk)) - 1 + 1);
    EXPECT_GT(checks, 6) << "the gather did go in pieces";
    EXPECT_EQ(chunked.rgba8, expected.rgba8) << "each receiver's sum as in one dispatch";
    EXPECT_EQ(counter(chunked, "nodes_visited_mean"), counter(expected, "nodes_visited_mean"));
    // Stopped between two chunks, the next frame is the whole one.
    frames.expectAStopKeepsNothing(s);
}

// Any traversal (hier_isr, whatever tau) is split within the loop budget: roots below the start level
// reached through their ancestors, which the test decides once. A split traversal gives the whole
// traversal's cut node for node (its visit and cut counts, summed over receivers, are integers) and
// its image up to float rounding. A traversal by the test that llvmpipe's limit cut short before
// (tau 0.00003) is gathered again, split.
TEST(TilesGl, ASplitTraversalGivesTheWholeTraversalsCut) {
    sharedContext();
    const auto scene = std::make_shared<const Scene>(loadScene("builtin:cornell"));
    const auto hierIsr = [](FrameRenderer& r) {
        auto* technique = dynamic_cast<HierIsr*>(r.technique());
        GIS_ASSERT(technique);
        return technique;
    };
    // rsm_size 64: sides 64 ... 1; hier_coarsest 2 starts 5 levels above the leaves, whole in one
    // dispatch with an unbounded budget. A budget of 100 takes the roots 2 levels lower (64 of them,
    // 1 + 85 + 2 iterations each at worst), in ranges of 2.
    for (const double tau : {0.0, 0.002, 0.05, 0.5}) {
        SCOPED_TRACE(tau);
        FrameState s = stateFor(*scene, "hier_isr", 96, 80);
        s.frameParams.set("rsm_size", 64);
        s.techniqueParams.set("tau", tau);
        s.techniqueParams.set("max_depth", 64);
        s.techniqueParams.set("hier_coarsest", 2);
        FrameRenderer whole;
        whole.setScene(scene);
        whole.render(s);
        hierIsr(whole)->setLoopBudget(1e300);
        const FrameOutput expected = whole.render(s);
        EXPECT_FALSE(expected.stats["counts"].contains("traversal_ranges"));
        FrameRenderer split;
        split.setScene(scene);
        split.render(s);
        hierIsr(split)->setLoopBudget(100.0);
        const FrameOutput ranged = split.render(s);
        EXPECT_EQ(counter(ranged, "traversal_split_levels"), 2.0);
        EXPECT_EQ(counter(ranged, "traversal_ranges"), 32.0) << "57 ranges asked: 2 of the 64 roots each";
        EXPECT_EQ(counter(ranged, "nodes_visited_mean"), counter(expected, "nodes_visited_mean"));
        EXPECT_EQ(counter(ranged, "cut_size_mean"), counter(expected, "cut_size_mean"));
        EXPECT_EQ(counter(ranged, "traversal_cut_short"), 0.0);
        EXPECT_EQ(counter(expected, "traversal_cut_short"), 0.0);
        const Difference d = compare(expected.rgba8, ranged.rgba8);
        EXPECT_LE(d.mean, 0.02);
        EXPECT_EQ(d.over8, 0.0);
    }

    // A traversal by the test goes whole first. At the default rsm_size (256) and hier_coarsest (16)
    // with tau 0.00003, llvmpipe's loop limit stops receivers short in one dispatch (gather.comp
    // counts them): the gather starts again in two ranges of 128 roots, and the next frame with the
    // same settings starts split.
    FrameState fine = stateFor(*scene, "hier_isr", 64, 48);
    fine.techniqueParams.set("tau", 0.00003);
    FrameRenderer renderer;
    renderer.setScene(scene);
    const bool llvmpipe = sharedContext().info().renderer.find("llvmpipe") != std::string::npos;
    const FrameOutput first = renderer.render(fine);
    EXPECT_EQ(counter(first, "traversal_cut_short"), 0.0);
    if (llvmpipe) {
        EXPECT_GT(counter(first, "traversal_cut_short_whole"), 0.0);
        EXPECT_EQ(counter(first, "traversal_ranges"), 2.0);
        const FrameOutput next = renderer.render(fine);
        EXPECT_EQ(counter(next, "traversal_cut_short_whole"), 0.0) << "split from the start";
        EXPECT_EQ(counter(next, "traversal_ranges"), 2.0);
        EXPECT_EQ(next.rgba8, first.rgba8);
        // Whole, as before: receivers stopped short, fewer nodes visited.
        hierIsr(renderer)->setLoopBudget(1e300);
        const FrameOutput cutShort = renderer.render(fine);
        EXPECT_GT(counter(cutShort, "traversal_cut_short"), 0.0);
        EXPECT_LT(counter(cutShort, "nodes_visited_mean"), counter(first, "nodes_visited_mean"));
    }
    // A traversal by the test that fits goes whole, in one dispatch.
    FrameState usual = stateFor(*scene, "hier_isr", 64, 48);
    const FrameOutput plain = renderer.render(usual);
    EXPECT_FALSE(plain.stats["counts"].contains("traversal_ranges"));
    EXPECT_EQ(counter(plain, "traversal_cut_short"), 0.0);
}

// Refinement's interruption (FrameRenderer::setInterruptCheck): a frame stops at the first check that
// says true, and keeps nothing half done: the frame after it is the one an uninterrupted renderer draws,
// at whichever stage it stopped.
TEST(TilesGl, InterruptedFramesKeepNothingHalfDone) {
    sharedContext();
    const auto shared = std::make_shared<const Scene>(loadScene("builtin:cornell"));
    // A file written by another tool: Blender's point lamps (tests/data/corpus/generate.py), one light
    // view per cube face.
    const auto lamps = std::make_shared<const Scene>(
        loadScene(std::string(GIS_SOURCE_DIR) + "/tests/data/corpus/point_lamps.glb"));
    auto reusingRenderer = [&](const std::shared_ptr<const Scene>& scene) {
        auto r = std::make_unique<FrameRenderer>();
        r->setReuseLightPasses(true); // as sessions render: kept light views are what could go stale
        r->setBackgroundBytes(kNoBackground);
        r->setScene(scene);
        return r;
    };
    for (const auto& [scene, technique] : {std::pair{shared, std::string("multires_gather")},
                                           {shared, "rsm_gather"},
                                           {shared, "hier_isr"},
                                           {lamps, "multires_gather"}}) {
        const FrameState lit = stateFor(*scene, technique, 96, 80);
        ASSERT_FALSE(lit.lights.empty());
        FrameState moved = lit; // another light: its views are drawn again
        moved.lights[0].light.position += glm::vec3(0.1f, 0.0f, 0.0f);
        const FrameOutput expected = reusingRenderer(scene)->render(lit);

        // An uninterrupted frame that draws its light views: how many checks it passes.
        int checks = 0;
        int gatherPieces = 0;
        {
            auto counting = reusingRenderer(scene);
            counting->setInterruptCheck([&] {
                ++checks;
                return false;
            });
            const FrameOutput out = counting->render(lit);
            EXPECT_FALSE(out.interrupted);
            EXPECT_EQ(out.rgba8, expected.rgba8) << scene->name << " " << technique;
            // One batch of VPLs, cut in eight: rsm_gather's 80 rows in bands of whole bin rows (64,
            // then 16); the receiver gathers' list in chunks of ceil(groups / 8) groups.
            const GatherCut cut = gatherCut(1);
            EXPECT_EQ(cut.cutsPerBatch, 8);
            const int groups = static_cast<int>(std::ceil(counter(out, "receivers_total") / 64.0));
            const int perChunk = (groups + cut.cutsPerBatch - 1) / cut.cutsPerBatch;
            gatherPieces = technique == "rsm_gather" ? 2 : (groups + perChunk - 1) / perChunk;
            EXPECT_GE(gatherPieces, 2) << scene->name << " " << technique << ": the gather is cut";
        }
        // Shadow maps, RSMs, eye passes, after the technique; inside it rsm_gather after its VPL
        // shadow maps, the hierarchical ones after their geometry levels and after the receivers'
        // stencil; and between the pieces of the gather.
        const int insideTechnique = technique == "rsm_gather" ? 1 : 2;
        EXPECT_EQ(checks, 4 + insideTechnique + gatherPieces - 1) << scene->name << " " << technique;

        for (int stopAt = 1; stopAt <= checks; ++stopAt) {
            auto renderer = reusingRenderer(scene);
            renderer->render(lit); // the light views of `lit`, kept
            int asked = 0;
            renderer->setInterruptCheck([&] { return ++asked >= stopAt; });
            const FrameOutput stopped = renderer->render(moved);
            EXPECT_TRUE(stopped.interrupted) << scene->name << " " << technique << " check " << stopAt;
            EXPECT_TRUE(stopped.rgba8.empty());
            EXPECT_EQ(asked, stopAt) << scene->name << " " << technique
                                     << ": the frame stops at the first true";
            renderer->setInterruptCheck({});
            // Back to the first light: its views were partly drawn over, so they are drawn again.
            const FrameOutput next = renderer->render(lit);
            EXPECT_FALSE(next.interrupted);
            EXPECT_GT(counter(next, "triangles_light_views"), 0.0)
                << scene->name << " " << technique << " check " << stopAt;
            EXPECT_EQ(next.rgba8, expected.rgba8)
                << scene->name << " " << technique << " stopped at check " << stopAt;
        }
    }

    // Environment probes (gallery: a room probe and two local ones), rendered again for another face size
    // under kept light views: a frame stopped between their cubes leaves none to be kept.
    {
        const auto gallery = std::make_shared<const Scene>(loadScene("builtin:gallery"));
        FrameState cubes = stateFor(*gallery, "multires_gather", 96, 80);
        FrameState resized = cubes;
        resized.frameParams.set("env_size", 32);
        FrameRenderer fresh;
        fresh.setScene(gallery);
        const FrameOutput expected = fresh.render(resized);
        ASSERT_EQ(counter(expected, "env_probes"), 3.0);
        int checks = 0;
        {
            FrameRenderer counting;
            counting.setReuseLightPasses(true);
            counting.setBackgroundBytes(kNoBackground);
            counting.setScene(gallery);
            counting.render(cubes);
            counting.setInterruptCheck([&] {
                ++checks;
                return false;
            });
            EXPECT_EQ(counting.render(resized).rgba8, expected.rgba8);
        }
        // Eye passes, the technique (3: after its geometry levels, after the receivers' stencil and
        // after it, and between the chunks of its receivers), the room probe's faces, before each
        // local probe and after its faces (2 x 2), after the reflections; the light views are kept.
        // The last six are the probes'.
        const int groups = static_cast<int>(std::ceil(counter(expected, "receivers_total") / 64.0));
        const int perChunk = (groups + 7) / 8;
        EXPECT_EQ(checks, 10 + (groups + perChunk - 1) / perChunk - 1);
        for (int stopAt = checks - 5; stopAt <= checks; ++stopAt) {
            FrameRenderer renderer;
            renderer.setReuseLightPasses(true);
            renderer.setScene(gallery);
            renderer.render(cubes);
            int asked = 0;
            renderer.setInterruptCheck([&] { return ++asked >= stopAt; });
            EXPECT_TRUE(renderer.render(resized).interrupted);
            renderer.setInterruptCheck({});
            const FrameOutput next = renderer.render(resized);
            EXPECT_GT(counter(next, "light_views_reused"), 0.0) << "what would have kept the cubes";
            // Stopped after the reflections, the cubes were whole and are kept.
            EXPECT_EQ(counter(next, "env_cubes_reused"), stopAt < checks ? 0.0 : 1.0)
                << "stopped at check " << stopAt;
            EXPECT_EQ(next.rgba8, expected.rgba8) << "environment probes stopped at check " << stopAt;
        }
    }

    // VPL parts: a part of another image stopped after its eye passes drew over the G-buffer that
    // the parts keep, so the next part of the first image starts a new mean and draws its own.
    auto renderer = reusingRenderer(shared);
    FrameState image = stateFor(*shared, "multires_gather", 96, 80);
    image.vplPart = {0, 3};
    renderer->render(image);
    FrameState other = image;
    other.camera.position += glm::vec3(0.05f, 0.0f, 0.0f);
    int asked = 0;
    renderer->setInterruptCheck([&] { return ++asked >= 1; });
    EXPECT_TRUE(renderer->render(other).interrupted);
    EXPECT_EQ(asked, 1) << "light views kept: the eye passes' check is the first";
    renderer->setInterruptCheck({});
    image.vplPart = {1, 3};
    const FrameOutput afterStop = renderer->render(image);
    EXPECT_EQ(counter(afterStop, "vpl_parts_averaged"), 1.0);
    EXPECT_EQ(counter(afterStop, "vpl_part_kept_gbuffer"), 0.0);
    // So does a whole frame of another image between two parts.
    image.vplPart = {0, 3};
    renderer->render(image);
    FrameState whole = other;
    whole.vplPart = {};
    renderer->render(whole);
    image.vplPart = {1, 3};
    const FrameOutput afterWhole = renderer->render(image);
    EXPECT_EQ(counter(afterWhole, "vpl_parts_averaged"), 1.0);
    EXPECT_EQ(counter(afterWhole, "vpl_part_kept_gbuffer"), 0.0);
}

} // namespace
} // namespace gis::test
