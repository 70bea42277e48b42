// The planner on the built-in scenes, without GL: each decision flips between a scene (or view) that
// calls for the effect and one that does not.
#include <gtest/gtest.h>

#include "effects/EffectPlan.h"
#include "frame/FrameState.h"
#include "scene/SceneLoader.h"

namespace {

using gis::EffectPlan;
using gis::FrameState;

struct Planned {
    gis::Scene scene;
    FrameState state;
    EffectPlan plan;
};

/// Plans `scene` with the `ssbc` technique (it has every knob) plus overrides, at 128x128.
Planned plan(const std::string& scene, const nlohmann::json& params = nlohmann::json::object(),
             void (*edit)(FrameState&) = nullptr) {
    Planned p{gis::makeBuiltinScene(scene), {}, {}};
    p.state = gis::makeFrameState(p.scene, "ssbc");
    p.state.width = p.state.height = 128;
    gis::applyParams(p.state, params, "test");
    if (edit) edit(p.state);
    p.plan = gis::planEffects(p.scene, p.state);
    return p;
}

const gis::EffectDecision& decision(const EffectPlan& plan, const std::string& effect) {
    const gis::EffectDecision* d = plan.find(effect);
    EXPECT_NE(d, nullptr) << effect;
    static const gis::EffectDecision none;
    return d ? *d : none;
}

TEST(EffectPlan, OcclusionOnlyWithOccluders) {
    const Planned boxes = plan("cornell"), empty = plan("cornell-empty");
    EXPECT_TRUE(decision(boxes.plan, "occlusion").enabled) << decision(boxes.plan, "occlusion").reason;
    EXPECT_GT(decision(boxes.plan, "occlusion").value, 0.01);
    EXPECT_FALSE(decision(empty.plan, "occlusion").enabled) << decision(empty.plan, "occlusion").reason;
    EXPECT_LT(decision(empty.plan, "occlusion").value, 1e-3); // a convex box occludes nothing
}

TEST(EffectPlan, BounceOffWithBlackWalls) {
    const Planned white = plan("cornell-empty"), black = plan("cornell-black");
    EXPECT_TRUE(decision(white.plan, "indirect").enabled);
    EXPECT_FALSE(decision(black.plan, "indirect").enabled) << decision(black.plan, "indirect").reason;
    EXPECT_TRUE(decision(black.plan, "direct").enabled); // the walls are still lit
    // Without the bounce nothing depends on it.
    EXPECT_FALSE(decision(black.plan, "compensation").enabled);
}

TEST(EffectPlan, CompensationFollowsTheClamp) {
    const Planned tight = plan("crease", {{"clamp_b", 8.0}}), loose = plan("crease", {{"clamp_b", 4000.0}});
    EXPECT_TRUE(decision(tight.plan, "compensation").enabled) << decision(tight.plan, "compensation").reason;
    EXPECT_FALSE(decision(loose.plan, "compensation").enabled) << decision(loose.plan, "compensation").reason;
    EXPECT_GT(decision(tight.plan, "compensation").value, decision(loose.plan, "compensation").value);
    const Planned off = plan("crease", {{"clamp_b", 0.0}});
    EXPECT_FALSE(decision(off.plan, "compensation").enabled);
    EXPECT_FALSE(decision(off.plan, "compensation").available);
}

TEST(EffectPlan, LightPointingAwayTurnsEverythingOff) {
    const Planned away = plan("crease", nlohmann::json::object(), [](FrameState& s) {
        s.lights.at(0).light.direction = {0.0f, 1.0f, 0.0f};
    });
    for (const char* e : {"direct", "indirect", "occlusion", "compensation"})
        EXPECT_FALSE(decision(away.plan, e).enabled) << e << ": " << decision(away.plan, e).reason;
    EXPECT_EQ(away.plan.vpls, 0);
    EXPECT_TRUE(decision(plan("crease").plan, "direct").enabled);
}

TEST(EffectPlan, ManualChangesNothingAutoApplies) {
    Planned p = plan("cornell-empty");
    FrameState manual = p.state;
    gis::applyEffectPlan(manual, p.plan);
    EXPECT_EQ(gis::paramsJson(manual), gis::paramsJson(p.state));
    EXPECT_EQ(manual.technique, "ssbc");
    EXPECT_FALSE(manual.plan.is_null());

    Planned a = plan("cornell-black", {{"effects", "auto"}, {"vpl_shadows", true}});
    FrameState applied = a.state;
    gis::applyEffectPlan(applied, a.plan);
    EXPECT_EQ(applied.technique, "none"); // no bounce: the indirect passes are skipped

    Planned b = plan("cornell-empty", {{"effects", "auto"}, {"vpl_shadows", true}});
    gis::applyEffectPlan(b.state, b.plan);
    EXPECT_EQ(b.state.technique, "ssbc");
    EXPECT_FALSE(b.state.techniqueParams.getBool("vpl_shadows"));
    EXPECT_EQ(b.state.techniqueParams.getInt("ssbc_iterations"), 1);
}

TEST(EffectPlan, ForcedStateWinsAndIsShown) {
    Planned p = plan("cornell-empty", {{"effect_occlusion", "on"}, {"effect_compensation", "off"}});
    const auto& occ = decision(p.plan, "occlusion");
    EXPECT_TRUE(occ.enabled);
    EXPECT_TRUE(occ.forced);
    EXPECT_TRUE(occ.applied); // forced applies even with effects = manual
    EXPECT_FALSE(decision(p.plan, "indirect").applied);
    gis::applyEffectPlan(p.state, p.plan);
    EXPECT_TRUE(p.state.techniqueParams.getBool("vpl_shadows"));
    EXPECT_EQ(p.state.techniqueParams.getInt("ssbc_iterations"), 0);
    const nlohmann::json j = gis::toJson(p.plan);
    EXPECT_EQ(j["decisions"][2]["effect"], "occlusion");
    EXPECT_EQ(j["decisions"][2]["forced"], true);
    EXPECT_NE(gis::describe(p.plan).find("forced on"), std::string::npos);
}

TEST(EffectPlan, AStopEndsThePlanWithoutDecisions) {
    gis::Scene scene = gis::makeBuiltinScene("cornell");
    FrameState state = gis::makeFrameState(scene, "ssbc");
    state.width = state.height = 128;
    const EffectPlan whole = gis::planEffects(scene, state);
    int asked = 0;
    gis::EffectPlanOptions never;
    never.stop = [&] {
        ++asked;
        return false;
    };
    const EffectPlan unstopped = gis::planEffects(scene, state, never);
    EXPECT_FALSE(unstopped.stopped);
    EXPECT_EQ(gis::toJson(unstopped)["decisions"], gis::toJson(whole)["decisions"]);
    EXPECT_GE(asked, whole.receivers / gis::kPlanStopEvery - 1) << "asked through the bounce estimate";
    int left = 3;
    gis::EffectPlanOptions third;
    third.stop = [&] { return --left <= 0; };
    const EffectPlan stopped = gis::planEffects(scene, state, third);
    EXPECT_TRUE(stopped.stopped);
    EXPECT_TRUE(stopped.decisions.empty());
    EXPECT_EQ(left, 0) << "it ended at the first true";
}

TEST(EffectPlan, Deterministic) {
    const Planned a = plan("cornell"), b = plan("cornell");
    EXPECT_EQ(gis::toJson(a.plan)["decisions"], gis::toJson(b.plan)["decisions"]);
}

} // namespace

// The multiresolution start follows the view's discontinuity density: the Cornell box's edges split
// every 16^2 patch, so refinement starts at 32^2; a view filled by the flat back wall keeps even 4^2
// patches whole, so it starts there. Other techniques get no levels decision.
TEST(EffectPlan, MultiresLevelsFollowTheDiscontinuityDensity) {
    auto multires = [](const std::string& scene, void (*edit)(FrameState&), const char* mode) {
        Planned p{gis::makeBuiltinScene(scene), {}, {}};
        p.state = gis::makeFrameState(p.scene, "multires_splat");
        p.state.width = p.state.height = 256;
        gis::applyParams(p.state, {{"effects", mode}}, "test");
        if (edit) edit(p.state);
        p.plan = gis::planEffects(p.scene, p.state);
        return p;
    };
    const Planned box = multires("cornell", nullptr, "auto");
    EXPECT_EQ(decision(box.plan, "levels").value, 32.0) << decision(box.plan, "levels").reason;
    const Planned wall = multires(
        "cornell-empty",
        [](FrameState& s) {
            s.camera.position = {0.0f, 1.0f, -0.5f}; // half a metre from the back wall, looking at it
            s.camera.target = {0.0f, 1.0f, -1.0f};
        },
        "auto");
    EXPECT_EQ(decision(wall.plan, "levels").value, 4.0) << decision(wall.plan, "levels").reason;

    FrameState applied = box.state;
    gis::applyEffectPlan(applied, box.plan);
    EXPECT_EQ(applied.techniqueParams.getInt("coarsest_size"), 32);
    const Planned manual = multires("cornell", nullptr, "manual");
    FrameState untouched = manual.state;
    gis::applyEffectPlan(untouched, manual.plan);
    EXPECT_EQ(untouched.techniqueParams.getInt("coarsest_size"), 16) << "manual mode only reports";
    EXPECT_EQ(plan("cornell").plan.find("levels"), nullptr) << "ssbc has no eye hierarchy";
}
