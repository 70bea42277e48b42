// Adaptive quality's decisions without GL or threads: presets under the client's parameters, the
// snapshot's step, refinement capped or skipped to fit the budget and the slices, interactive frames
// sized by the frame budget, and predictions from what earlier steps measured.
#include <cmath>

#include <gtest/gtest.h>

#include "frame/FrameState.h"
#include "frame/VplBudget.h"
#include "scene/SceneLoader.h"
#include "session/AdaptiveQuality.h"

namespace gis {
namespace {

const Scene& cornell() {
    static const Scene scene = loadScene("builtin:cornell");
    return scene;
}

/// rsm_gather with vpl_grid 8 (64 VPLs) at 256 x 256.
FrameState requested() {
    FrameState s = makeFrameState(cornell(), "rsm_gather");
    s.width = s.height = 256;
    s.techniqueParams.set("vpl_grid", 8);
    return s;
}

nlohmann::json presets() {
    return {{"techniques",
             {{"rsm_gather",
               {{"interactive", {{"vpl_grid", 4}}},
                {"balanced", {{"vpl_grid", 16}}},
                {"final", {{"vpl_grid", 64}}}}}}}};
}

SessionLimits limits() {
    SessionLimits l;
    l.refineBudgetMs = 30000;
    l.sliceMs = 20;
    l.frameTargetMs = 80;
    return l;
}

int grid(const FrameState& s) {
    return s.techniqueParams.getInt("vpl_grid");
}

TEST(AdaptiveQuality, StepsRenderTheirPresetUnderTheClientsParameters) {
    AdaptiveQuality q(limits(), presets());
    const nlohmann::json none = nlohmann::json::object();
    EXPECT_EQ(grid(q.presetState(requested(), none, QualityStep::Interactive)), 4);
    EXPECT_EQ(grid(q.presetState(requested(), none, QualityStep::Final)), 64);
    EXPECT_EQ(grid(q.presetState(requested(), {{"vpl_grid", 8}}, QualityStep::Final)), 8) << "explicit wins";
    EXPECT_EQ(grid(q.presetState(requested(), none, QualityStep::Fixed)), 8) << "fixed: as asked";
    AdaptiveQuality noPresets(limits(), nullptr);
    EXPECT_EQ(grid(noPresets.presetState(requested(), none, QualityStep::Final)), 8);
    SessionLimits tight = limits();
    tight.maxVpls = 1000;
    AdaptiveQuality capped(tight, presets());
    EXPECT_EQ(grid(capped.presetState(requested(), none, QualityStep::Final)), 8)
        << "a preset over the VPL limit is not used";
}

TEST(AdaptiveQuality, PredictionsScaleTheNearestMeasuredStep) {
    AdaptiveQuality q(limits(), presets());
    FrameState s = requested(); // 64 VPLs, 65,536 px
    EXPECT_EQ(q.predictStepMs("cornell", s, QualityStep::Balanced), 0.0) << "nothing measured";
    q.recordStepCost("cornell", s, QualityStep::Interactive, 1e-3); // 65.5 ms at 64 VPLs
    EXPECT_NEAR(q.predictStepMs("cornell", s, QualityStep::Interactive), 65.536, 1e-9);
    FrameState bigger = s;
    bigger.techniqueParams.set("vpl_grid", 16); // 4x the VPLs
    EXPECT_NEAR(q.predictStepMs("cornell", bigger, QualityStep::Final), 4 * 65.536, 1e-9)
        << "the interactive step scaled by VPLs";
    q.recordStepCost("cornell", bigger, QualityStep::Balanced, 2e-3);
    EXPECT_NEAR(q.predictStepMs("cornell", bigger, QualityStep::Final), 131.072, 1e-9) << "the nearest one";
    EXPECT_EQ(q.predictStepMs("other", s, QualityStep::Final), 0.0) << "per scene";
    q.recordStepCost("cornell", s, QualityStep::Final, std::nan(""));
    EXPECT_NEAR(q.predictStepMs("cornell", bigger, QualityStep::Final), 131.072, 1e-9) << "NaN is not kept";
}

TEST(AdaptiveQuality, OnlyTheVplPassesOfAMeasuredStepScaleWithTheVpls) {
    AdaptiveQuality q(limits(), presets());
    FrameState s = requested(); // 64 VPLs, 65,536 px
    // 65.5 ms at 64 VPLs, of which a tenth in the gather: the shadow maps, G-buffer and the rest cost
    // the same with 64 times the VPLs.
    q.recordStepCost("cornell", s, QualityStep::Interactive, 1e-3, 1e-4);
    FrameState many = s;
    many.techniqueParams.set("vpl_grid", 64); // 4,096 VPLs
    EXPECT_NEAR(q.predictStepMs("cornell", many, QualityStep::Balanced), 65.536 * (0.9 + 0.1 * 64), 1e-9);
    EXPECT_NEAR(q.predictStepMs("cornell", s, QualityStep::Balanced), 65.536, 1e-9) << "at the same VPLs";
    // A VPL part larger than the whole is the whole; one not known (or not a number) scales it all.
    q.recordStepCost("cornell", s, QualityStep::Interactive, 1e-3, 5e-3);
    EXPECT_NEAR(q.predictStepMs("cornell", many, QualityStep::Balanced), 64 * 65.536, 1e-9);
    q.recordStepCost("cornell", s, QualityStep::Interactive, 1e-3, std::nan(""));
    EXPECT_NEAR(q.predictStepMs("cornell", many, QualityStep::Balanced), 64 * 65.536, 1e-9);
}

TEST(AdaptiveQuality, TheVplPassesAreTheTechniquesOwn) {
    const nlohmann::json stats = {{"passes",
                                   {{{"name", "shadow_map"}, {"cpu_ms", 5.0}},
                                    {{"name", "vpl_gather"}, {"cpu_ms", 7.0}, {"gpu_ms", 6.0}},
                                    {{"name", "light_tree"}, {"cpu_ms", 2.0}},
                                    {{"name", "vpl_gather"}, {"cpu_ms", 1.5}},
                                    {{"name", "upsample"}, {"cpu_ms", 3.0}}}}};
    EXPECT_DOUBLE_EQ(vplPassesMs("multires_gather", stats), 7.5) << "gpu_ms first, every run of the pass";
    EXPECT_DOUBLE_EQ(vplPassesMs("hier_isr", stats), 9.5) << "the tree over the VPLs too";
    EXPECT_DOUBLE_EQ(vplPassesMs("multires_splat", stats), 0.0) << "its splat did not run";
    EXPECT_LT(vplPassesMs("none", stats), 0.0) << "no VPLs: none named";
    EXPECT_DOUBLE_EQ(vplPassesMs("rsm_gather", nlohmann::json::object()), 0.0) << "no passes";
}

TEST(AdaptiveQuality, TheTimeLeftFollowsTheStepsPaceOnceHalfIsDone) {
    EXPECT_LT(stepEtaMs(0, 0, 0, 0, 0), 0.0) << "nothing known";
    EXPECT_DOUBLE_EQ(stepEtaMs(1000, 0, 0, 0, 5000), 4000) << "the prediction before any pace";
    EXPECT_DOUBLE_EQ(stepEtaMs(6000, 0, 0, 0, 5000), 0) << "a prediction overrun leaves nothing, not less";
    EXPECT_DOUBLE_EQ(stepEtaMs(3000, 0.5, 0, 0, 0), 3000) << "the pace alone";
    // The one-time work took 1 s and 1 % of the image; the next 2 s did 59 % more.
    EXPECT_DOUBLE_EQ(stepEtaMs(3000, 0.6, 1000, 0.01, 100000), 2000.0 * 0.4 / 0.59) << "half done: the pace";
    // Half-way to half: half the pace, half what is left of the prediction.
    EXPECT_DOUBLE_EQ(stepEtaMs(1000, 0.25, 0, 0, 9000), 0.5 * (1000 * 0.75 / 0.25) + 0.5 * 8000);
    EXPECT_DOUBLE_EQ(stepEtaMs(5000, 1.0, 0, 0, 9000), 0.0) << "done";
    EXPECT_DOUBLE_EQ(stepEtaMs(1000, std::nan(""), 0, 0, 3000), 2000) << "a share not a number counts as 0";
}

TEST(AdaptiveQuality, RefinementOverTheBudgetIsCappedOrSkipped) {
    SessionLimits l = limits();
    l.refineBudgetMs = 1000;
    AdaptiveQuality q(l, presets());
    const nlohmann::json none = nlohmann::json::object();
    // The final preset (4096 VPLs) predicted from the interactive step (16 VPLs, 16.4 ms) at 256 times
    // that: 4.2 s, over the 1 s budget; 0.9 x 4096 / 4.2 = 879 VPLs fit, more than the balanced 256.
    q.recordStepCost("cornell", q.presetState(requested(), none, QualityStep::Interactive),
                     QualityStep::Interactive, 2.5e-4);
    const AdaptiveQuality::Plan finalPlan =
        q.plan("cornell", requested(), none, QualityStep::Final, false, 80);
    EXPECT_FALSE(finalPlan.skip);
    EXPECT_GT(finalPlan.predictedMs, 1000.0);
    const long vpls = vplEstimate(finalPlan.state);
    EXPECT_LT(vpls, 4096);
    EXPECT_GT(vpls, 256) << "more than the balanced step's";
    EXPECT_NE(finalPlan.why.find("capped at"), std::string::npos) << finalPlan.why;
    EXPECT_NE(finalPlan.why.find("--refine-budget-ms"), std::string::npos) << finalPlan.why;

    l.refineBudgetMs = 10; // nothing fits: not even the balanced step's VPLs
    AdaptiveQuality tight(l, presets());
    tight.recordStepCost("cornell", tight.presetState(requested(), none, QualityStep::Interactive),
                         QualityStep::Interactive, 2.5e-4);
    const AdaptiveQuality::Plan skipped =
        tight.plan("cornell", requested(), none, QualityStep::Final, false, 80);
    EXPECT_TRUE(skipped.skip);
    EXPECT_NE(skipped.why.find("no more than the step before"), std::string::npos) << skipped.why;
}

TEST(AdaptiveQuality, TheBudgetsVplCapLeavesTheRestOfTheFrameItsTime) {
    SessionLimits l = limits();
    l.refineBudgetMs = 1000;
    AdaptiveQuality q(l, presets());
    const nlohmann::json none = nlohmann::json::object();
    // The interactive step (16 VPLs, 65,536 px): 16.4 ms, 1.6 ms of it in the gather. The final
    // preset (4,096 VPLs): 14.7 + 1.6 x 256 = 434 ms, within the budget: not capped.
    const FrameState interactive = q.presetState(requested(), none, QualityStep::Interactive);
    q.recordStepCost("cornell", interactive, QualityStep::Interactive, 2.5e-4, 2.5e-5);
    const AdaptiveQuality::Plan fits = q.plan("cornell", requested(), none, QualityStep::Final, false, 80);
    EXPECT_NEAR(fits.predictedMs, 65536 * (2.25e-4 + 2.5e-5 * 256), 1e-6);
    EXPECT_EQ(vplEstimate(fits.state), 4096) << fits.why;
    // 65.5 ms, a quarter of it in the gather: 49.2 + 16.4 x 256 ms = 4.2 s. The VPLs that fit 0.9 of
    // the 1 s leave the rest its 49.2 ms: 16 x (900 - 49.2) / 16.4 = 831, a 28 x 28 grid, where
    // scaling the whole frame gave 0.9 x 4096 / 4.2 = 869, 29 x 29, and a step over its budget.
    q.recordStepCost("cornell", interactive, QualityStep::Interactive, 1e-3, 2.5e-4);
    const AdaptiveQuality::Plan capped = q.plan("cornell", requested(), none, QualityStep::Final, false, 80);
    EXPECT_EQ(grid(capped.state), 28) << capped.why;
    EXPECT_LE(q.predictStepMs("cornell", capped.state, QualityStep::Final), 900.0);
    // The rest of the frame alone over the budget: no VPL count fits, the step is skipped.
    q.recordStepCost("cornell", interactive, QualityStep::Interactive, 0.02, 1e-4);
    const AdaptiveQuality::Plan skipped = q.plan("cornell", requested(), none, QualityStep::Final, false, 80);
    EXPECT_TRUE(skipped.skip) << skipped.why;
    EXPECT_DOUBLE_EQ(q.vplsForStepMs("cornell", requested(), QualityStep::Final, 900.0), 0.0);
}

TEST(AdaptiveQuality, ASmallestTileOverItsSliceCapsTheStep) {
    AdaptiveQuality q(limits(), presets());
    // With bias compensation the gather cannot render its VPLs in parts: its tiles must fit a slice.
    const nlohmann::json none = {{"ssbc_iterations", 1}};
    const FrameState balanced = q.presetState(requested(), none, QualityStep::Balanced);
    ASSERT_EQ(balanced.techniqueParams.getInt("ssbc_iterations"), 1);
    // Tiles of the balanced step (256 VPLs).
    EXPECT_TRUE(q.recordMinTileCost("cornell", balanced, QualityStep::Balanced, 25.6)) << "first: news";
    EXPECT_FALSE(q.recordMinTileCost("cornell", balanced, QualityStep::Balanced, 28.2)) << "within 20 %";
    EXPECT_FALSE(q.recordMinTileCost("cornell", balanced, QualityStep::Balanced, 10.0)) << "cheaper";
    EXPECT_TRUE(q.recordMinTileCost("cornell", balanced, QualityStep::Balanced, 51.2)) << "much worse";
    const AdaptiveQuality::Plan p = q.plan("cornell", requested(), none, QualityStep::Balanced, false, 80);
    // 51.2 ms at 256 VPLs, linear: 0.8 x 20 ms fits 256 x 16 / 51.2 = 80 VPLs.
    EXPECT_FALSE(p.skip);
    EXPECT_LE(vplEstimate(p.state), 80);
    EXPECT_NE(p.why.find("slice (--slice-ms)"), std::string::npos) << p.why;
}

// hier_isr's traversal costs about leaves^0.4 (TechniqueInfo::vplCostExponent): predictions and caps
// follow that law, not the leaves themselves, or its final step would be predicted at many times
// its cost and capped for nothing.
TEST(AdaptiveQuality, PredictionsAndCapsFollowTheTechniquesCostExponent) {
    FrameState s = makeFrameState(cornell(), "hier_isr");
    s.width = s.height = 256;
    s.techniqueParams.set("hier_coarsest", 1);
    const nlohmann::json hierPresets = {{"techniques",
                                         {{"hier_isr",
                                           {{"interactive", {{"max_depth", 16}}},
                                            {"balanced", {{"max_depth", 64}}},
                                            {"final", {{"max_depth", 256}}}}}}}};
    SessionLimits l = limits();
    l.refineBudgetMs = 1000;
    AdaptiveQuality q(l, hierPresets);
    const nlohmann::json none = nlohmann::json::object();
    const FrameState interactive = q.presetState(s, none, QualityStep::Interactive);
    const FrameState final = q.presetState(s, none, QualityStep::Final);
    ASSERT_EQ(vplEstimate(interactive), 256);
    ASSERT_EQ(vplEstimate(final), 65536);
    q.recordStepCost("cornell", interactive, QualityStep::Interactive, 2e-3); // 131 ms at 256 leaves
    // 256 times the leaves: 256^0.4 = 9.19 times the time, 1.2 s (linear: 33.6 s).
    const double predicted = q.predictStepMs("cornell", final, QualityStep::Final);
    EXPECT_NEAR(predicted, 131.072 * std::pow(256.0, 0.4), 1e-6);
    // Over the 1 s budget: the cap is where the power law meets 0.9 s, 65536 x (900 / 1205)^(1 / 0.4)
    // = 31,593 leaves, so max_depth 128 (16,384); a linear cap would give 1,759 leaves, max_depth 32.
    const AdaptiveQuality::Plan plan = q.plan("cornell", s, none, QualityStep::Final, false, 80);
    EXPECT_FALSE(plan.skip) << plan.why;
    EXPECT_EQ(plan.state.techniqueParams.getInt("max_depth"), 128) << plan.why;
    EXPECT_NE(plan.why.find("--refine-budget-ms"), std::string::npos) << plan.why;

    // A smallest tile over its slice: 64 ms at the balanced step's 4,096 leaves; 0.8 x 20 ms is a
    // quarter of that, (1/4)^(1 / 0.4) x 4,096 = 128 leaves fit (linear: 1,024), so max_depth 8.
    const FrameState balanced = q.presetState(s, {{"ssbc_iterations", 1}}, QualityStep::Balanced);
    ASSERT_EQ(vplEstimate(balanced), 4096);
    EXPECT_TRUE(q.recordMinTileCost("cornell", balanced, QualityStep::Balanced, 64.0));
    // Tiles are compared at equal leaves: 64 ms at 4,096 is 36.8 ms at 1,024, so 30 ms there is no news.
    FrameState fewer = balanced;
    fewer.techniqueParams.set("max_depth", 32);
    EXPECT_FALSE(q.recordMinTileCost("cornell", fewer, QualityStep::Balanced, 30.0)) << "cheaper than 36.8";
    const AdaptiveQuality::Plan tiled =
        q.plan("cornell", s, {{"ssbc_iterations", 1}}, QualityStep::Balanced, false, 80);
    EXPECT_EQ(tiled.state.techniqueParams.getInt("max_depth"), 8) << tiled.why;
    EXPECT_NE(tiled.why.find("slice (--slice-ms)"), std::string::npos) << tiled.why;
}

TEST(AdaptiveQuality, SnapshotsTakeTheBestStepThatFits) {
    AdaptiveQuality q(limits(), presets());
    const nlohmann::json none = nlohmann::json::object();
    const AdaptiveQuality::Plan unknown = q.plan("cornell", requested(), none, QualityStep::Final, true, 80);
    EXPECT_EQ(unknown.step, QualityStep::Interactive) << "nothing measured: the interactive step";
    EXPECT_EQ(unknown.state.width, 256) << "at full size";
    EXPECT_TRUE(unknown.budget.is_null());
    q.recordStepCost("cornell", q.presetState(requested(), none, QualityStep::Balanced),
                     QualityStep::Balanced, 1e-3);
    const AdaptiveQuality::Plan fits = q.plan("cornell", requested(), none, QualityStep::Final, true, 80);
    EXPECT_EQ(fits.step, QualityStep::Final) << "predicted at 262 ms from the balanced step";
    EXPECT_EQ(grid(fits.state), 64);
}

TEST(AdaptiveQuality, InteractiveFramesFollowTheFrameBudget) {
    AdaptiveQuality q(limits(), presets());
    const nlohmann::json none = nlohmann::json::object();
    const AdaptiveQuality::Plan first =
        q.plan("cornell", requested(), none, QualityStep::Interactive, false, 80);
    EXPECT_EQ(first.budgetKey, "cornell/rsm_gather");
    EXPECT_LT(first.scale, 1.0) << "nothing measured: the budget's first guess";
    EXPECT_EQ(first.state.width, static_cast<int>(std::lround(256 * first.scale)));
    EXPECT_EQ(first.budget["target_ms"], 80);

    const AdaptiveQuality::Plan noTarget =
        q.plan("cornell", requested(), none, QualityStep::Interactive, false, 0);
    EXPECT_EQ(noTarget.scale, 1.0) << "the server's interactive scale";
    EXPECT_EQ(noTarget.state.width, 256);
    EXPECT_EQ(noTarget.budget["reason"], "no frame-time target: the server's interactive scale");

    const AdaptiveQuality::Plan fixed = q.plan("cornell", requested(), none, QualityStep::Fixed, false, 80);
    EXPECT_EQ(grid(fixed.state), 8);
    EXPECT_EQ(fixed.state.width, 256);
    EXPECT_EQ(std::string(qualityStepName(fixed.step)), "fixed");
}

} // namespace
} // namespace gis

namespace gis {
namespace {

TEST(AdaptiveQuality, RefinementStepsBudgetTheEnvironmentProbes) {
    AdaptiveQuality q(limits(), presets());
    const nlohmann::json none = nlohmann::json::object();
    const double share = envProbeBudgetMs(80, QualityStep::Interactive);
    EXPECT_DOUBLE_EQ(share, 20.0);
    EXPECT_DOUBLE_EQ(envProbeBudgetMs(80, QualityStep::Final), 80.0);
    EXPECT_DOUBLE_EQ(envProbeBudgetMs(80, QualityStep::Fixed), 0.0);
    const AdaptiveQuality::Plan interactive =
        q.plan("cornell", requested(), none, QualityStep::Interactive, false, 80);
    EXPECT_DOUBLE_EQ(interactive.state.frameParams.getFloat("env_budget_ms"), share);
    EXPECT_DOUBLE_EQ(interactive.budget.at("env_budget_ms").get<double>(), share) << "shown in stats.budget";
    const AdaptiveQuality::Plan balanced =
        q.plan("cornell", requested(), none, QualityStep::Balanced, false, 80);
    EXPECT_DOUBLE_EQ(balanced.state.frameParams.getFloat("env_budget_ms"), share)
        << "the same budget: the probes rendered for interactive frames are kept";
    const AdaptiveQuality::Plan final = q.plan("cornell", requested(), none, QualityStep::Final, false, 80);
    EXPECT_DOUBLE_EQ(final.state.frameParams.getFloat("env_budget_ms"), 80.0)
        << "the final step: within one frame, so that its first tile holds input back no longer";
    const AdaptiveQuality::Plan snapshot =
        q.plan("cornell", requested(), none, QualityStep::Balanced, true, 80);
    EXPECT_DOUBLE_EQ(snapshot.state.frameParams.getFloat("env_budget_ms"), 0.0) << "snapshots as asked";
    const AdaptiveQuality::Plan untargeted =
        q.plan("cornell", requested(), none, QualityStep::Interactive, false, 0);
    EXPECT_DOUBLE_EQ(untargeted.state.frameParams.getFloat("env_budget_ms"), 0.0) << "no target, no budget";

    FrameState asked = requested();
    asked.frameParams.set("env_budget_ms", 500.0);
    const AdaptiveQuality::Plan own =
        q.plan("cornell", asked, {{"env_budget_ms", 500.0}}, QualityStep::Interactive, false, 80);
    EXPECT_DOUBLE_EQ(own.state.frameParams.getFloat("env_budget_ms"), 500.0) << "the client's value wins";
}

TEST(AdaptiveQuality, InteractiveFramesDrawAtTheServersLevelOfDetailUnlessTheClientSetOne) {
    SessionLimits limits;
    limits.interactiveLodPixels = 1.5;
    AdaptiveQuality q(limits, nullptr);
    const nlohmann::json none = nlohmann::json::object();
    const AdaptiveQuality::Plan interactive =
        q.plan("cornell", requested(), none, QualityStep::Interactive, false, 80);
    EXPECT_DOUBLE_EQ(interactive.state.frameParams.getFloat("lod_pixels"), 1.5);
    EXPECT_DOUBLE_EQ(interactive.budget.at("lod_pixels").get<double>(), 1.5) << "shown in stats.budget";
    for (QualityStep step : {QualityStep::Balanced, QualityStep::Final, QualityStep::Fixed})
        EXPECT_DOUBLE_EQ(
            q.plan("cornell", requested(), none, step, false, 80).state.frameParams.getFloat("lod_pixels"),
            0.0)
            << qualityStepName(step) << " draws every triangle";
    EXPECT_DOUBLE_EQ(q.plan("cornell", requested(), none, QualityStep::Interactive, true, 80)
                         .state.frameParams.getFloat("lod_pixels"),
                     0.0)
        << "a snapshot draws every triangle";

    FrameState asked = requested();
    asked.frameParams.set("lod_pixels", 0.0);
    const AdaptiveQuality::Plan own =
        q.plan("cornell", asked, {{"lod_pixels", 0.0}}, QualityStep::Interactive, false, 80);
    EXPECT_DOUBLE_EQ(own.state.frameParams.getFloat("lod_pixels"), 0.0) << "the client's value wins";

    limits.interactiveLodPixels = 0.0;
    AdaptiveQuality off(limits, nullptr);
    EXPECT_DOUBLE_EQ(off.plan("cornell", requested(), none, QualityStep::Interactive, false, 80)
                         .state.frameParams.getFloat("lod_pixels"),
                     0.0);
}

TEST(AdaptiveQuality, EveryLiveStepDrawsTheLightViewsWithinATexelUnlessTheClientSetIt) {
    // The light views are kept while the lights stay: simplified in an interactive frame, they serve the
    // refinement steps after it, which must not draw them again at full detail.
    SessionLimits limits;
    AdaptiveQuality q(limits, nullptr);
    const nlohmann::json none = nlohmann::json::object();
    const auto texels = [](const AdaptiveQuality::Plan& p) {
        return p.state.frameParams.getFloat("light_lod_texels");
    };
    for (QualityStep step : {QualityStep::Interactive, QualityStep::Balanced, QualityStep::Final})
        EXPECT_DOUBLE_EQ(texels(q.plan("cornell", requested(), none, step, false, 80)), kLiveLightLodTexels)
            << qualityStepName(step);
    EXPECT_DOUBLE_EQ(q.plan("cornell", requested(), none, QualityStep::Interactive, false, 80)
                         .budget.at("light_lod_texels")
                         .get<double>(),
                     kLiveLightLodTexels)
        << "shown in stats.budget";
    EXPECT_DOUBLE_EQ(texels(q.plan("cornell", requested(), none, QualityStep::Fixed, false, 80)), 0.0)
        << "a fixed-quality view renders what was asked";
    EXPECT_DOUBLE_EQ(texels(q.plan("cornell", requested(), none, QualityStep::Final, true, 80)), 0.0)
        << "a snapshot draws every triangle";
    FrameState asked = requested();
    asked.frameParams.set("light_lod_texels", 0.0);
    EXPECT_DOUBLE_EQ(
        texels(q.plan("cornell", asked, {{"light_lod_texels", 0.0}}, QualityStep::Balanced, false, 80)), 0.0)
        << "the client's value wins";
    limits.interactiveLodPixels = 0.0;
    AdaptiveQuality off(limits, nullptr);
    EXPECT_DOUBLE_EQ(texels(off.plan("cornell", requested(), none, QualityStep::Interactive, false, 80)), 0.0)
        << "--interactive-lod-px 0 turns the levels off everywhere";
}

} // namespace
} // namespace gis

namespace gis {
namespace {

// The frame budget's receiver cap reaches the technique that has one (multires_gather): a guess for
// the first frame, then from the measured frames, unless the client set the parameter itself; other
// techniques are untouched.
TEST(AdaptiveQuality, InteractiveFramesCapTheGatherAtTwiceTheLastReceiverShare) {
    AdaptiveQuality q(limits(), nullptr);
    const nlohmann::json none = nlohmann::json::object();
    FrameState asked = makeFrameState(cornell(), "multires_gather");
    asked.width = asked.height = 256;
    const AdaptiveQuality::Plan first = q.plan("cornell", asked, none, QualityStep::Interactive, false, 80);
    const double guess = FrameBudget::Config{}.firstReceiverShareCap;
    EXPECT_DOUBLE_EQ(first.state.techniqueParams.getFloat("receiver_share_cap"), guess) << "nothing measured";
    EXPECT_DOUBLE_EQ(first.budget["receiver_share_cap"].get<double>(), guess);

    FrameCost cost;
    cost.pixels = 100 * 100;
    cost.vpls = 256;
    cost.frameMs = 30;
    cost.techniqueMs = 10;
    cost.receiverShare = 0.1;
    // Two frames: the budget does not trust the first one's time (its shaders' compilation).
    q.budget().record(first.budgetKey, cost);
    q.budget().record(first.budgetKey, cost);
    const AdaptiveQuality::Plan next = q.plan("cornell", asked, none, QualityStep::Interactive, false, 80);
    EXPECT_DOUBLE_EQ(next.state.techniqueParams.getFloat("receiver_share_cap"), 0.2);
    EXPECT_DOUBLE_EQ(next.budget["receiver_share_cap"].get<double>(), 0.2);
    for (QualityStep step : {QualityStep::Balanced, QualityStep::Final})
        EXPECT_DOUBLE_EQ(q.plan("cornell", asked, none, step, false, 80)
                             .state.techniqueParams.getFloat("receiver_share_cap"),
                         1.0)
            << qualityStepName(step) << " gathers every VPL";

    FrameState own = asked;
    own.techniqueParams.set("receiver_share_cap", 0.5);
    const AdaptiveQuality::Plan kept =
        q.plan("cornell", own, {{"receiver_share_cap", 0.5}}, QualityStep::Interactive, false, 80);
    EXPECT_DOUBLE_EQ(kept.state.techniqueParams.getFloat("receiver_share_cap"), 0.5) << "the client's wins";
    EXPECT_TRUE(kept.budget["receiver_share_cap"].is_null());

    // The light-tree techniques gather over receivers too.
    for (const char* technique : {"isr", "hier_isr"}) {
        FrameState tree = makeFrameState(cornell(), technique);
        q.budget().record(std::string("cornell/") + technique, cost);
        q.budget().record(std::string("cornell/") + technique, cost);
        EXPECT_DOUBLE_EQ(q.plan("cornell", tree, none, QualityStep::Interactive, false, 80)
                             .state.techniqueParams.getFloat("receiver_share_cap"),
                         0.2)
            << technique;
    }

    // rsm_gather has no receivers to cap, whatever the budget measured under its key.
    q.budget().record("cornell/rsm_gather", cost);
    const AdaptiveQuality::Plan plain =
        q.plan("cornell", requested(), none, QualityStep::Interactive, false, 80);
    EXPECT_FALSE(plain.state.techniqueParams.has("receiver_share_cap"));
    EXPECT_TRUE(plain.budget["receiver_share_cap"].is_null());
}

} // namespace
} // namespace gis

namespace gis {
namespace {

// An interactive frame's receiver cap cuts by the exponent the session's frames measured at the VPLs
// it asks for (FrameState::receiverCapExponent); with none measured there, 0 (the technique's fixed
// one), and refinement steps never carry one.
TEST(AdaptiveQuality, TheReceiverCapCutsByTheExponentMeasuredAtTheAskedVpls) {
    AdaptiveQuality q(limits(), nullptr);
    const nlohmann::json none = nlohmann::json::object();
    FrameState asked = makeFrameState(cornell(), "hier_isr");
    asked.width = asked.height = 64;
    const AdaptiveQuality::Plan first = q.plan("cornell", asked, none, QualityStep::Interactive, false, 80);
    EXPECT_DOUBLE_EQ(first.state.receiverCapExponent, 0.0) << "nothing measured";

    // Cheap frames at the asked leaves, whose traversal grew as leaves^0.13 there.
    const long leaves = vplEstimate(asked);
    FrameCost cost;
    cost.pixels = 64 * 64;
    cost.vpls = leaves;
    cost.gatheredVpls = leaves;
    cost.frameMs = 5;
    cost.passesMs = 5;
    cost.techniqueMs = 2;
    cost.receiverShare = 0.1;
    cost.vplCostExponent = 0.13;
    cost.techniqueParams = first.techniqueParamsKey;
    q.budget().record(first.budgetKey, cost);
    q.budget().record(first.budgetKey, cost);
    const AdaptiveQuality::Plan next = q.plan("cornell", asked, none, QualityStep::Interactive, false, 80);
    ASSERT_EQ(vplEstimate(next.state), leaves) << next.budget.dump();
    EXPECT_DOUBLE_EQ(next.state.receiverCapExponent, 0.13);
    // Under another tau that exponent does not hold: the cap cuts by the technique's fixed one.
    FrameState otherTau = asked;
    otherTau.techniqueParams.set("tau", 0.0);
    const nlohmann::json explicitTau = {{"tau", 0.0}};
    const AdaptiveQuality::Plan changed =
        q.plan("cornell", otherTau, explicitTau, QualityStep::Interactive, false, 80);
    EXPECT_NE(changed.techniqueParamsKey, first.techniqueParamsKey);
    EXPECT_DOUBLE_EQ(changed.state.receiverCapExponent, 0.0) << changed.budget.dump();
    EXPECT_DOUBLE_EQ(q.plan("cornell", asked, none, QualityStep::Final, false, 80).state.receiverCapExponent,
                     0.0);
}

} // namespace
} // namespace gis
