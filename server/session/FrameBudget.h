// The live view's frame-time budget: which size and VPL cap the next interactive frame renders with so
// that it meets the session's target (protocol `frame_target_ms`), chosen from what this session's
// frames of that scene and technique measured, never from a fixed table. The counterpart of an
// adaptive frame rate for GI: resolution first, then the VPLs, then resolution again
// (docs/interactive.md).
//
// Model, per scene and technique, from the last interactive frames (exponential means):
//   ms(pixels, vpls) = pixels * (baseRate + encodeRate) + pixels * vpls^e * vplRate
// with e the technique's vplCostExponent (1 for a sum over every VPL, 0.4 for hier_isr's traversal).
// where baseRate comes from the renderer's own stages (shadow maps, G-buffer, direct, composite,
// reflections, overheads) and vplRate from the technique's passes. Counting all of the technique's
// passes as VPL-bound over-predicts what more VPLs cost, so the budget climbs cautiously.
// A technique that gathers over receivers (multires_gather) costs receivers x VPLs, and a view's
// receivers are not a model's to predict: the next frame's gather is capped at twice the last
// frame's receiver share instead, or a quarter above the last cap after a frame it cut, which the
// prediction then adds to the technique's passes (receiverShareCapAfter,
// TechniqueInfo::capReceiverShare).
#pragma once

#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "gi/Catalog.h" // usableVplCostExponent

namespace gis {

/// One measured interactive frame.
struct FrameCost {
    double pixels = 0;      ///< rendered
    long vpls = 0;          ///< rendered (0: the technique has none)
    double frameMs = 0;     ///< the renderer's frame_ms
    double techniqueMs = 0; ///< the technique's passes within it
    double encodeMs = 0;
    /// The technique's passes cost about pixels x vpls^vplCostExponent (TechniqueInfo::vplCostExponent).
    double vplCostExponent = 1.0;
    /// The gather's work per pixel and VPL asked for: receivers per pixel (counts receivers_total /
    /// pixels), or the cap (params receiver_share_cap) for a frame the cap cut. Below 0 when the
    /// technique has no receiver list.
    double receiverShare = -1;
    bool receiverCut = false; ///< the cap cut the frame's VPLs (receiverShare is then the cap)

    /// A rendered frame's cost from its stats (frame_ms, technique_ms, counts, params) at width x
    /// height, whose parameters asked for `askedVpls` (vplEstimate), which it counts whether or not the
    /// receiver cap cut them (counts.receiver_share_capped_vpls): its time is the time of a frame that
    /// asks for them, under a cap. encodeMs stays 0.
    static FrameCost ofFrame(const nlohmann::json& stats, int width, int height, long askedVpls,
                             double vplCostExponent);
};

/// What the next interactive frame renders with, and why.
struct BudgetChoice {
    double scale = 1.0;     ///< size factor (0, 1]
    long vplCap = 0;        ///< 0: the parameters' own count
    double predictedMs = 0; ///< 0: nothing measured yet
    /// The gather's work cap for the next frame (TechniqueInfo::capReceiverShare), receivers per pixel;
    /// 0: none (nothing measured, or the technique has no receivers).
    double receiverShareCap = 0;
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
        /// The first two frames of a scene and technique (nothing measured, then only a frame that
        /// compiled the technique's shaders): this size factor, at most firstVplCap VPLs (a guess
        /// kept small, so that those frames stay short).
        double firstScale = 0.35;
        long firstVplCap = 1024;
    };
    explicit FrameBudget(Config config) : mConfig(config) {}
    const Config& config() const { return mConfig; }
    void setTargetMs(double ms) { mConfig.targetMs = ms; }

    /// The choice for a frame of `key` (scene/technique) whose parameters ask for `requestedVpls`
    /// (0: none) and can be capped (`cappable`) at fullPixels full-size pixels.
    BudgetChoice choose(const std::string& key, long requestedVpls, bool cappable, double fullPixels);
    void record(const std::string& key, const FrameCost& cost);
    /// Predicted ms of a frame of `key` at `pixels` with `vpls`; 0 when nothing is measured.
    double predictMs(const std::string& key, double pixels, long vpls) const;
    /// Predicted ms of the technique's VPL passes alone over `pixels` with `vpls` (pixels x vpls^e at
    /// the measured rate); 0 when nothing is measured or the technique's frames had no VPLs.
    double vplPassesMs(const std::string& key, double pixels, long vpls) const;

private:
    struct Rates {
        double base = 0, encode = 0, vpl = 0; ///< ms per pixel, ms per pixel, ms per pixel per VPL^exponent
        double exponent = 1.0;                ///< FrameCost::vplCostExponent of the last frame
        double tech = 0;                      ///< ms per pixel of the technique when it has no VPLs
        double receiverShare = -1;            ///< the last frame's (FrameCost::receiverShare)
        bool receiverCut = false;             ///< FrameCost::receiverCut of the last frame
        int frames = 0;
        int level = -1; ///< index of the last choice in the candidate ladder
    };
    /// ms at `pixels` and `vpls` from `rates`, the technique's passes times `techniqueFactor`.
    static double predict(const Rates& rates, double pixels, long vpls, double techniqueFactor);

    Config mConfig;
    std::map<std::string, Rates> mRates;
};

} // namespace gis
