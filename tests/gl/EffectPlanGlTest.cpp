// The effect plan in the GL pipeline: where the planner leaves every effect on, the frame is the
// everything-on frame bit for bit; where it switches effects off, the frame stays within 1% relative
// RMSE of the everything-on frame (each threshold is 0.5%), and the stats carry the plan.
#include <cmath>

#include "GlTestSupport.h"
#include "effects/EffectPlan.h"

using namespace gis;
using test::badValues;
using test::counter;
using test::relativeRmseOf;

namespace {

constexpr int kSize = 64;

/// Relative RMSE of a against b over RGB (linear RGBA frames).

struct Pair {
    FrameOutput all, planned;
    FrameState plannedState;
};

/// Everything on: `ssbc` (clamp_b 40, one compensation step) with VPL visibility.
Pair renderBoth(const std::string& sceneName) {
    const nlohmann::json everything = {{"vpl_shadows", true}};
    Pair p;
    p.all = test::renderScene(sceneName, "ssbc", kSize, kSize, everything);
    const Scene& scene = *test::sharedRenderer().scene();
    FrameState state = makeFrameState(scene, "ssbc");
    state.width = state.height = kSize;
    applyParams(state, everything, "test");
    applyParams(state, {{"effects", "auto"}}, "test");
    applyEffectPlan(state, planEffects(scene, state));
    p.plannedState = state;
    p.planned = test::sharedRenderer().render(state, true);
    return p;
}

TEST(EffectPlanGl, AllOnPlanIsTheEverythingOnFrame) {
    const Pair p = renderBoth("builtin:cornell");
    EXPECT_EQ(p.plannedState.technique, "ssbc");
    EXPECT_EQ(p.planned.linear, p.all.linear);
    ASSERT_TRUE(p.planned.stats.contains("plan"));
    EXPECT_EQ(p.planned.stats["plan"]["mode"], "auto");
    EXPECT_FALSE(p.all.stats.contains("plan")); // no plan made, none reported
}

TEST(EffectPlanGl, DroppedEffectsStayWithinOnePercent) {
    for (const char* scene : {"builtin:cornell-empty", "builtin:cornell-black"}) {
        const Pair p = renderBoth(scene);
        const bool changed =
            p.plannedState.technique == "none" || !p.plannedState.techniqueParams.getBool("vpl_shadows");
        EXPECT_TRUE(changed) << scene << ": the plan should drop an effect";
        EXPECT_LT(relativeRmseOf(p.planned, p.all), 0.01) << scene;
    }
}

} // namespace
