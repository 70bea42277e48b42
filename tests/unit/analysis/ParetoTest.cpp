#include <cmath>

#include <gtest/gtest.h>

#include "analysis/Pareto.h"
#include "analysis/SweepGrid.h"
#include "core/Error.h"

namespace {

using gis::TradeoffPoint;

TEST(Pareto, KeepsOnlyUndominatedPointsOrderedByTime) {
    std::vector<TradeoffPoint> pts = {{10, 0.5}, {20, 0.3}, {15, 0.6}, {40, 0.1}, {30, 0.3}, {5, 0.9}};
    auto front = gis::paretoFront(pts);
    EXPECT_EQ(front, (std::vector<std::size_t>{5, 0, 1, 3}));
}

TEST(Pareto, DuplicatesKeepTheFirst) {
    std::vector<TradeoffPoint> pts = {{10, 0.5}, {10, 0.5}, {10, 0.4}};
    EXPECT_EQ(gis::paretoFront(pts), (std::vector<std::size_t>{2}));
    EXPECT_TRUE(gis::paretoFront({}).empty());
}

TEST(Pareto, KneeIsTheBendOfTheFront) {
    // A sharp bend at 20 ms: far below the chord from (1, 1) to (1000, 0.01) in log-log space.
    std::vector<TradeoffPoint> front = {{1, 1}, {20, 0.02}, {100, 0.015}, {1000, 0.01}};
    EXPECT_EQ(gis::kneeOfFront(front), 1u);
    EXPECT_EQ(gis::kneeOfFront({{1, 1}}), 0u);
    EXPECT_EQ(gis::kneeOfFront({{1, 1}, {2, 0.5}}), 1u);
}

TEST(Pareto, PresetsFollowTheBudget) {
    std::vector<TradeoffPoint> front = {{5, 0.9}, {30, 0.2}, {80, 0.1}, {300, 0.05}};
    auto c = gis::choosePresets(front, 100);
    EXPECT_EQ(c.interactive, 2u);
    EXPECT_EQ(c.final, 3u);
    EXPECT_GE(c.balanced, c.interactive);
    EXPECT_LE(c.balanced, c.final);
    // Nothing within the budget: the fastest point.
    EXPECT_EQ(gis::choosePresets(front, 1).interactive, 0u);
}

// Differences within the noise do not buy a slower preset: of points equally accurate within the
// tolerance the fastest is chosen, for final and interactive alike.
TEST(Pareto, PresetsIgnoreDifferencesWithinTheNoise) {
    const std::vector<gis::TradeoffPoint> front = {
        {10, 0.30}, {40, 0.105}, {90, 0.100}, {400, 0.098}, {2000, 0.097}};
    const auto exact = gis::choosePresets(front, 100);
    EXPECT_EQ(exact.final, 4u);
    EXPECT_EQ(exact.interactive, 2u);
    const auto tolerant = gis::choosePresets(front, 100, 0.01);
    EXPECT_EQ(tolerant.final, 1u);       // 0.105 is within 0.01 of 0.097
    EXPECT_EQ(tolerant.interactive, 1u); // 0.105 is within 0.01 of 0.100
    EXPECT_GE(tolerant.balanced, tolerant.interactive);
    EXPECT_LE(tolerant.balanced, tolerant.final);
    // A tolerance below every gap changes nothing; a non-finite one is treated as none.
    EXPECT_EQ(gis::choosePresets(front, 100, 0.0005).final, 4u);
    EXPECT_EQ(gis::choosePresets(front, 100, std::nan("")).final, 4u);
    // A final budget: the most accurate point within it, of equals the fastest.
    EXPECT_EQ(gis::choosePresets(front, 100, 0, 500).final, 3u);
    EXPECT_EQ(gis::choosePresets(front, 100, 0.0025, 500).final, 2u);
    EXPECT_EQ(gis::choosePresets(front, 100, 0, 5).final, 0u); // none fits: the fastest
    EXPECT_LE(gis::choosePresets(front, 100, 0, 5).interactive, gis::choosePresets(front, 100, 0, 5).final);
}

gis::ParamTable table() {
    using gis::ParamType;
    return gis::ParamTable(
        {{.name = "count", .type = ParamType::Int, .defaultValue = 4, .min = 1, .max = 16},
         {.name = "mode", .type = ParamType::Enum, .defaultValue = 0, .options = {"a", "b", "c"}},
         {.name = "on", .type = ParamType::Bool, .defaultValue = 1}});
}

TEST(SweepGrid, DefaultFirstThenOneKnobAtATimeWalkingOutward) {
    auto grid = gis::oneAtATimeGrid(table(), 4);
    ASSERT_FALSE(grid.empty());
    EXPECT_TRUE(grid[0].knob.empty());
    EXPECT_EQ(grid[0].params["count"], 4);
    // count: sweep values 1, 6, 11, 16 -> above the default ascending, then below descending.
    std::vector<int> counts;
    for (const auto& p : grid)
        if (p.knob == "count") counts.push_back(p.value.get<int>());
    EXPECT_EQ(counts, (std::vector<int>{6, 11, 16, 1}));
    int modes = 0, ons = 0;
    for (const auto& p : grid) {
        if (p.knob == "mode") ++modes;
        if (p.knob == "on") {
            ++ons;
            EXPECT_EQ(p.params["on"], false);
            EXPECT_EQ(p.params["count"], 4); // the other knobs stay at their defaults
        }
    }
    EXPECT_EQ(modes, 2); // every option but the default
    EXPECT_EQ(ons, 1);
}

TEST(SweepGrid, KnobsRestrictAndUnknownKnobsAreNamed) {
    auto grid = gis::oneAtATimeGrid(table(), 3, {"mode"});
    EXPECT_EQ(grid.size(), 3u);
    try {
        gis::oneAtATimeGrid(table(), 3, {"cuont"});
        FAIL();
    } catch (const gis::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("cuont"), std::string::npos);
    }
    EXPECT_EQ(gis::describeChanges(table(), grid[1].params), "mode=b");
    EXPECT_EQ(gis::describeChanges(table(), grid[0].params), "defaults");
}

} // namespace

namespace {

// The service's default: the most accurate interactive preset within the budget; within the noise,
// the more accurate final preset, then the faster. The first case is the 128 x 128 rerun's
// (docs/accuracy-texels.md): multires_gather's 64^2 VPLs against hier_isr's hier_coarsest 1.
TEST(DefaultTechnique, NoiseTiesGoToTheMoreAccurateFinalThenTheFaster) {
    const double noise = 0.0139;
    const gis::TechniquePresets gather{{91.8, 0.2244}, {387.2, 0.1716}};
    const gis::TechniquePresets traversal{{78.5, 0.2183}, {120.0, 0.2089}};
    EXPECT_EQ(gis::chooseDefaultTechnique({gather, traversal}, 100, noise), 0);
    EXPECT_EQ(gis::chooseDefaultTechnique({traversal, gather}, 100, noise), 1) << "independent of the order";
    // Finals within the noise of each other: the faster interactive preset.
    const gis::TechniquePresets traversalBetterFinal{{78.5, 0.2183}, {120.0, 0.1800}};
    EXPECT_EQ(gis::chooseDefaultTechnique({gather, traversalBetterFinal}, 100, noise), 1);
    // An interactive error lower beyond the noise wins whatever the finals.
    const gis::TechniquePresets clearlyBetter{{95.0, 0.1900}, {300.0, 0.2500}};
    EXPECT_EQ(gis::chooseDefaultTechnique({gather, clearlyBetter}, 100, noise), 1);
    // Over the budget: not a candidate; none within it: -1.
    EXPECT_EQ(gis::chooseDefaultTechnique({clearlyBetter, gather}, 92, noise), 1);
    EXPECT_EQ(gis::chooseDefaultTechnique({gather, clearlyBetter}, 50, noise), -1);
    // Without noise the lower error wins outright.
    EXPECT_EQ(gis::chooseDefaultTechnique({gather, traversal}, 100, 0.0), 1);
}

} // namespace
