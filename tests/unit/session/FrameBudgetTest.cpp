#include <cmath>

#include <gtest/gtest.h>

#include "session/AdaptiveQuality.h"
#include "session/FrameBudget.h"

namespace gis {
namespace {

// A synthetic renderer: ms = pixels * (base + pixels-independent VPL part) like a gather.
FrameCost synthetic(double pixels, long vpls, double basePerPixel, double perPixelVpl) {
    FrameCost c;
    c.pixels = pixels;
    c.vpls = vpls;
    c.techniqueMs = pixels * static_cast<double>(vpls) * perPixelVpl;
    c.frameMs = pixels * basePerPixel + c.techniqueMs;
    c.encodeMs = 0.0;
    return c;
}

// hier_isr's leaves under a cap of `cap` (its limitVpls): a power of four.
long leavesUnder(long cap) {
    long side = 1;
    while ((side * 2) * (side * 2) <= cap) side *= 2;
    return side * side;
}

// Runs the loop choose -> render -> record a few times and returns the settled choice.
BudgetChoice settle(FrameBudget& budget, long vpls, double fullPixels, double base, double perVpl,
                    double* lastMs = nullptr) {
    BudgetChoice choice;
    for (int i = 0; i < 12; ++i) {
        choice = budget.choose("k", vpls, true, fullPixels);
        const double pixels = fullPixels * choice.scale * choice.scale;
        const long rendered = choice.vplCap > 0 ? choice.vplCap : vpls;
        const FrameCost cost = synthetic(pixels, rendered, base, perVpl);
        if (lastMs) *lastMs = cost.frameMs;
        budget.record("k", cost);
    }
    return choice;
}

TEST(FrameBudget, FirstFrameIsSmallAndSaysWhy) {
    FrameBudget budget(FrameBudget::Config{});
    const BudgetChoice c = budget.choose("k", 65536, true, 960 * 800);
    EXPECT_LE(c.scale, 0.35);
    EXPECT_EQ(c.vplCap, 1024);
    EXPECT_NE(c.reason.find("nothing measured"), std::string::npos);
}

TEST(FrameBudget, TheFirstFramesTimeIsNotTrusted) {
    FrameBudget budget(FrameBudget::Config{});
    const double full = 960 * 800;
    const BudgetChoice first = budget.choose("k", 4096, true, full);
    const double pixels = full * first.scale * first.scale;
    // The first frame compiled its shaders: eight times what the same frame costs after.
    FrameCost compiled = synthetic(pixels, first.vplCap, 1e-4, 1e-8);
    const FrameCost warm = compiled;
    compiled.frameMs *= 8;
    compiled.techniqueMs *= 8;
    budget.record("k", compiled);
    const BudgetChoice second = budget.choose("k", 4096, true, full);
    EXPECT_DOUBLE_EQ(second.scale, first.scale) << "another small frame, not a fifth of the size";
    EXPECT_EQ(second.vplCap, first.vplCap);
    EXPECT_NE(second.reason.find("second frame"), std::string::npos) << second.reason;
    budget.record("k", warm);
    EXPECT_DOUBLE_EQ(budget.predictMs("k", pixels, first.vplCap), warm.frameMs)
        << "the second replaces the first";
    const BudgetChoice third = budget.choose("k", 4096, true, full);
    EXPECT_GT(third.scale, first.scale) << third.reason;
}

TEST(FrameBudget, TheFirstFramesPassesPredictTheSecond) {
    FrameBudget budget(FrameBudget::Config{});
    const double full = 960 * 800;
    const BudgetChoice first = budget.choose("k", 65536, true, full);
    const double pixels = full * first.scale * first.scale;
    // hier_isr at tau 0 on cornell: the first frame's passes took 238 ms, its whole time 343 ms
    // (compiling); at the same size and VPLs the next took 205 ms. A dear first frame must not be
    // followed by another as dear.
    FrameCost compiled = synthetic(pixels, first.vplCap, 1e-4, 2e-6);
    const FrameCost warm = compiled;
    compiled.passesMs = warm.frameMs;
    compiled.frameMs = warm.frameMs + 105.0;
    ASSERT_GT(warm.frameMs, 150.0);
    budget.record("k", compiled);
    EXPECT_NEAR(budget.predictMs("k", pixels, first.vplCap), warm.frameMs, 1e-9)
        << "the first frame counts by its passes";
    const BudgetChoice second = budget.choose("k", 65536, true, full);
    EXPECT_NE(second.reason.find("first one's passes"), std::string::npos) << second.reason;
    EXPECT_GT(second.predictedMs, 0.0);
    EXPECT_LE(second.predictedMs, 80.0) << second.reason;
    ASSERT_GT(second.vplCap, 0);
    EXPECT_LT(second.vplCap, first.vplCap) << second.reason;
    const double secondPixels = full * second.scale * second.scale;
    EXPECT_LE(synthetic(secondPixels, second.vplCap, 1e-4, 2e-6).frameMs, 80.0);

    // Untimed passes (0) leave the rule before: the second frame is the first's guess again.
    FrameBudget untimed(FrameBudget::Config{});
    untimed.choose("k", 65536, true, full);
    FrameCost noPasses = compiled;
    noPasses.passesMs = 0;
    untimed.record("k", noPasses);
    const BudgetChoice guess = untimed.choose("k", 65536, true, full);
    EXPECT_DOUBLE_EQ(guess.scale, first.scale);
    EXPECT_EQ(guess.vplCap, first.vplCap);
}

TEST(FrameBudget, CheapFramesGetFullQuality) {
    FrameBudget budget(FrameBudget::Config{});
    double ms = 0;
    const BudgetChoice c = settle(budget, 256, 512 * 512, 1e-5, 1e-9, &ms);
    EXPECT_DOUBLE_EQ(c.scale, 1.0);
    EXPECT_EQ(c.vplCap, 0);
    EXPECT_LE(ms, 80.0);
}

TEST(FrameBudget, ResolutionGoesFirstThenVpls) {
    FrameBudget budget(FrameBudget::Config{});
    double ms = 0;
    // 256 VPLs at 768k pixels cost 4 ns per pixel and VPL (llvmpipe's gather): 800 ms at full size.
    BudgetChoice c = settle(budget, 256, 960 * 800, 2e-5, 4e-6, &ms);
    EXPECT_LE(ms, 80.0 * 1.05);
    EXPECT_GE(c.scale, 0.3 - 1e-9);
    // 65,536 VPLs: the size alone cannot do it; the VPLs are capped.
    FrameBudget big(FrameBudget::Config{});
    c = settle(big, 65536, 960 * 800, 2e-5, 4e-6, &ms);
    EXPECT_LE(ms, 80.0 * 1.05);
    EXPECT_GT(c.vplCap, 0);
    EXPECT_LT(c.vplCap, 65536);
    EXPECT_NE(c.reason.find("VPLs"), std::string::npos);
}

TEST(FrameBudget, ImpossibleTargetsGiveTheCheapestFrameAndSayIt) {
    FrameBudget::Config config;
    config.targetMs = 1.0;
    FrameBudget budget(config);
    const BudgetChoice c = settle(budget, 256, 960 * 800, 1e-3, 1e-6);
    EXPECT_DOUBLE_EQ(c.scale, config.minScale);
    EXPECT_NE(c.reason.find("over the"), std::string::npos);
}

TEST(FrameBudget, NoisyMeasurementsDoNotFlicker) {
    FrameBudget budget(FrameBudget::Config{});
    settle(budget, 256, 960 * 800, 2e-5, 4e-6);
    int changes = 0;
    double previous = -1;
    for (int i = 0; i < 40; ++i) {
        const BudgetChoice c = budget.choose("k", 256, true, 960 * 800);
        if (previous >= 0 && c.scale != previous) ++changes;
        previous = c.scale;
        const double pixels = 960.0 * 800.0 * c.scale * c.scale;
        FrameCost cost = synthetic(pixels, c.vplCap > 0 ? c.vplCap : 256, 2e-5, 4e-6);
        cost.frameMs *= i % 2 ? 1.08 : 0.92; // +-8 % noise
        cost.techniqueMs *= i % 2 ? 1.08 : 0.92;
        budget.record("k", cost);
    }
    EXPECT_LE(changes, 6);
}

// hier_isr's traversal: its cap is max_depth, a power-of-two side (so a cap of 52 leaves renders 16),
// and its time grows as about leaves^0.4 (the cut below that depth), not linearly. Scaled to what it
// measured at 288 x 240 on cornell (the rest of the frame 22 ms, the gather 87.6 ms at 65,536
// leaves): modelled linearly, a capped frame predicts every larger count far too dear and the cap
// stays where a first cheap frame put it; with the exponent the budget settles near the target.
TEST(FrameBudget, ASublinearCostLiftsTheCapToTheTarget) {
    const double fullPixels = 960.0 * 800.0;
    const double base = 22.0 / (288.0 * 240.0);                             // ms per pixel
    const double perUnit = 87.6 / (288.0 * 240.0 * std::pow(65536.0, 0.4)); // ms per pixel per leaf^0.4
    auto run = [&](double modelExponent, double* lastMs) {
        FrameBudget budget(FrameBudget::Config{});
        BudgetChoice c;
        for (int i = 0; i < 16; ++i) {
            c = budget.choose("k", 65536, true, fullPixels);
            const double pixels = fullPixels * c.scale * c.scale;
            const long leaves = c.vplCap > 0 ? leavesUnder(c.vplCap) : 65536;
            FrameCost cost;
            cost.pixels = pixels;
            cost.vpls = leaves;
            cost.techniqueMs = pixels * std::pow(static_cast<double>(leaves), 0.4) * perUnit;
            cost.frameMs = pixels * base + cost.techniqueMs;
            cost.vplCostExponent = modelExponent;
            *lastMs = cost.frameMs;
            budget.record("k", cost);
        }
        return c;
    };
    double linearMs = 0, sublinearMs = 0;
    const BudgetChoice linear = run(1.0, &linearMs);
    const BudgetChoice sublinear = run(0.4, &sublinearMs);
    const long linearLeaves = linear.vplCap > 0 ? leavesUnder(linear.vplCap) : 65536;
    const long sublinearLeaves = sublinear.vplCap > 0 ? leavesUnder(sublinear.vplCap) : 65536;
    EXPECT_LE(sublinearMs, 80.0 * 1.05) << sublinear.reason;
    EXPECT_GE(sublinearMs, 80.0 * 0.6)
        << "the frame uses the target, not a fraction of it: " << sublinear.reason;
    EXPECT_GE(sublinearLeaves, 16 * linearLeaves)
        << "linear model: " << linear.reason << " (" << linearMs << " ms); sublinear: " << sublinear.reason;
}

// hier_isr's exponent is measured near each frame (frameVplCostExponent), so it changes from frame
// to frame: the VPL rate carries over (the last frame's VPLs predicted as before), the means are not
// started again (which sent every frame back to the first frame's guess).
TEST(FrameBudget, AnExponentMeasuredPerFrameCarriesTheRateOver) {
    FrameBudget budget(FrameBudget::Config{});
    FrameCost cost = synthetic(288 * 240, 256, 2e-4, 2e-6);
    cost.passesMs = cost.frameMs;
    cost.vplCostExponent = 1.0;
    budget.record("k", cost);
    budget.record("k", cost);
    const double before = budget.predictMs("k", 288 * 240, 256);
    ASSERT_GT(before, 0.0);
    cost.vplCostExponent = 0.2;
    budget.record("k", cost);
    EXPECT_NEAR(budget.predictMs("k", 288 * 240, 256), before, 1e-9 * before);
    EXPECT_NEAR(budget.vplPassesMs("k", 288 * 240, 1024), cost.techniqueMs * std::pow(4.0, 0.2),
                1e-9 * cost.techniqueMs)
        << "more VPLs at the new exponent";
    const BudgetChoice next = budget.choose("k", 65536, true, 960 * 800);
    EXPECT_EQ(next.reason.find("first frame"), std::string::npos) << next.reason;
    EXPECT_EQ(next.reason.find("second frame"), std::string::npos) << next.reason;
}

// A technique that names its VPL passes (TechniqueInfo::vplPasses): only they grow with the VPLs,
// its other passes cost per pixel. With all of them counted as VPL-bound, a frame whose eye
// hierarchy and upsampling dwarf its gather (hier_isr's at 16 leaves: 12 ms against 4) predicts the
// next level of leaves at four times all of it.
TEST(FrameBudget, OnlyTheVplPassesGrowWithTheVpls) {
    const double pixels = 288 * 240;
    FrameCost cost;
    cost.pixels = pixels;
    cost.vpls = 16;
    cost.techniqueMs = 16.0; // eye hierarchy and upsampling 12 ms, gather 4 ms
    cost.vplPassesMs = 4.0;
    cost.frameMs = 30.0;
    cost.passesMs = 30.0;
    FrameBudget named(FrameBudget::Config{});
    named.record("k", cost);
    named.record("k", cost);
    EXPECT_NEAR(named.predictMs("k", pixels, 16), 30.0, 1e-9);
    EXPECT_NEAR(named.predictMs("k", pixels, 64), 30.0 + 3 * 4.0, 1e-9);
    EXPECT_NEAR(named.vplPassesMs("k", pixels, 64), 16.0, 1e-9);
    cost.vplPassesMs = -1; // not named: the whole technique grows
    FrameBudget unnamed(FrameBudget::Config{});
    unnamed.record("k", cost);
    unnamed.record("k", cost);
    EXPECT_NEAR(unnamed.predictMs("k", pixels, 64), 30.0 + 3 * 16.0, 1e-9);
}

// A cap renders what the technique's knob leaves of it (hier_isr's leaves go in fours): the
// candidates are predicted at that. Predicted at the cap itself, 311 "VPLs" over a frame measured at
// 256 leaves looked 1.2x dearer than the 256 leaves they render, and the frame fell to 64.
TEST(FrameBudget, CandidatesArePredictedAtTheVplsTheTechniqueRenders) {
    const double full = 960 * 800, pixels = full * 0.3 * 0.3;
    FrameCost cost;
    cost.pixels = pixels;
    cost.vpls = 256;
    cost.frameMs = 74.0;
    cost.passesMs = 74.0;
    cost.techniqueMs = 54.0;
    cost.vplPassesMs = 54.0;
    FrameBudget quantised(FrameBudget::Config{}), plain(FrameBudget::Config{});
    for (FrameBudget* b : {&quantised, &plain}) {
        b->record("k", cost);
        b->record("k", cost);
    }
    const BudgetChoice q = quantised.choose("k", 65536, true, full, {}, leavesUnder);
    EXPECT_DOUBLE_EQ(q.scale, 0.3);
    EXPECT_EQ(q.vplCap, 256) << q.reason;
    EXPECT_NEAR(q.predictedMs, 74.0, 1e-9);
    const BudgetChoice p = plain.choose("k", 65536, true, full);
    EXPECT_LT(leavesUnder(p.vplCap), 256) << p.reason;
}

// The exponent each frame measured is kept by the VPLs it gathered from (the receiver cap's cut,
// when it cut): what the next cap at those VPLs cuts by.
TEST(FrameBudget, ExponentsAreKeptByTheVplsGathered) {
    FrameBudget budget(FrameBudget::Config{});
    EXPECT_EQ(budget.exponentAt("k", 65536, ""), 0.0);
    FrameCost cost = synthetic(288 * 240, 65536, 2e-4, 1e-9);
    cost.gatheredVpls = 65536;
    cost.vplCostExponent = 0.13;
    budget.record("k", cost);
    EXPECT_DOUBLE_EQ(budget.exponentAt("k", 65536, ""), 0.13);
    cost.gatheredVpls = 256; // the cap cut it to 256 leaves, where the traversal grows faster
    cost.vplCostExponent = 0.85;
    budget.record("k", cost);
    EXPECT_DOUBLE_EQ(budget.exponentAt("k", 256, ""), 0.85);
    EXPECT_DOUBLE_EQ(budget.exponentAt("k", 65536, ""), 0.13);
    EXPECT_EQ(budget.exponentAt("k", 1024, ""), 0.0);
    EXPECT_EQ(budget.exponentAt("other", 65536, ""), 0.0);
    // Under other technique parameters (another tau) the exponents measured before do not hold: none
    // is given for them, and a frame under them forgets the old ones.
    const std::string otherTau = R"({"tau":0.0})";
    EXPECT_EQ(budget.exponentAt("k", 256, otherTau), 0.0);
    cost.techniqueParams = otherTau;
    cost.gatheredVpls = 4096;
    cost.vplCostExponent = 0.98;
    budget.record("k", cost);
    EXPECT_DOUBLE_EQ(budget.exponentAt("k", 4096, otherTau), 0.98);
    EXPECT_EQ(budget.exponentAt("k", 256, otherTau), 0.0);
    EXPECT_EQ(budget.exponentAt("k", 256, ""), 0.0);
    EXPECT_EQ(budget.exponentAt("k", 4096, ""), 0.0);

    const nlohmann::json stats = {
        {"frame_ms", 10.0},
        {"technique_ms", 5.0},
        {"params", {{"receiver_share_cap", 0.2}}},
        {"counts", {{"receivers_total", 500.0}, {"receiver_share_capped_vpls", 256.0}}}};
    EXPECT_EQ(FrameCost::ofFrame(stats, 50, 20, 65536, 0.85).gatheredVpls, 256);
    EXPECT_EQ(FrameCost::ofFrame({{"frame_ms", 10.0}}, 50, 20, 65536, 0.13).gatheredVpls, 65536);
}

TEST(FrameBudget, GarbageMeasurementsAreIgnored) {
    FrameBudget budget(FrameBudget::Config{});
    FrameCost bad;
    bad.pixels = 0;
    bad.frameMs = 10;
    budget.record("k", bad);
    bad.pixels = 100;
    bad.frameMs = std::numeric_limits<double>::quiet_NaN();
    budget.record("k", bad);
    EXPECT_EQ(budget.predictMs("k", 1000, 16), 0.0);
}

} // namespace
} // namespace gis

namespace gis {
namespace {

// The gather's work cap follows the last frame's work share (receivers per pixel, times the share of
// the VPLs a cap left it): twice it, within [kMinReceiverShareCap, 1]; none before a frame with
// receivers was measured.
TEST(FrameBudget, TheReceiverCapIsTwiceTheLastFramesWorkShare) {
    EXPECT_DOUBLE_EQ(receiverShareCapAfter(0.1, false), 0.2);
    EXPECT_DOUBLE_EQ(receiverShareCapAfter(0.001, false), kMinReceiverShareCap);
    EXPECT_DOUBLE_EQ(receiverShareCapAfter(0.7, false), 1.0);
    EXPECT_DOUBLE_EQ(receiverShareCapAfter(-1.0, false), 1.0);
    EXPECT_DOUBLE_EQ(receiverShareCapAfter(std::nan(""), false), 1.0);
    EXPECT_DOUBLE_EQ(receiverShareCapAfter(0.1, true), 0.125) << "a cut frame's cap grows by a quarter";
    EXPECT_DOUBLE_EQ(receiverShareCapAfter(0.001, true), kMinReceiverShareCap);

    FrameBudget budget(FrameBudget::Config{});
    EXPECT_DOUBLE_EQ(budget.choose("k", 4096, true, 960 * 800).receiverShareCap,
                     FrameBudget::Config{}.firstReceiverShareCap)
        << "nothing measured: a guess, kept small";
    FrameCost cost = synthetic(300 * 250, 4096, 2e-4, 1e-8);
    cost.passesMs = cost.frameMs;
    budget.record("k", cost);
    EXPECT_EQ(budget.choose("k", 4096, true, 960 * 800).receiverShareCap, 0.0) << "no receivers";
    cost.receiverShare = 0.03;
    budget.record("k", cost);
    BudgetChoice choice = budget.choose("k", 4096, true, 960 * 800);
    EXPECT_DOUBLE_EQ(choice.receiverShareCap, 0.06);
    EXPECT_DOUBLE_EQ(choice.toJson(80, 4096)["receiver_share_cap"].get<double>(), 0.06);
    // The last frame's, not a mean: a view with many receivers lifts the cap at once.
    cost.receiverShare = 0.3;
    budget.record("k", cost);
    EXPECT_DOUBLE_EQ(budget.choose("k", 4096, true, 960 * 800).receiverShareCap, 0.6);
    // Another key has its own.
    EXPECT_DOUBLE_EQ(budget.choose("other", 4096, true, 960 * 800).receiverShareCap,
                     FrameBudget::Config{}.firstReceiverShareCap);
    EXPECT_TRUE(BudgetChoice{}.toJson(80, 4096)["receiver_share_cap"].is_null());
}

} // namespace
} // namespace gis

namespace gis {
namespace {

TEST(FrameBudget, AFramesCostComesFromItsStats) {
    const nlohmann::json plain = {
        {"frame_ms", 40.0}, {"technique_ms", 25.0}, {"counts", {{"pixels", 20000}}}};
    FrameCost c = FrameCost::ofFrame(plain, 200, 100, 4096, 1.0);
    EXPECT_DOUBLE_EQ(c.pixels, 20000);
    EXPECT_EQ(c.vpls, 4096);
    EXPECT_DOUBLE_EQ(c.frameMs, 40.0);
    EXPECT_DOUBLE_EQ(c.techniqueMs, 25.0);
    EXPECT_LT(c.receiverShare, 0.0) << "no receivers";

    const nlohmann::json listed = {
        {"frame_ms", 40.0}, {"technique_ms", 25.0}, {"counts", {{"receivers_total", 2000}}}};
    EXPECT_DOUBLE_EQ(FrameCost::ofFrame(listed, 200, 100, 4096, 1.0).receiverShare, 0.1);

    // Cut to a 1 x 1 grid of the 4 x 4 asked for under a cap of 0.1 with 0.8 of the pixels receivers:
    // it did the cap's work per pixel and asked VPL (so the next cap is twice it, not twice a sixteenth
    // of 0.8, which a 4 x 4 grid would round down to one VPL again), and counts the VPLs asked for.
    const nlohmann::json capped = {
        {"frame_ms", 40.0},
        {"technique_ms", 25.0},
        {"params", {{"receiver_share_cap", 0.1}}},
        {"counts", {{"receivers_total", 16000}, {"receiver_share_capped_vpls", 1}}}};
    c = FrameCost::ofFrame(capped, 200, 100, 16, 1.0);
    EXPECT_EQ(c.vpls, 16);
    EXPECT_DOUBLE_EQ(c.receiverShare, 0.1);
    EXPECT_TRUE(c.receiverCut);
    nlohmann::json uncut = capped;
    uncut["counts"].erase("receiver_share_capped_vpls");
    EXPECT_DOUBLE_EQ(FrameCost::ofFrame(uncut, 200, 100, 16, 1.0).receiverShare, 0.8)
        << "a cap it stayed under";
    EXPECT_LT(FrameCost::ofFrame(nlohmann::json::object(), 0, 0, 0, 1.0).receiverShare, 0.0);
}

} // namespace
} // namespace gis

namespace gis {
namespace {

TEST(FrameBudget, AFrameOverItsReceiverCapSaysSoInItsBudget) {
    BudgetChoice choice;
    choice.receiverShareCap = 0.04;
    choice.reason = "0.50 of the size meet the 80 ms target";
    nlohmann::json budget = choice.toJson(80, 4096);
    const nlohmann::json uncapped = {{"counts", {{"receivers_total", 500}}}};
    nlohmann::json same = budget;
    noteReceiverCap(same, uncapped, 100, 100);
    EXPECT_EQ(same, budget) << "nothing to say";

    const nlohmann::json capped = {
        {"counts", {{"receivers_total", 4200}, {"receiver_share_capped_vpls", 361}}}};
    noteReceiverCap(budget, capped, 100, 100);
    EXPECT_EQ(budget["receiver_capped_vpls"], 361);
    EXPECT_EQ(
        budget["reason"],
        "0.50 of the size meet the 80 ms target; this view's receivers (42% of the pixels) exceed the 4% "
        "cap set from the last frame: 361 of 4096 VPLs gathered");
}

} // namespace
} // namespace gis

namespace gis {
namespace {

// The budget and the receiver cap together, on a synthetic multiresolution gather: a light view (1%
// of the pixels receivers) then a heavy one (42%, the atrium from inside). The first heavy frame costs
// at most about twice the light frames' gather; within a dozen frames the view renders again near
// the target (none over 1.2x of it on the way) with at least the budget's 16 VPLs (the rounded cap
// once stalled at one VPL here).
TEST(FrameBudget, AJumpInReceiversIsAbsorbedWithoutAStallOrACollapse) {
    constexpr double kFull = 960 * 800, kTarget = 80;
    constexpr double kFixedPerPixel = 2e-4, kEyePerPixel = 1e-4, kPerPair = 2e-6; // ms
    FrameBudget budget(FrameBudget::Config{});
    auto frame = [&](double share, long askedGrid) {
        const BudgetChoice choice = budget.choose("k", askedGrid * askedGrid, true, kFull);
        const double pixels = kFull * choice.scale * choice.scale;
        // The budget's VPL cap and then the technique's receiver cap, as the live view applies them
        // (AdaptiveQuality::planInteractive, EyeHierarchy::capVplsToReceivers).
        const TechniqueInfo& info = findTechniqueInfo("multires_gather");
        ParamSet params(info.params);
        params.set("vpl_grid", askedGrid);
        if (choice.vplCap > 0) info.limitVpls(params, choice.vplCap);
        const long asked = params.getInt("vpl_grid");
        const double cap = choice.receiverShareCap > 0 ? choice.receiverShareCap : 1.0;
        info.capReceiverShare(params, cap);
        capVplsForReceivers(info, params, asked * asked, pixels, share * pixels);
        const long grid = params.getInt("vpl_grid");
        const double technique =
            pixels * kEyePerPixel + kPerPair * share * pixels * static_cast<double>(grid * grid);
        nlohmann::json counts = {{"receivers_total", share * pixels}};
        if (grid < asked) counts["receiver_share_capped_vpls"] = grid * grid;
        const nlohmann::json stats = {{"frame_ms", pixels * kFixedPerPixel + technique},
                                      {"technique_ms", technique},
                                      {"params", {{"receiver_share_cap", cap}}},
                                      {"counts", counts}};
        budget.record("k", FrameCost::ofFrame(stats, 1, static_cast<int>(pixels), asked * asked, 1.0));
        return std::pair{stats["frame_ms"].get<double>(), grid * grid};
    };
    double lightMs = 0;
    for (int i = 0; i < 15; ++i) lightMs = frame(0.01, 64).first;
    ASSERT_LE(lightMs, kTarget * 1.05);
    const auto [firstHeavyMs, firstVpls] = frame(0.42, 64);
    EXPECT_LE(firstHeavyMs, 2.5 * lightMs) << "the cap holds the jump";
    EXPECT_LT(firstVpls, 4096);
    double ms = 0;
    long vpls = 0;
    double worst = firstHeavyMs;
    for (int i = 0; i < 12; ++i) {
        std::tie(ms, vpls) = frame(0.42, 64);
        worst = std::max(worst, ms);
    }
    EXPECT_LE(worst, 1.2 * kTarget)
        << "while the cap still cuts, the budget keeps the frames near the target "
           "(a cap doubling after cut frames gave 196 ms here, and 105 ms with the prediction grown alike)";
    EXPECT_LE(ms, kTarget * 1.05);
    EXPECT_GE(vpls, 16) << "the cap must not strand the view at one VPL";
    EXPECT_GT(ms, kTarget * 0.5) << "nor the budget far below its target";
}

// A light drag at large maps: a renderer whose frames cost pixels x base plus, when they draw the
// light views, their texels at a fixed rate per map kind (shadow maps; RSMs with what is built on them).
struct LightDragRenderer {
    double shadowPerTexel = 2e-6, rsmPerTexel = 4e-5; // ms
    double base = 1e-4;                               // ms per pixel
    FrameCost frame(double pixels, int shadowSide, int rsmSide, bool drawn) const {
        FrameCost c;
        c.pixels = pixels;
        c.frameMs = pixels * base;
        c.lightViews = 1;
        if (drawn) {
            c.drewLightViews = true;
            c.shadowTexels = double(shadowSide) * shadowSide;
            c.rsmTexels = double(rsmSide) * rsmSide;
            c.shadowMs = c.shadowTexels * shadowPerTexel;
            c.rsmMs = c.rsmTexels * rsmPerTexel;
            c.frameMs += c.shadowMs + c.rsmMs;
        }
        return c;
    }
};

TEST(FrameBudget, LightViewsAtTheDefaultsAreNeverCapped) {
    FrameBudget budget(FrameBudget::Config{});
    const LightDragRenderer r;
    const LightViewAsk defaults{1024, 256, true};
    for (int i = 0; i < 6; ++i) {
        const BudgetChoice c = budget.choose("k", 0, false, 960 * 800, defaults);
        EXPECT_EQ(c.shadowSideCap, 0);
        EXPECT_EQ(c.rsmSideCap, 0);
        EXPECT_TRUE(c.toJson(80, 0)["light_view_cap"].is_null());
        budget.record("k", r.frame(960 * 800 * c.scale * c.scale, 1024, 256, true));
    }
}

TEST(FrameBudget, UnmeasuredLargeLightViewsStartAtTheDefaultsSides) {
    FrameBudget budget(FrameBudget::Config{});
    const BudgetChoice c = budget.choose("k", 0, false, 960 * 800, LightViewAsk{4096, 1024, true});
    EXPECT_EQ(c.shadowSideCap, 1024);
    EXPECT_EQ(c.rsmSideCap, 256);
    EXPECT_NE(c.reason.find("not measured yet"), std::string::npos) << c.reason;
    // A technique that reads no RSM: only the shadow maps are capped.
    const BudgetChoice noRsm = budget.choose("k", 0, false, 960 * 800, LightViewAsk{4096, 1024, false});
    EXPECT_EQ(noRsm.shadowSideCap, 1024);
    EXPECT_EQ(noRsm.rsmSideCap, 0);
    EXPECT_TRUE(noRsm.toJson(80, 0)["light_view_cap"]["rsm_side"].is_null());
}

TEST(FrameBudget, ALightDragAtLargeMapsKeepsTheSizeAndCapsTheDearerMap) {
    const LightDragRenderer r;
    const LightViewAsk large{4096, 1024, true};
    const double full = 960 * 800;
    // At the defaults, a drag: 1024^2 x 2e-6 = 2.1 ms of shadow maps, 256^2 x 4e-5 = 2.6 ms of RSMs.
    FrameBudget budget(FrameBudget::Config{});
    BudgetChoice c;
    for (int i = 0; i < 8; ++i) {
        c = budget.choose("k", 0, false, full, LightViewAsk{1024, 256, true});
        budget.record("k", r.frame(full * c.scale * c.scale, 1024, 256, true));
    }
    const double defaultScale = c.scale;
    // rsm_size 1024 and shadow_map_size 4096 asked: 33.6 + 41.9 ms at their full sides, over the
    // 28 ms share of an 80 ms target. The RSMs cost more per map: halved first, to 512 (10.5 ms); then
    // the shadow maps to 2048 (8.4 ms): 18.9 ms.
    double lastMs = 0;
    for (int i = 0; i < 8; ++i) {
        c = budget.choose("k", 0, false, full, large);
        ASSERT_GT(c.shadowSideCap, 0) << c.reason;
        const FrameCost cost = r.frame(full * c.scale * c.scale, c.shadowSideCap, c.rsmSideCap, true);
        lastMs = cost.frameMs;
        budget.record("k", cost);
    }
    EXPECT_EQ(c.rsmSideCap, 512);
    EXPECT_EQ(c.shadowSideCap, 2048);
    EXPECT_EQ(c.shadowSideAsked, 4096);
    EXPECT_EQ(c.rsmSideAsked, 1024);
    EXPECT_NEAR(c.lightViewMs, 18.9, 0.1);
    EXPECT_LE(lastMs, 80.0);
    EXPECT_NE(c.reason.find("RSMs 512 of 1024"), std::string::npos) << c.reason;
    // The pixels pay for what the light views leave of the target, not for all of it: the size
    // stays within a few ladder steps of the drag at the defaults' (without the light views'
    // own rates it fell to the smallest).
    EXPECT_GE(c.scale, 0.8 * defaultScale);
    const nlohmann::json j = c.toJson(80, 0)["light_view_cap"];
    EXPECT_EQ(j["shadow_side"], 2048);
    EXPECT_EQ(j["rsm_side_asked"], 1024);
    // Frames that keep their maps (an orbit after the drag) are predicted without them, and climb.
    budget.record("k", r.frame(full * c.scale * c.scale, 2048, 512, false));
    const BudgetChoice orbit = budget.choose("k", 0, false, full, large);
    EXPECT_GT(orbit.scale, c.scale);
    EXPECT_LE(orbit.predictedMs, 80.0);
}

TEST(FrameBudget, AFrameSaidToDrawItsLightViewsIsPredictedWithThem) {
    const LightDragRenderer r;
    const double full = 960 * 800;
    FrameBudget budget(FrameBudget::Config{});
    LightViewAsk large{4096, 1024, true};
    BudgetChoice c;
    for (int i = 0; i < 8; ++i) { // a drag: the rates of both maps measured
        c = budget.choose("k", 0, false, full, large);
        budget.record("k", r.frame(full * c.scale * c.scale, c.shadowSideCap, c.rsmSideCap, true));
    }
    for (int i = 0; i < 4; ++i) { // an orbit after it: the maps kept
        c = budget.choose("k", 0, false, full, large);
        budget.record("k", r.frame(full * c.scale * c.scale, c.shadowSideCap, c.rsmSideCap, false));
    }
    const BudgetChoice orbit = budget.choose("k", 0, false, full, large);
    // The first frame of the next drag, or the answer to a changed light parameter: after an orbit's
    // frames, only the session's word says that this one draws the maps again.
    large.redraw = LightViewAsk::Redraw::Yes;
    const BudgetChoice drag = budget.choose("k", 0, false, full, large);
    EXPECT_LT(drag.scale, orbit.scale);
    EXPECT_LE(drag.predictedMs, 80.0);
    EXPECT_GE(drag.predictedMs, drag.lightViewMs);
    // And after a drag's frame, a frame said to keep them is predicted without them.
    budget.record("k", r.frame(full * drag.scale * drag.scale, drag.shadowSideCap, drag.rsmSideCap, true));
    large.redraw = LightViewAsk::Redraw::No;
    EXPECT_GT(budget.choose("k", 0, false, full, large).scale, drag.scale);
}

TEST(FrameBudget, TheLightViewsCostComesFromTheirPasses) {
    const nlohmann::json stats = {{"frame_ms", 100.0},
                                  {"technique_ms", 50.0},
                                  {"counts", nlohmann::json::object()},
                                  {"lighting", {{"views", 2}, {"shadow_side", 1024}, {"rsm_side", 512}}},
                                  {"passes",
                                   {{{"name", "shadow_map"}, {"gpu_ms", 8.0}},
                                    {{"name", "rsm"}, {"gpu_ms", 6.0}},
                                    {{"name", "rsm_flux"}, {"gpu_ms", 2.0}},
                                    {{"name", "light_tree"}, {"gpu_ms", 10.0}},
                                    {{"name", "vpl_gather"}, {"gpu_ms", 40.0}}}}};
    const FrameCost c = FrameCost::ofFrame(stats, 100, 100, 0, 1.0, {"light_tree"});
    EXPECT_TRUE(c.drewLightViews);
    EXPECT_EQ(c.lightViews, 2);
    EXPECT_DOUBLE_EQ(c.shadowTexels, 2.0 * 1024 * 1024);
    EXPECT_DOUBLE_EQ(c.shadowMs, 8.0);
    EXPECT_DOUBLE_EQ(c.rsmTexels, 2.0 * 512 * 512);
    EXPECT_DOUBLE_EQ(c.rsmMs, 18.0);
    EXPECT_DOUBLE_EQ(c.lightViewTechniqueMs, 10.0);
    EXPECT_DOUBLE_EQ(c.passesMs, 66.0);
    EXPECT_LT(c.vplPassesMs, 0.0) << "no VPL passes named";
    // The session's: hier_isr's VPL passes (light_tree, vpl_gather) from the same stats.
    EXPECT_DOUBLE_EQ(vplPassesMs("hier_isr", stats), 50.0);
    // Kept maps: nothing drawn, whatever passes ran.
    nlohmann::json kept = stats;
    kept["counts"]["light_views_reused"] = 2;
    EXPECT_FALSE(FrameCost::ofFrame(kept, 100, 100, 0, 1.0, {"light_tree"}).drewLightViews);
    // The pixels' rate leaves the light views out: 100 ms - 40 ms of technique - 26 ms of light views.
    FrameBudget budget(FrameBudget::Config{});
    budget.record("k", c);
    budget.record("k", c);
    EXPECT_NEAR(budget.predictMs("k", 100 * 100, 0), 74.0, 1e-9);
}

} // namespace
} // namespace gis
