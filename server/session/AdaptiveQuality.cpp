#include "session/AdaptiveQuality.h"

#include <algorithm>
#include <cmath>

#include "core/Error.h"
#include "frame/Presets.h"
#include "frame/VplBudget.h"
#include "gi/Catalog.h"

namespace gis {
namespace {

FrameBudget::Config budgetConfig(const SessionLimits& limits) {
    FrameBudget::Config budget;
    budget.targetMs = limits.frameTargetMs;
    budget.maxScale = std::clamp(limits.interactiveScale, 0.05, 1.0);
    budget.preferredMinScale = std::min(budget.preferredMinScale, budget.maxScale);
    budget.minScale = std::min(budget.minScale, budget.preferredMinScale);
    budget.firstScale = std::min(budget.firstScale, budget.maxScale);
    return budget;
}

QualityStep lower(QualityStep step) {
    return static_cast<QualityStep>(static_cast<int>(step) - 1);
}

} // namespace

const char* qualityStepName(QualityStep step) {
    switch (step) {
    case QualityStep::Interactive:
        return "interactive";
    case QualityStep::Balanced:
        return "balanced";
    case QualityStep::Final:
        return "final";
    case QualityStep::Fixed:
        break;
    }
    return "fixed";
}

AdaptiveQuality::AdaptiveQuality(const SessionLimits& limits, nlohmann::json presets)
    : mLimits(limits), mPresets(std::move(presets)), mBudget(budgetConfig(limits)) {}

std::string AdaptiveQuality::stepKey(const std::string& sceneName, const FrameState& state,
                                     QualityStep step) {
    return sceneName + "/" + state.technique + "/" + std::to_string(static_cast<int>(step));
}

FrameState AdaptiveQuality::presetState(const FrameState& requested, const nlohmann::json& explicitParams,
                                        QualityStep step) const {
    if (mPresets.is_null() || step == QualityStep::Fixed) return requested;
    try {
        FrameState preset = requested;
        preset.techniqueParams.resetToDefaults();
        applyPreset(preset, mPresets, qualityStepName(step));
        nlohmann::json techniqueExplicit = nlohmann::json::object();
        for (const auto& [k, v] : explicitParams.items())
            if (preset.techniqueParams.has(k)) techniqueExplicit[k] = v;
        preset.techniqueParams.apply(techniqueExplicit);
        if (vplEstimate(preset) <= mLimits.maxVpls) return preset;
    } catch (const InputError&) {
        // No preset for this technique: the step renders the parameters as they are.
    }
    return requested;
}

namespace {

// A technique's passes cost about vpls^e (TechniqueInfo::vplCostExponent): 1 for a sum over every VPL,
// less for a traversal such as hier_isr's, whose cost grows far more slowly than its leaves.
double vplCostExponent(const FrameState& state) {
    return usableVplCostExponent(findTechniqueInfo(state.technique).vplCostExponent);
}

// The VPLs at which a cost of `costMs` at `vpls` falls to `targetMs`, under that power law.
double vplsForCost(double vpls, double costMs, double targetMs, double exponent) {
    if (!(costMs > 0.0) || !(targetMs > 0.0)) return vpls;
    return vpls * std::pow(targetMs / costMs, 1.0 / exponent);
}

} // namespace

double vplPassesMs(const std::string& technique, const nlohmann::json& stats) {
    const TechniqueInfo& info = findTechniqueInfo(technique);
    if (info.vplPasses.empty()) return -1.0;
    double ms = 0.0;
    const nlohmann::json passes = stats.value("passes", nlohmann::json::array());
    for (const nlohmann::json& pass : passes) {
        if (!pass.is_object()) continue;
        const std::string name = pass.value("name", std::string());
        if (std::find(info.vplPasses.begin(), info.vplPasses.end(), name) == info.vplPasses.end()) continue;
        const nlohmann::json& gpu = pass.contains("gpu_ms") ? pass["gpu_ms"] : nlohmann::json();
        const double t = gpu.is_number() ? gpu.get<double>() : pass.value("cpu_ms", 0.0);
        if (std::isfinite(t) && t > 0.0) ms += t;
    }
    return ms;
}

double stepEtaMs(double elapsedMs, double share, double paceFromMs, double paceFromShare,
                 double predictedMs) {
    share = std::clamp(std::isfinite(share) ? share : 0.0, 0.0, 1.0);
    if (share >= 1.0) return 0.0;
    const bool predicted = std::isfinite(predictedMs) && predictedMs > 0.0;
    const double predictedLeft = predicted ? std::max(0.0, predictedMs - elapsedMs) : 0.0;
    const double paced = share - paceFromShare;
    if (!(paced > 0.0) || !(elapsedMs > paceFromMs)) return predicted ? predictedLeft : -1.0;
    const double paceLeft = (elapsedMs - paceFromMs) * (1.0 - share) / paced;
    if (!predicted) return paceLeft;
    const double weight = std::min(1.0, share / kStepPaceTrustedShare);
    return weight * paceLeft + (1.0 - weight) * predictedLeft;
}

double AdaptiveQuality::predictStepMs(const std::string& sceneName, const FrameState& state,
                                      QualityStep step) const {
    const double pixels = static_cast<double>(state.width) * state.height;
    const double vpls = static_cast<double>(std::max(1L, vplEstimate(state)));
    // Measured at the VPLs that step rendered with (perhaps capped): scaled to this state's. Not
    // rendered yet: the nearest measured lower step, scaled by pixels and its VPL passes by the VPLs'
    // cost (a gather grows with pixels x vpls^e), so a final preset with 256 times the VPLs is
    // predicted before it runs.
    const StepCost* cost = nearestStepCost(sceneName, state, step);
    if (!cost) return 0.0;
    const double vplScale = std::pow(vpls / static_cast<double>(cost->vpls), vplCostExponent(state));
    return pixels * ((cost->msPerPixel - cost->vplMsPerPixel) + cost->vplMsPerPixel * vplScale);
}

const AdaptiveQuality::StepCost* AdaptiveQuality::nearestStepCost(const std::string& sceneName,
                                                                  const FrameState& state,
                                                                  QualityStep step) const {
    for (int s = static_cast<int>(step); s >= 0; --s)
        if (auto c = mStepCost.find(stepKey(sceneName, state, static_cast<QualityStep>(s)));
            c != mStepCost.end())
            return &c->second;
    return nullptr;
}

double AdaptiveQuality::vplsForStepMs(const std::string& sceneName, const FrameState& state, QualityStep step,
                                      double targetMs) const {
    const StepCost* cost = nearestStepCost(sceneName, state, step);
    if (!cost) return static_cast<double>(std::max(1L, vplEstimate(state)));
    const double pixels = static_cast<double>(state.width) * state.height;
    // The VPL passes get what the rest of the frame leaves of the target: none, no count fits.
    const double vplTargetMs = targetMs - pixels * (cost->msPerPixel - cost->vplMsPerPixel);
    const double vplMsAtMeasured = pixels * cost->vplMsPerPixel;
    if (!(vplTargetMs > 0.0) || !(vplMsAtMeasured > 0.0)) return 0.0;
    return static_cast<double>(cost->vpls) *
           std::pow(vplTargetMs / vplMsAtMeasured, 1.0 / vplCostExponent(state));
}

void AdaptiveQuality::recordStepCost(const std::string& sceneName, const FrameState& state, QualityStep step,
                                     double msPerPixel, double vplMsPerPixel) {
    if (!(msPerPixel > 0.0) || !std::isfinite(msPerPixel)) return;
    // Not known (or not a number): the whole cost is taken to scale, as a frame of VPL passes alone.
    const double vplPart = std::isfinite(vplMsPerPixel) && vplMsPerPixel >= 0.0
                               ? std::min(vplMsPerPixel, msPerPixel)
                               : msPerPixel;
    mStepCost[stepKey(sceneName, state, step)] = {msPerPixel, vplPart, std::max(1L, vplEstimate(state))};
}

bool AdaptiveQuality::recordMinTileCost(const std::string& sceneName, const FrameState& state,
                                        QualityStep step, double tileMs) {
    if (!(tileMs > 0.0) || !std::isfinite(tileMs)) return false;
    const TileCost measured{tileMs, std::max(1L, vplEstimate(state))};
    const std::string key = stepKey(sceneName, state, step);
    const auto known = mMinTileCost.find(key);
    if (known == mMinTileCost.end()) {
        mMinTileCost[key] = measured;
        return true;
    }
    // Compared at equal VPLs: the known tile's cost scaled to the new one's VPLs.
    const double knownAtMeasured = known->second.ms * std::pow(static_cast<double>(measured.vpls) /
                                                                   static_cast<double>(known->second.vpls),
                                                               vplCostExponent(state));
    if (tileMs <= knownAtMeasured) return false;
    known->second = measured;
    return tileMs > 1.2 * knownAtMeasured;
}

AdaptiveQuality::Plan AdaptiveQuality::plan(const std::string& sceneName, const FrameState& requested,
                                            const nlohmann::json& explicitParams, QualityStep step,
                                            bool snapshot, int frameTargetMs,
                                            const std::function<bool(const FrameState&)>& keepsLightViews) {
    Plan p;
    p.step = step;
    p.budgetKey = sceneName + "/" + requested.technique;
    if (step == QualityStep::Fixed) {
        p.state = requested;
        return p;
    }
    p.state = presetState(requested, explicitParams, step);
    // A snapshot is the best step that fits, judged like refinement: a step never measured nor
    // predictable counts as too slow; the interactive one (at full size) always fits.
    if (snapshot && mLimits.refineBudgetMs > 0) {
        const double budgetMs = std::min(static_cast<double>(mLimits.refineBudgetMs), kSnapshotBudgetMs);
        while (p.step > QualityStep::Interactive) {
            const double predictedMs = predictStepMs(sceneName, p.state, p.step);
            if (predictedMs > 0.0 && predictedMs <= budgetMs) break;
            p.step = lower(p.step);
            p.state = presetState(requested, explicitParams, p.step);
        }
    }
    if (p.step == QualityStep::Final && p.state.frameParams.has("effects") &&
        !explicitParams.contains("effects")) {
        // The plan's bias compensation (and direct/bounce decisions), but not indirect occlusion unless
        // asked for: one cube shadow map per VPL costs minutes per frame on CPU rendering at the final
        // preset's VPL counts.
        p.state.frameParams.set("effects", "auto");
        if (p.state.frameParams.has("effect_occlusion") && !explicitParams.contains("effect_occlusion"))
            p.state.frameParams.set("effect_occlusion", "off");
    }
    // Interactive and balanced frames share one environment-probe budget, so that the probes a light
    // change renders within it are kept until the final step renders them again within a whole frame
    // (its first tile would otherwise hold input back for as long as every probe at env_size takes).
    const double envBudgetMs = envProbeBudgetMs(frameTargetMs, p.step);
    const bool budgetProbes = !snapshot && envBudgetMs > 0.0 && p.state.frameParams.has("env_budget_ms") &&
                              !explicitParams.contains("env_budget_ms");
    if (budgetProbes) p.state.frameParams.set("env_budget_ms", envBudgetMs);
    // The light views within a texel at every step, not only the interactive one: drawn once while the
    // lights stay, a light drag's maps then serve the refinement after it, whose first tile would
    // otherwise hold input back while it draws every light view at full detail (176 ms on the
    // atrium), for no measured gain (docs/interactive.md, "Level of detail"). A snapshot (the best
    // image the client asked for) draws every triangle.
    const bool lightLevels = !snapshot && mLimits.interactiveLodPixels > 0.0 &&
                             p.state.frameParams.has("light_lod_texels") &&
                             !explicitParams.contains("light_lod_texels");
    if (lightLevels) p.state.frameParams.set("light_lod_texels", kLiveLightLodTexels);
    if (p.step != QualityStep::Interactive && !snapshot && mLimits.refineBudgetMs > 0)
        planRefinement(sceneName, requested, explicitParams, p);
    if (p.step == QualityStep::Interactive && !snapshot) {
        planInteractive(frameTargetMs, explicitParams, keepsLightViews, p);
        if (budgetProbes) p.budget["env_budget_ms"] = envBudgetMs;
        // Interactive frames only: the steps that refine the view draw every triangle.
        if (mLimits.interactiveLodPixels > 0.0 && p.state.frameParams.has("lod_pixels") &&
            !explicitParams.contains("lod_pixels")) {
            p.state.frameParams.set("lod_pixels", mLimits.interactiveLodPixels);
            p.budget["lod_pixels"] = mLimits.interactiveLodPixels;
        }
        if (lightLevels) p.budget["light_lod_texels"] = kLiveLightLodTexels;
    }
    return p;
}

void AdaptiveQuality::planRefinement(const std::string& sceneName, const FrameState& requested,
                                     const nlohmann::json& explicitParams, Plan& p) const {
    const double budgetMs = mLimits.refineBudgetMs;
    const double predictedMs = predictStepMs(sceneName, p.state, p.step);
    p.predictedMs = predictedMs;
    // Fewer VPLs where the technique can take them (a step's cost grows as vpls^e with them) when
    // the whole step would overrun the budget, or, for a technique that cannot render its VPLs in
    // parts, when even the smallest tile would overrun a slice (input waits for at most one tile);
    // else a step over the budget is skipped. The client is told which.
    const TechniqueInfo& info = findTechniqueInfo(p.state.technique);
    const double exponent = vplCostExponent(p.state);
    const long vpls = vplEstimate(p.state);
    double cap = static_cast<double>(vpls);
    std::string why;
    if (predictedMs > budgetMs) {
        cap = vplsForStepMs(sceneName, p.state, p.step, 0.9 * budgetMs);
        why = "predicted at " + std::to_string(std::lround(predictedMs / 1000.0)) +
              " s, over the server's refinement budget of " + std::to_string(std::lround(budgetMs / 1000.0)) +
              " s (--refine-budget-ms)";
    }
    // The smallest tile's measured cost where a step measured one, else the interactive frames'
    // cost of the technique's passes over that tile at this step's VPLs.
    const auto minTile = mMinTileCost.find(stepKey(sceneName, p.state, p.step));
    const TileCost tile =
        minTile != mMinTileCost.end()
            ? minTile->second
            : TileCost{
                  mBudget.vplPassesMs(p.budgetKey, double(kMinRefineTileSide) * kMinRefineTileSide, vpls),
                  std::max(1L, vpls)};
    const bool inParts = info.vplParts && info.vplParts(p.state.techniqueParams);
    if (tile.ms > 0.0 && !inParts) {
        const double sliceCap =
            vplsForCost(static_cast<double>(tile.vpls), tile.ms, 0.8 * mLimits.sliceMs, exponent);
        if (sliceCap < cap) {
            cap = sliceCap;
            why = "a " + std::to_string(kMinRefineTileSide) + " x " + std::to_string(kMinRefineTileSide) +
                  " tile must fit one " + std::to_string(mLimits.sliceMs) + " ms slice (--slice-ms)";
        }
    }
    // A final step capped to no more VPLs than the balanced one would only repeat it.
    const long floorVpls =
        p.step == QualityStep::Final
            ? std::max(16L, vplEstimate(presetState(requested, explicitParams, QualityStep::Balanced)) + 1)
            : 16L;
    const bool capped = cap < static_cast<double>(vpls);
    if (capped && info.limitVpls && cap >= static_cast<double>(floorVpls)) {
        info.limitVpls(p.state.techniqueParams, static_cast<long>(cap));
        p.why = "capped at " + std::to_string(vplEstimate(p.state)) + " of " + std::to_string(vpls) +
                " VPLs: " + why;
    } else if (predictedMs > budgetMs || (capped && info.limitVpls)) {
        if (capped && info.limitVpls)
            why = "at most " + std::to_string(std::max(0L, static_cast<long>(cap))) + " of " +
                  std::to_string(vpls) + " VPLs fit (" + why + "), no more than the step before";
        p.skip = true;
        p.why = why;
    }
}

void AdaptiveQuality::planInteractive(int frameTargetMs, const nlohmann::json& explicitParams,
                                      const std::function<bool(const FrameState&)>& keepsLightViews,
                                      Plan& p) {
    const long requestedVpls = vplEstimate(p.state);
    p.techniqueParamsKey = p.state.techniqueParams.toJson().dump();
    if (frameTargetMs > 0) {
        mBudget.setTargetMs(frameTargetMs);
        const TechniqueInfo& info = findTechniqueInfo(p.state.technique);
        const ParamSet& fp = p.state.frameParams;
        LightViewAsk lightViews{fp.has("shadow_map_size") ? fp.getInt("shadow_map_size") : 0,
                                fp.has("rsm_size") ? fp.getInt("rsm_size") : 0, info.readsRsm};
        if (keepsLightViews)
            lightViews.redraw =
                keepsLightViews(p.state) ? LightViewAsk::Redraw::No : LightViewAsk::Redraw::Yes;
        // What a cap leaves of the VPLs: the technique's own knob, on one copy of the frame.
        FrameState capped = p.state;
        const auto renderedVpls = [&info, &p, &capped](long cap) {
            capped.techniqueParams = p.state.techniqueParams;
            info.limitVpls(capped.techniqueParams, cap);
            return vplEstimate(capped);
        };
        const BudgetChoice choice = mBudget.choose(
            p.budgetKey, requestedVpls, static_cast<bool>(info.limitVpls),
            static_cast<double>(p.state.width) * p.state.height, lightViews,
            info.limitVpls ? std::function<long(long)>(renderedVpls) : std::function<long(long)>());
        p.scale = choice.scale;
        p.state.lightViewCap = {choice.shadowSideCap, choice.rsmSideCap};
        if (choice.vplCap > 0 && info.limitVpls) info.limitVpls(p.state.techniqueParams, choice.vplCap);
        // A cap the client set itself stays.
        const bool capReceivers = choice.receiverShareCap > 0.0 && info.capReceiverShare &&
                                  !explicitParams.contains("receiver_share_cap");
        if (capReceivers) {
            info.capReceiverShare(p.state.techniqueParams, choice.receiverShareCap);
            // The cap cuts by the exponent this session's frames measured at the VPLs asked for
            // (hier_isr's near 65,536 leaves is about a third of its fixed one).
            p.state.receiverCapExponent =
                mBudget.exponentAt(p.budgetKey, vplEstimate(p.state), p.techniqueParamsKey);
        }
        p.budget = choice.toJson(frameTargetMs, requestedVpls);
        if (!capReceivers) p.budget["receiver_share_cap"] = nullptr;
    } else {
        p.scale = std::clamp(mLimits.interactiveScale, 0.05, 1.0);
        p.budget = {
            {"target_ms", 0},        {"scale", p.scale},
            {"vpls", requestedVpls}, {"vpl_cap", nullptr},
            {"predicted_ms", 0},     {"reason", "no frame-time target: the server's interactive scale"}};
    }
    p.state.width = std::max(16, static_cast<int>(std::lround(p.state.width * p.scale)));
    p.state.height = std::max(16, static_cast<int>(std::lround(p.state.height * p.scale)));
}

} // namespace gis
