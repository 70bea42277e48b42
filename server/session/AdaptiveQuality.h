// Adaptive quality's decisions for one session, without GL, sockets or threads (protocol/PROTOCOL.md,
// "Adaptive quality"; docs/interactive.md):
//   - each step renders its preset (presets/presets.json) under the parameters the client set;
//   - a snapshot renders the best step predicted to fit the snapshot budget;
//   - a refinement step predicted over the refinement budget, or whose smallest tile would overrun a
//     slice, renders fewer VPLs where the technique can take them, else it is skipped, with the reason;
//   - an interactive frame's size and VPL cap come from the frame budget (session/FrameBudget.h);
//   - the environment probes get a share of the frame target (env_budget_ms; a whole one in the
//     final step), unless the client set it.
// It keeps what it measured: each step's cost per pixel by scene and technique, the smallest tile's
// cost per VPL where one overran its slice, and the frame budget's rates. Session's worker owns one
// and asks it before every frame; tests drive it directly (tests/unit/session/AdaptiveQualityTest.cpp).
#pragma once

#include <functional>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "frame/FrameState.h"
#include "session/FrameBudget.h"
#include "session/SessionLimits.h"

namespace gis {

/// The live view's steps; Fixed frames (adaptive off) are rendered as asked.
enum class QualityStep : int { Fixed = -1, Interactive = 0, Balanced = 1, Final = 2 };
const char* qualityStepName(QualityStep step); ///< "interactive", "balanced", "final", "fixed"

/// The share of the interactive frame target that an interactive or balanced frame rendering the
/// environment probes again may spend on them; the final step may spend a whole frame target.
constexpr double kEnvProbeShareOfFrame = 0.25;
/// env_budget_ms of `step` for a frame target (0: none).
inline double envProbeBudgetMs(int frameTargetMs, QualityStep step) {
    if (frameTargetMs <= 0 || step == QualityStep::Fixed) return 0.0;
    return (step == QualityStep::Final ? 1.0 : kEnvProbeShareOfFrame) * frameTargetMs;
}

/// The smallest refinement tile side (px): a few ms of fixed cost per tile on llvmpipe, so smaller
/// ones would mostly repeat it.
constexpr int kMinRefineTileSide = 16;
/// A snapshot renders in one piece while the controller's input waits behind it: at most this long.
constexpr double kSnapshotBudgetMs = 5000.0;
/// light_lod_texels of every adaptive step while the server's levels of detail are on
/// (--interactive-lod-px above 0) and the client did not set it: the frame parameter's maximum.
constexpr double kLiveLightLodTexels = 1.0;

/// The ms of a rendered frame's passes that grow with the VPLs (TechniqueInfo::vplPasses of
/// `technique`, from stats.passes: gpu_ms, else cpu_ms); below 0 when the technique names none.
double vplPassesMs(const std::string& technique, const nlohmann::json& stats);

/// The time left of a refinement step `elapsedMs` into it with `share` (0..1) of its image done: the
/// step's own pace since `paceFrom` (elapsed ms and share once the one-time work of its first tile,
/// the light views, was done), blended with what is left of `predictedMs` (predictStepMs; 0: none)
/// in proportion to the share done until kStepPaceTrustedShare: the first tiles are the smallest and
/// the dearest per pixel, and the first rows of an image are often its cheapest (sky, background):
/// with the pace alone from a tenth on, a Blender export's final step said 1-2 s left at a quarter
/// of its image with 6-11 s to go. Below 0 when neither is known (protocol: eta_ms null).
double stepEtaMs(double elapsedMs, double share, double paceFromMs, double paceFromShare, double predictedMs);
inline constexpr double kStepPaceTrustedShare = 0.5;

class AdaptiveQuality {
public:
    /// `presets`: presets/presets.json's document, null for none (every step renders as requested).
    AdaptiveQuality(const SessionLimits& limits, nlohmann::json presets);

    /// What one frame renders.
    struct Plan {
        FrameState state;
        QualityStep step = QualityStep::Fixed; ///< a snapshot may take a lower step than asked
        bool skip = false;                     ///< a refinement step that cannot fit: render nothing
        double predictedMs = 0.0;              ///< the step's predicted total, where known
        std::string why;       ///< skip: why; a capped refinement step: what it renders less of
        double scale = 1.0;    ///< interactive: the size factor applied to the state
        nlohmann::json budget; ///< interactive: stats.budget (null otherwise)
        std::string budgetKey; ///< "scene/technique": where the frame's cost is recorded
        /// Interactive: the technique's parameters before the budget's caps, as JSON
        /// (FrameCost::techniqueParams: what the frame's measured cost exponent holds for).
        std::string techniqueParamsKey;
    };
    /// The plan for `step` of `requested` (the session's state: its full size, the client's
    /// parameters) in scene `sceneName`. `explicitParams` are those the client set (they win over
    /// presets); `snapshot` asks for the best step that fits kSnapshotBudgetMs; `frameTargetMs` is the
    /// session's interactive target (0: none).
    /// `keepsLightViews` (may be empty): whether a frame of a state keeps the light views drawn before
    /// (FrameRenderer::keepsLightViews), asked for interactive frames.
    Plan plan(const std::string& sceneName, const FrameState& requested, const nlohmann::json& explicitParams,
              QualityStep step, bool snapshot, int frameTargetMs,
              const std::function<bool(const FrameState&)>& keepsLightViews = {});

    /// `requested` under the preset of `step` and then the explicit parameters; `requested` itself
    /// when there are no presets, none for this technique, or the preset asks for more VPLs than allowed.
    FrameState presetState(const FrameState& requested, const nlohmann::json& explicitParams,
                           QualityStep step) const;

    /// The total ms a step of `state` is predicted to take: its own last measurement, else the nearest
    /// lower step's, scaled by pixels and, its VPL passes alone, by VPLs; 0 when neither was measured.
    double predictStepMs(const std::string& sceneName, const FrameState& state, QualityStep step) const;
    /// The VPLs at which that prediction for `state` is `targetMs` (only the VPL passes shrink with
    /// them): 0 when the rest of the frame alone takes longer; the state's own VPLs when nothing is
    /// measured.
    double vplsForStepMs(const std::string& sceneName, const FrameState& state, QualityStep step,
                         double targetMs) const;
    /// A finished step's cost per pixel (at the VPLs `state` rendered with), of which `vplMsPerPixel`
    /// in the technique's VPL passes (vplPassesMs; below 0: not known, the whole cost scales with the
    /// VPLs). Only that part grows with more VPLs: scaling the whole of a frame with 16 VPLs to a step
    /// with 4,096 predicted 300 s for a step of 3 s, and capped or skipped it.
    void recordStepCost(const std::string& sceneName, const FrameState& state, QualityStep step,
                        double msPerPixel, double vplMsPerPixel = -1.0);
    /// A smallest tile of a technique that cannot split its VPLs overran its slice, taking `tileMs` at
    /// the VPLs of `state`; the step's VPL cap follows it. True when this is news (first, or 20 % worse
    /// than known at equal VPLs): the step should start again with the cap.
    bool recordMinTileCost(const std::string& sceneName, const FrameState& state, QualityStep step,
                           double tileMs);

    /// The interactive frames' budget (their measured rates, and the costs refinement predicts from).
    FrameBudget& budget() { return mBudget; }
    const FrameBudget& budget() const { return mBudget; }

private:
    struct StepCost {
        double msPerPixel = 0;
        double vplMsPerPixel = 0; ///< the part that scales with the VPLs, at most msPerPixel
        long vpls = 1;
    };
    struct TileCost {
        double ms = 0; ///< the smallest tile's time
        long vpls = 1; ///< at these VPLs
    };
    static std::string stepKey(const std::string& sceneName, const FrameState& state, QualityStep step);
    /// The cost of `step` of `state`'s scene and technique, else of the nearest lower step measured.
    const StepCost* nearestStepCost(const std::string& sceneName, const FrameState& state,
                                    QualityStep step) const;
    void planRefinement(const std::string& sceneName, const FrameState& requested,
                        const nlohmann::json& explicitParams, Plan& plan) const;
    void planInteractive(int frameTargetMs, const nlohmann::json& explicitParams,
                         const std::function<bool(const FrameState&)>& keepsLightViews, Plan& plan);

    SessionLimits mLimits;
    nlohmann::json mPresets;
    FrameBudget mBudget;
    std::map<std::string, StepCost> mStepCost;    ///< scene/technique/step
    std::map<std::string, TileCost> mMinTileCost; ///< scene/technique/step
};

} // namespace gis
