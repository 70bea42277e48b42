// The environment probes' plan under env_budget_ms, from a cost model fed with synthetic
// measurements (render/EnvProbeBudget.h); the GL side is tests/gl/EnvProbeGlTest.cpp.
#include <gtest/gtest.h>

#include <cmath>

#include "render/EnvProbeBudget.h"

namespace gis {
namespace {

TEST(EnvProbeBudget, BeforeAMeasurementTheRoomProbeGoesFirstAtTheSmallSize) {
    EnvProbeCostModel model;
    EXPECT_LT(model.probeMs(128), 0.0);
    // Under a budget, unmeasured probes could take seconds (env_size 512 with 256 samples on a CPU):
    // the room probe alone, at 32 texels, is measured first.
    EnvProbePlan plan = planEnvProbes(128, 4, 20.0, model);
    EXPECT_EQ(plan.size, kEnvPreferredMinSize);
    EXPECT_EQ(plan.probes, 1);
    EXPECT_LT(plan.predictedMs, 0.0);
    EXPECT_NE(plan.reason.find("not measured"), std::string::npos) << plan.reason;
    EXPECT_NE(plan.reason.find("asked: env_size 128, 4 probes"), std::string::npos) << plan.reason;
    plan = planEnvProbes(16, 4, 20.0, model);
    EXPECT_EQ(plan.size, 16) << "a smaller env_size is kept";
    EXPECT_EQ(plan.probes, 1);
    // Without a budget (gi-render, the HTTP API) every probe renders as asked, measured or not.
    plan = planEnvProbes(128, 4, 0.0, model);
    EXPECT_EQ(plan.size, 128);
    EXPECT_EQ(plan.probes, 4);
    model.record(128, 4, 400.0);
    plan = planEnvProbes(128, 4, 0.0, model);
    EXPECT_EQ(plan.size, 128);
    EXPECT_EQ(plan.probes, 4);
    EXPECT_NE(plan.reason.find("no budget"), std::string::npos) << plan.reason;
}

TEST(EnvProbeBudget, OneMeasurementTakesHalfItsCostAsFixed) {
    EnvProbeCostModel model;
    model.record(128, 2, 60.0); // 30 ms a probe
    EXPECT_DOUBLE_EQ(model.probeMs(128), 30.0);
    EXPECT_DOUBLE_EQ(model.probeMs(64), 30.0 * (0.5 + 0.5 / 4));
    EXPECT_DOUBLE_EQ(model.probeMs(256), 30.0 * (0.5 + 0.5 * 4));
    model.record(128, 1, std::nan(""));
    model.record(128, 0, 10.0);
    EXPECT_DOUBLE_EQ(model.probeMs(128), 30.0) << "NaN and empty renders are not measurements";
    model.record(128, 1, 10.0);
    EXPECT_DOUBLE_EQ(model.probeMs(128), 20.0) << "two: their mean";
    model.record(128, 1, 500.0); // one slow frame
    EXPECT_DOUBLE_EQ(model.probeMs(128), 30.0) << "the median";
    for (int i = 0; i < kEnvCostSamples; ++i) model.record(128, 1, 12.0);
    EXPECT_DOUBLE_EQ(model.probeMs(128), 12.0) << "the last few only";
}

TEST(EnvProbeBudget, TwoSizesFitFixedAndPerTexelCosts) {
    EnvProbeCostModel model;
    model.record(32, 1, 12.0);  // 10 + 2e-3 * 1024 ~ 12
    model.record(128, 1, 42.8); // 10 + 2e-3 * 16384 ~ 42.8
    const double perTexel = (42.8 - 12.0) / (128.0 * 128.0 - 32.0 * 32.0);
    const double fixed = 12.0 - perTexel * 32 * 32;
    EXPECT_NEAR(model.probeMs(64), fixed + perTexel * 64 * 64, 1e-9);
    EXPECT_NEAR(model.probeMs(256), fixed + perTexel * 256 * 256, 1e-9);
    EnvProbeCostModel noisy;
    noisy.record(32, 1, 20.0);
    noisy.record(64, 1, 18.0); // cheaper at the larger size: noise, taken as flat
    EXPECT_NEAR(noisy.probeMs(128), 18.0, 1e-9);
    EXPECT_GE(noisy.probeMs(16), 0.0);
}

TEST(EnvProbeBudget, SmallerFacesFirstThenFewerProbesThenTheRoomProbeAlone) {
    EnvProbeCostModel model;
    model.record(32, 1, 12.0);
    model.record(128, 1, 42.8);
    // Everything fits: as asked.
    EnvProbePlan plan = planEnvProbes(128, 3, 200.0, model);
    EXPECT_EQ(plan.size, 128);
    EXPECT_EQ(plan.probes, 3);
    EXPECT_NEAR(plan.predictedMs, 3 * 42.8, 1e-9);
    EXPECT_NE(plan.reason.find("within"), std::string::npos) << plan.reason;
    // Three probes fit at 64 (3 x 18.2 ms) but not at 128.
    plan = planEnvProbes(128, 3, 60.0, model);
    EXPECT_EQ(plan.size, 64);
    EXPECT_EQ(plan.probes, 3);
    EXPECT_LE(plan.predictedMs, 60.0);
    EXPECT_NE(plan.reason.find("asked: env_size 128, 3 probes"), std::string::npos) << plan.reason;
    // Not three even at 32 (36 ms): two at the largest size that fits.
    plan = planEnvProbes(128, 3, 30.0, model);
    EXPECT_EQ(plan.probes, 2);
    EXPECT_EQ(plan.size, 32);
    // The room probe alone below 32 texels.
    plan = planEnvProbes(128, 3, 11.0, model);
    EXPECT_EQ(plan.probes, 1);
    EXPECT_EQ(plan.size, 16);
    EXPECT_LE(plan.predictedMs, 11.0);
    // Nothing fits: the room probe at the smallest size, said so.
    plan = planEnvProbes(128, 3, 1.0, model);
    EXPECT_EQ(plan.probes, 1);
    EXPECT_EQ(plan.size, kEnvMinSize);
    EXPECT_NE(plan.reason.find("over budget"), std::string::npos) << plan.reason;
    // A small env_size is never raised and never halved below kEnvMinSize.
    plan = planEnvProbes(8, 2, 1.0, model);
    EXPECT_EQ(plan.size, 8);
    EXPECT_EQ(plan.probes, 1);
}

} // namespace
} // namespace gis
