#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "session/VplPartPlanner.h"

namespace gis {
namespace {

VplPartPlanner::Limits limits() {
    VplPartPlanner::Limits l;
    l.targetMs = 14;
    l.tilePixels = 4096;
    l.minTilePixels = 256;
    l.maxParts = 4096;
    return l;
}

// A synthetic tile renderer: a part of `pixels` split in `parts` costs fixed + vpl / parts per pixel.
double partMs(double pixels, int parts, double fixedPerPixel, double vplPerPixel) {
    return pixels * (fixedPerPixel + vplPerPixel / parts);
}

// Plans and renders tiles until the plan settles; returns the last plan and its part's cost.
VplPartPlan settle(VplPartPlanner& planner, long vpls, double firstGuess, double fixedPerPixel,
                   double vplPerPixel, double* lastPartMs) {
    VplPartPlan plan;
    for (int tile = 0; tile < 10; ++tile) {
        plan = planner.plan(vpls, firstGuess);
        const double ms = partMs(plan.pixels, plan.parts, fixedPerPixel, vplPerPixel);
        for (int part = 0; part < plan.parts && part < 20; ++part)
            planner.record(plan.pixels, plan.parts, ms);
        *lastPartMs = ms;
    }
    return plan;
}

TEST(VplPartPlanner, FirstPlanSplitsThePredictedVplWork) {
    VplPartPlanner planner(limits());
    // 0.01 ms per pixel unsplit: 41 ms for the 4096-pixel tile, so 3 parts of 14 ms.
    const VplPartPlan plan = planner.plan(1000, 0.01);
    EXPECT_EQ(plan.pixels, 4096);
    EXPECT_EQ(plan.parts, 3);
    // Never more parts than VPLs.
    EXPECT_EQ(planner.plan(2, 0.1).parts, 2);
    EXPECT_EQ(planner.plan(1000, 0.0).parts, 1);
}

TEST(VplPartPlanner, FixedCostsDoNotMultiplyTheParts) {
    // The case that kept 154 parts a tile: 8 ms of fixed work a part, 16 ms of VPL work a tile, and a
    // first guess that said 11 parts.
    VplPartPlanner planner(limits());
    const double fixed = 8.0 / 4096, vpl = 16.0 / 4096;
    double lastMs = 0;
    const VplPartPlan plan = settle(planner, 1600, 11 * 14.0 / 4096, fixed, vpl, &lastMs);
    EXPECT_LE(lastMs, 14.0 * 1.001);
    // ceil(16 / (14 - 8)) = 3 parts; the old rule ended at hundreds.
    EXPECT_GE(plan.parts, 3);
    EXPECT_LE(plan.parts, 4);
    EXPECT_EQ(plan.pixels, 4096);
    double f = 0, v = 0;
    ASSERT_TRUE(planner.fitted(f, v));
    EXPECT_NEAR(f, 8.0, 0.5);
    EXPECT_NEAR(v, 16.0, 1.0);
}

TEST(VplPartPlanner, VplBoundWorkSplitsUntilAPartFits) {
    VplPartPlanner planner(limits());
    const double fixed = 1.0 / 4096, vpl = 400.0 / 4096;
    double lastMs = 0;
    // A first guess ten times too low: the overrun raises the parts.
    const VplPartPlan plan = settle(planner, 100000, 40.0 / 4096, fixed, vpl, &lastMs);
    EXPECT_LE(lastMs, 14.0 * 1.001);
    EXPECT_GE(plan.parts, 31); // 400 / 13
    EXPECT_LE(plan.parts, 34);
}

TEST(VplPartPlanner, FixedWorkOverTheTargetShrinksTheTile) {
    VplPartPlanner planner(limits());
    // 20 ms of fixed work on a full tile: no part count can fit it.
    const double fixed = 20.0 / 4096, vpl = 20.0 / 4096;
    double lastMs = 0;
    const VplPartPlan plan = settle(planner, 1000, 40.0 / 4096, fixed, vpl, &lastMs);
    EXPECT_LT(plan.pixels, 4096);
    EXPECT_GE(plan.pixels, 256);
    EXPECT_LE(lastMs, 14.0 * 1.001);
}

TEST(VplPartPlanner, FixedWorkOverTheTargetInTheSmallestTileKeepsPartsFew) {
    VplPartPlanner planner(limits());
    // 20 ms of fixed work a part whatever the tile's size (costs per pass), 20 ms of VPL work a tile:
    // parts cannot fit the target, so each holds at most 30 % of it in VPL work.
    double lastMs = 0;
    VplPartPlan plan;
    for (int tile = 0; tile < 10; ++tile) {
        plan = planner.plan(1000, 40.0 / 4096);
        lastMs = 20.0 + 20.0 / plan.parts;
        for (int part = 0; part < std::min(plan.parts, 20); ++part)
            planner.record(plan.pixels, plan.parts, lastMs);
    }
    // Shrinking was tried, found futile (the fixed work did not shrink) and undone.
    EXPECT_EQ(plan.pixels, 4096);
    EXPECT_LE(plan.parts, 5); // 20 ms of VPL work in parts of at most 0.3 x 14 ms
    EXPECT_LE(lastMs, 20.0 + 0.3 * 14.0 + 0.5);
}

TEST(VplPartPlanner, ManyPartsComeDownWhenTheyCostLittle) {
    VplPartPlanner planner(limits());
    for (int i = 0; i < 20; ++i) planner.record(4096, 200, 3.0); // 200 parts of 3 ms: over-split
    const VplPartPlan plan = planner.plan(1000, 0.01);
    EXPECT_LT(plan.parts, 200);
    EXPECT_GE(plan.parts, 1);
}

TEST(VplPartPlanner, IgnoresUnusableMeasurements) {
    VplPartPlanner planner(limits());
    planner.record(0, 4, 10.0);
    planner.record(4096, 0, 10.0);
    planner.record(4096, 4, std::nan(""));
    planner.record(4096, 4, -1.0);
    double f = 0, v = 0;
    EXPECT_FALSE(planner.fitted(f, v));
    EXPECT_EQ(planner.plan(1000, 0.01).parts, 3); // still the first guess
}

} // namespace
} // namespace gis

namespace gis {
namespace {

// A step starts from what the last one learned, scaled to its own VPL count: its first plan is the
// settled one (not the prediction's hundreds of parts), and a step with four times the VPLs starts
// with about four times the VPL share per part.
TEST(VplPartPlanner, RemembersItsFitsForTheNextStep) {
    VplPartPlanner first(limits());
    double lastMs = 0;
    // Mostly fixed work (6 ms a part) and a little VPL work (4 ms for the tile's 1600 VPLs).
    const double fixedPerPixel = 6.0 / 4096, vplPerPixel = 4.0 / 4096;
    const VplPartPlan settled = settle(first, 1600, 1.0, fixedPerPixel, vplPerPixel, &lastMs);
    EXPECT_LE(lastMs, 14.0);
    const VplPartPlanner::Memory memory = first.remember(1600);
    ASSERT_FALSE(memory.empty());

    VplPartPlanner fresh(limits());
    const VplPartPlan guessed = fresh.plan(1600, 1.0); // a prediction of 4096 ms for the tile
    EXPECT_GT(guessed.parts, 100);

    VplPartPlanner next(limits());
    next.recall(memory, 1600);
    const VplPartPlan recalled = next.plan(1600, 1.0);
    EXPECT_EQ(recalled.parts, settled.parts);
    EXPECT_EQ(recalled.pixels, settled.pixels);
    double fixedMs = 0, vplMs = 0;
    ASSERT_TRUE(next.fitted(fixedMs, vplMs));
    EXPECT_NEAR(fixedMs, 6.0 * settled.pixels / 4096, 0.05);

    VplPartPlanner bigger(limits());
    bigger.recall(memory, 6400);
    ASSERT_TRUE(bigger.fitted(fixedMs, vplMs));
    EXPECT_NEAR(vplMs, 4.0 * 4.0 * settled.pixels / 4096, 0.2);
    EXPECT_LE(
        partMs(bigger.plan(6400, 1.0).pixels, bigger.plan(6400, 1.0).parts, fixedPerPixel, 4.0 * vplPerPixel),
        14.0 + 1e-9);
}

} // namespace
} // namespace gis

namespace gis {
namespace {

// A tile's first part also draws what its later parts keep (G-buffer, direct light, eye hierarchy):
// the planner tells that extra work from the fixed and VPL work and sizes the parts so that the first
// one fits the target too.
TEST(VplPartPlanner, FirstPartsExtraWorkIsFittedAndTheFirstPartFits) {
    // Full-size tile: 2 ms fixed a part, 5 ms more in the first, 40 ms of VPL work.
    const double fixedMs = 2.0, extraMs = 5.0, vplMs = 40.0;
    auto run = [&](VplPartPlanner& planner, bool markFirst, double& firstMs, double& laterMs) {
        VplPartPlan plan;
        for (int tile = 0; tile < 12; ++tile) {
            plan = planner.plan(4000, 40.0 / 4096);
            const double scale = plan.pixels / 4096;
            laterMs = scale * (fixedMs + vplMs / plan.parts);
            firstMs = laterMs + scale * extraMs;
            planner.record(plan.pixels, plan.parts, firstMs, markFirst);
            for (int part = 1; part < std::min(plan.parts, 20); ++part)
                planner.record(plan.pixels, plan.parts, laterMs);
        }
        return plan;
    };
    double firstMs = 0, laterMs = 0;
    VplPartPlanner planner(limits());
    const VplPartPlan plan = run(planner, true, firstMs, laterMs);
    EXPECT_EQ(plan.pixels, 4096);
    EXPECT_EQ(plan.parts, 6); // ceil(40 / (14 - 2 - 5))
    EXPECT_LE(firstMs, 14.0);
    double f = 0, v = 0, e = 0;
    ASSERT_TRUE(planner.fitted(f, v, &e));
    EXPECT_NEAR(e, extraMs, 1e-6);
    EXPECT_NEAR(f, fixedMs, 1e-6);
    EXPECT_NEAR(v, vplMs, 1e-6);

    // Without telling first parts apart, the extra work is averaged in and the first part overruns.
    VplPartPlanner averaging(limits());
    double averagedFirstMs = 0;
    run(averaging, false, averagedFirstMs, laterMs);
    EXPECT_GT(averagedFirstMs, 14.0);

    // The next step starts from the same fit, extra work included.
    const VplPartPlanner::Memory memory = planner.remember(4000);
    ASSERT_EQ(memory.firstExtra.size(), 1u);
    VplPartPlanner next(limits());
    next.recall(memory, 4000);
    double e2 = 0;
    ASSERT_TRUE(next.fitted(f, v, &e2));
    EXPECT_NEAR(e2, extraMs, 1e-6);
    EXPECT_EQ(next.plan(4000, 1.0).parts, 6);
}

// Whole tiles (one part each, so every part is a first part) fit as before: no extra work is
// inferred without later parts to compare with.
TEST(VplPartPlanner, WholeTilesInferNoExtraWork) {
    VplPartPlanner planner(limits());
    for (int i = 0; i < 4; ++i) {
        planner.record(4096, 1, 20.0, true);
        planner.record(4096, 4, 8.0, true); // a first part only: no later part of 4 to compare
    }
    double f = 0, v = 0, e = -1;
    ASSERT_TRUE(planner.fitted(f, v, &e));
    EXPECT_EQ(e, 0.0);
    EXPECT_NEAR(f, 4.0, 1e-6); // 20 = f + v, 8 = f + v / 4
    EXPECT_NEAR(v, 16.0, 1e-6);
}

} // namespace
} // namespace gis
