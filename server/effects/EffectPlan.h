// Effect planning: decides per scene and view which lighting effects are worth simulating, from cheap
// Embree ray measurements of the same scene, view and light the GL pipeline renders, and maps the
// decisions onto the pipeline's existing knobs (applyEffectPlan). Details and measurements:
// docs/effects.md.
//
// Effects and the knob each one drives:
//   direct        the lights at all (FrameLight::enabled); off only when they light nothing
//                 that reaches the view, directly or after one bounce
//   indirect      the technique's indirect passes (technique `none` when off)
//   occlusion     indirect visibility (`vpl_shadows`, where the technique has it)
//   compensation  bias compensation of the clamp (`ssbc_iterations` 1 vs 0, where the technique has
//                 it and `clamp_b` > 0)
//
// Every measurement except `direct` is an estimated relative RMSE (the metric of
// analysis/Metrics.h) that switching the effect off would add against a one-bounce ground truth:
// sqrt(sum_i |delta_i|^2) / sqrt(sum_i |truth_i|^2) over receivers sampled through the image. An
// effect whose estimate is below its threshold is planned off.
//
// Lives in its own library (gis::effects) beside the metrics because it needs the reference layer's
// RayScene and the render layer's FrameState, while the metrics library must stay core-only; the
// renderer never calls it (render sits below reference), so callers plan, apply and pass the JSON
// on through FrameState::plan for the stats.
//
// Threading: pure functions on the calling thread; planEffects builds its own BVH unless it is given
// one (a session keeps its scene's, built on a thread of its own).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "frame/FrameState.h"
#include "scene/Scene.h"

namespace gis {
namespace reference {
class RayScene;
}

struct EffectDecision {
    std::string effect;      ///< "direct", "indirect", "occlusion", "compensation"
    bool enabled = true;     ///< the decision (forced or measured)
    bool forced = false;     ///< the user forced it with effect_<name> = on/off
    bool applied = false;    ///< applyEffectPlan acts on it (forced, or `effects` = auto)
    bool available = true;   ///< the technique has a knob for it
    std::string reason;      ///< one sentence: why, with the numbers
    std::string measurement; ///< what `value` is
    double value = 0.0;      ///< the measurement behind the decision
    double threshold = 0.0;  ///< on iff value > threshold (unless forced)
    double costMs = 0.0;     ///< estimated frame time of the effect when on (llvmpipe model)
};

struct EffectPlanOptions {
    int viewSamples = 1024;           ///< receivers, stratified over the image
    int vplSamples = 192;             ///< light paths, stratified over the spot cone
    std::uint64_t seed = 1;           ///< deterministic: same inputs, same plan
    double indirectThreshold = 0.005; ///< estimated relative RMSE of dropping the bounce
    double occlusionThreshold = 0.005;
    double compensationThreshold = 0.005;
    /// Asked every kPlanStopEvery receivers of the bounce estimate (most of a plan's time): true
    /// ends the plan there, marked `stopped` (a refinement step's plan that input interrupts).
    std::function<bool()> stop;
};
/// Receivers between two questions to EffectPlanOptions::stop: 1,024 receivers x 192 light paths
/// took 17.8-27.3 ms on the built-in scenes (two cores), so about 1 ms a question.
constexpr int kPlanStopEvery = 64;

struct EffectPlan {
    std::string mode = "manual"; ///< the frame parameter `effects`
    std::vector<EffectDecision> decisions;
    int receivers = 0;  ///< view samples that hit a surface
    int vpls = 0;       ///< light samples that hit a surface
    long long rays = 0; ///< rays traced
    double analysisMs = 0.0;
    /// EffectPlanOptions::stop ended it early: no decision is made, the plan must not be used.
    bool stopped = false;
    /// The lights the frame renders (id) and those it skips with the reason (LightSetModel::skipped):
    /// a skipped light's shadow-map and RSM passes do not run.
    std::vector<std::string> lightsRendered, lightsSkipped;

    const EffectDecision* find(std::string_view effect) const;
    /// The decision for `effect`; true when it is unknown.
    bool enabled(std::string_view effect) const;
};

/// Measures and decides. Reads the frame parameters `effects` and `effect_<name>` of `state` for the
/// forced states. Never throws for a valid FrameState (an empty view or a dark light plans effects
/// off with a reason).
EffectPlan planEffects(const Scene& scene, const FrameState& state, const EffectPlanOptions& options = {});
/// The same with the scene's ray structure built once and kept (RayScene(scene), flattened instances
/// and all; its build is most of a plan on a big scene: 0.5-0.8 s at 2M triangles, against a few
/// milliseconds of rays). `rays` must be built from `scene`; queries are thread-safe.
EffectPlan planEffects(const Scene& scene, const reference::RayScene& rays, const FrameState& state,
                       const EffectPlanOptions& options = {});

/// Maps the applied decisions onto `state`'s knobs (see the table at the top) and stores the plan's
/// JSON in state.plan. With `effects` = manual and nothing forced it changes only state.plan.
void applyEffectPlan(FrameState& state, const EffectPlan& plan);

nlohmann::json toJson(const EffectPlan& plan);
/// A fixed-width table for `gi-render --explain`.
std::string describe(const EffectPlan& plan);

} // namespace gis
