// The live view's frame-time budget: which size and VPL cap the next interactive frame renders with so
// that it meets the session's target (protocol `frame_target_ms`), chosen from what this session's
// frames of that scene and technique measured, never from a fixed table. The counterpart of an
// adaptive frame rate for GI: resolution first, then the VPLs, then resolution again
// (docs/interactive.md).
//
// Model, per scene and technique, from the last interactive frames (exponential means):
//   ms(pixels, vpls) = pixels * (baseRate + encodeRate) + pixels * vpls^e * vplRate
// with e the technique's exponent near the last frame (frameVplCostExponent: 1 for a sum over every
// VPL; for hier_isr's traversal, measured from its visits, about 1 at tau 0 or a few hundred leaves
// and far lower over thousands), where baseRate comes from the renderer's own stages (shadow maps,
// G-buffer, direct, composite, reflections, overheads) and the technique's passes that do not grow
// with the VPLs (eye hierarchy, upsampling), and vplRate from its VPL passes (TechniqueInfo::vplPasses).
// A technique that gathers over receivers (multires_gather) costs receivers x VPLs, and a view's
// receivers are not a model's to predict: the next frame's gather is capped at twice the last
// frame's receiver share instead, or a quarter above the last cap after a frame it cut, which the
// prediction then adds to the technique's passes (receiverShareCapAfter,
// TechniqueInfo::capReceiverShare).
//
// The light views (shadow maps, RSMs and what is built over them, TechniqueInfo::lightViewPasses)
// cost per texel, not per pixel, and only in frames that draw them again (a light drag, a changed
// light parameter; an orbit keeps them). Their rates are kept apart, per texel of each kind of map:
// a frame that draws them is predicted with them when the frame before drew them too, and when their
// sides exceed the defaults' the frame draws them at most large enough to take kLightViewShareOfFrame
// of the target (never below the defaults' sides): a drag at rsm_size 1024 otherwise shrank the
// image to a tenth of its size (docs/interactive.md, "Light views in interactive frames").
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gi/Catalog.h" // usableVplCostExponent

namespace gis {

/// One measured interactive frame.
struct FrameCost {
    double pixels = 0;  ///< rendered
    long vpls = 0;      ///< rendered (0: the technique has none)
    double frameMs = 0; ///< the renderer's frame_ms
    /// The frame's timed passes together (gpu_ms, as technique_ms sums); 0: not known. A scene and
    /// technique's first frame spends most of its compile and first-upload time outside them.
    double passesMs = 0;
    double techniqueMs = 0; ///< the technique's passes within it
    /// The technique's VPL passes within those (TechniqueInfo::vplPasses; the session fills it in with
    /// vplPassesMs, AdaptiveQuality.h): what grows with the VPLs; its other passes (the eye hierarchy,
    /// upsampling) cost per pixel. Below 0: the technique names none, and all of techniqueMs grows
    /// with the VPLs.
    double vplPassesMs = -1;
    double encodeMs = 0;
    /// The technique's passes cost about pixels x vpls^vplCostExponent (TechniqueInfo::vplCostExponent).
    double vplCostExponent = 1.0;
    /// The gather's work per pixel and VPL asked for: receivers per pixel (counts receivers_total /
    /// pixels), or the cap (params receiver_share_cap) for a frame the cap cut. Below 0 when the
    /// technique has no receiver list.
    double receiverShare = -1;
    bool receiverCut = false; ///< the cap cut the frame's VPLs (receiverShare is then the cap)
    /// The VPLs the frame gathered from: those the receiver cap left it (counts
    /// receiver_share_capped_vpls), or vpls; where vplCostExponent was measured.
    long gatheredVpls = 0;
    /// The technique's parameters before the budget's caps, as JSON (AdaptiveQuality::Plan::
    /// techniqueParamsKey): what vplCostExponent holds for. hier_isr's at 256 leaves is about 1 at
    /// tau 0 and 0.85 at tau 0.01; a change of them forgets the exponents measured before.
    std::string techniqueParams;
    /// The light views, when the frame drew them (counts.light_views_reused absent and a shadow_map
    /// pass timed): their views, texels (views x side^2) and ms (shadow_map; rsm, rsm_flux and the
    /// technique's lightViewPasses). lightViewTechniqueMs is the part of techniqueMs among them.
    bool drewLightViews = false;
    int lightViews = 0;
    double shadowTexels = 0, shadowMs = 0;
    double rsmTexels = 0, rsmMs = 0;
    double lightViewTechniqueMs = 0;

    /// A rendered frame's cost from its stats (frame_ms, technique_ms, counts, params) at width x
    /// height, whose parameters asked for `askedVpls` (vplEstimate), which it counts whether or not the
    /// receiver cap cut them (counts.receiver_share_capped_vpls): its time is the time of a frame that
    /// asks for them, under a cap. encodeMs stays 0.
    static FrameCost ofFrame(const nlohmann::json& stats, int width, int height, long askedVpls,
                             double vplCostExponent, const std::vector<std::string>& lightViewPasses = {});
};

/// The light views a frame's parameters ask for: shadow_map_size and rsm_size, and whether the
/// technique reads the RSMs (TechniqueInfo::readsRsm).
struct LightViewAsk {
    int shadowMapSize = 0; ///< 0: not known (no cap)
    int rsmSize = 0;
    bool readsRsm = true;
    /// Whether the frame draws its light views again (FrameRenderer::keepsLightViews); not known:
    /// when the frame before drew them.
    enum class Redraw { Unknown, Yes, No } redraw = Redraw::Unknown;
};
/// The share of the frame target that the light views may take in a frame that draws them again.
inline constexpr double kLightViewShareOfFrame = 0.35;

/// What the next interactive frame renders with, and why.
struct BudgetChoice {
    double scale = 1.0;     ///< size factor (0, 1]
    long vplCap = 0;        ///< 0: the parameters' own count
    double predictedMs = 0; ///< 0: nothing measured yet
    /// The gather's work cap for the next frame (TechniqueInfo::capReceiverShare), receivers per pixel;
    /// 0: none (nothing measured, or the technique has no receivers).
    double receiverShareCap = 0;
    /// FrameState::LightViewCap for the next frame (0: none), the sides asked (after lightViewSide),
    /// the light views' predicted ms at the capped sides, and why.
    int shadowSideCap = 0, rsmSideCap = 0;
    int shadowSideAsked = 0, rsmSideAsked = 0;
    double lightViewMs = 0;
    std::string lightViewReason;
    std::string reason;
    nlohmann::json toJson(double targetMs, long requestedVpls) const;
};

/// The gather's work cap after a frame whose work was `lastShare` (FrameCost::receiverShare): twice
/// that after a frame the cap left whole, so that the usual frame-to-frame change in an orbit gathers
/// every VPL; a quarter more than the cap after a frame it cut, so that while a view with many more
/// receivers than the last (from outside a building into it) is cut, each frame's gather grows by at
/// most a quarter over the last and the budget's size and VPL choice, learning from each, keeps up
/// (doubling it each frame gave frames three times the target on the way). At least
/// kMinReceiverShareCap, at most 1.
inline constexpr double kReceiverShareGrowth = 2.0;
inline constexpr double kCutReceiverShareGrowth = 1.25;
inline constexpr double kMinReceiverShareCap = 0.02;
double receiverShareCapAfter(double lastShare, bool lastCut);

/// What the receiver cap did to a rendered frame, into its stats.budget (BudgetChoice::toJson): when
/// the frame gathered from fewer VPLs (counts.receiver_share_capped_vpls), receiver_capped_vpls
/// (those VPLs) and a sentence on the reason. Nothing otherwise.
void noteReceiverCap(nlohmann::json& budget, const nlohmann::json& frameStats, int width, int height);

class FrameBudget {
public:
    struct Config {
        double targetMs = 80; ///< render + encode of one interactive frame
        double maxScale = 1.0;
        double preferredMinScale = 0.3; ///< below this, VPLs go first
        double minScale = 0.1;
        long minVpls = 16;
        /// The first frame of a scene and technique (nothing measured), and the second when the
        /// first's passes were not timed (only a frame that compiled the technique's shaders): this
        /// size factor, at most firstVplCap VPLs (a guess kept small, so that those frames stay
        /// short).
        double firstScale = 0.35;
        long firstVplCap = 1024;
        /// ...and the gather's work capped at this many receivers per pixel (receiver_share_cap):
        /// VPLs alone do not bound a gather over receivers (hier_isr at tau 0 with depth_threshold 0,
        /// every pixel a receiver: 1,219 ms for the first frame's 1024 VPLs). Twice cornell's share.
        double firstReceiverShareCap = 0.25;
    };
    explicit FrameBudget(Config config) : mConfig(config) {}
    const Config& config() const { return mConfig; }
    void setTargetMs(double ms) { mConfig.targetMs = ms; }

    /// The choice for a frame of `key` (scene/technique) whose parameters ask for `requestedVpls`
    /// (0: none) and can be capped (`cappable`) at fullPixels full-size pixels. `renderedVpls`, when
    /// given, says how many VPLs a cap of v leaves the technique (its knob's steps: hier_isr's leaves
    /// go in fours), which the candidates are predicted and reported with.
    BudgetChoice choose(const std::string& key, long requestedVpls, bool cappable, double fullPixels,
                        const LightViewAsk& lightViews = {},
                        const std::function<long(long)>& renderedVpls = {});
    void record(const std::string& key, const FrameCost& cost);
    /// Predicted ms of a frame of `key` at `pixels` with `vpls`; 0 when nothing is measured.
    double predictMs(const std::string& key, double pixels, long vpls) const;
    /// Predicted ms of the technique's VPL passes alone over `pixels` with `vpls` (pixels x vpls^e at
    /// the measured rate); 0 when nothing is measured or the technique's frames had no VPLs.
    double vplPassesMs(const std::string& key, double pixels, long vpls) const;
    /// The cost exponent the last frame of `key` that gathered from exactly `vpls` VPLs measured
    /// (FrameCost::vplCostExponent at FrameCost::gatheredVpls) under the technique parameters
    /// `techniqueParams` (FrameCost::techniqueParams): what the receiver cap of a frame asking for them
    /// cuts by (FrameState::receiverCapExponent). 0 when none did, or none under those parameters.
    double exponentAt(const std::string& key, long vpls, const std::string& techniqueParams) const;

private:
    struct Rates {
        double base = 0, encode = 0, vpl = 0; ///< ms per pixel, ms per pixel, ms per pixel per VPL^exponent
        double exponent = 1.0;                ///< FrameCost::vplCostExponent of the last frame
        long lastVpls = 0;                    ///< FrameCost::vpls of the last frame
        double tech = 0;                      ///< ms per pixel of the technique when it has no VPLs
        double receiverShare = -1;            ///< the last frame's (FrameCost::receiverShare)
        bool receiverCut = false;             ///< FrameCost::receiverCut of the last frame
        int frames = 0;
        /// The only frame measured was a first one, counted by its passes (FrameCost::passesMs).
        bool firstByPasses = false;
        int level = -1; ///< index of the last choice in the candidate ladder
        /// ms per texel of the shadow maps and of the RSMs (with their flux sums and the technique's
        /// lightViewPasses), from the frames that drew them (lightFrames).
        double shadowTexel = 0, rsmTexel = 0;
        int lightFrames = 0;
        bool lastDrewLightViews = false;
        int lightViews = 1; ///< the last frame's
        /// FrameCost::vplCostExponent by FrameCost::gatheredVpls, the newest frame's at each count
        /// (hier_isr's leaves are powers of four: a handful; at most kMaxExponentCounts).
        std::map<long, double> exponentAt;
        std::string exponentParams; ///< FrameCost::techniqueParams of the frames in exponentAt
    };
    static constexpr size_t kMaxExponentCounts = 64;
    /// The light views' sides and predicted ms for `ask` (BudgetChoice's light-view fields).
    void chooseLightViews(const Rates* rates, const LightViewAsk& ask, BudgetChoice& out) const;
    /// ms at `pixels` and `vpls` from `rates`, the technique's passes times `techniqueFactor`.
    static double predict(const Rates& rates, double pixels, long vpls, double techniqueFactor);

    Config mConfig;
    std::map<std::string, Rates> mRates;
};

} // namespace gis
