#include "session/FrameBudget.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "frame/LightModel.h"

namespace gis {
namespace {

std::string fmt(const char* f, double a, double b = 0, double c = 0, double d = 0) {
    char buf[256];
    std::snprintf(buf, sizeof buf, f, a, b, c, d);
    return buf;
}

struct Candidate {
    double scale;
    long vpls; ///< 0: uncapped
};

} // namespace

double receiverShareCapAfter(double lastShare, bool lastCut) {
    if (!std::isfinite(lastShare) || lastShare < 0.0) return 1.0;
    return std::clamp((lastCut ? kCutReceiverShareGrowth : kReceiverShareGrowth) * lastShare,
                      kMinReceiverShareCap, 1.0);
}

FrameCost FrameCost::ofFrame(const nlohmann::json& stats, int width, int height, long askedVpls,
                             double vplCostExponent, const std::vector<std::string>& lightViewPasses) {
    FrameCost cost;
    cost.pixels = static_cast<double>(std::max(width, 0)) * std::max(height, 0);
    cost.vpls = askedVpls;
    cost.vplCostExponent = vplCostExponent;
    cost.frameMs = stats.value("frame_ms", 0.0);
    cost.techniqueMs = stats.value("technique_ms", 0.0);
    const nlohmann::json counts = stats.value("counts", nlohmann::json::object());
    const double gathered = counts.value("receiver_share_capped_vpls", 0.0);
    cost.gatheredVpls = std::isfinite(gathered) && gathered >= 1.0 ? static_cast<long>(gathered) : askedVpls;
    if (counts.contains("receivers_total") && cost.pixels > 0.0) {
        cost.receiverShare = counts.value("receivers_total", 0.0) / cost.pixels;
        // A frame the cap cut did the cap's work per pixel and asked VPL, whatever grid the rounding
        // left it: the next cap grows from the cap (growing from the rounded-down grid's work stalled
        // a small grid at one VPL, which never reached the next square).
        const nlohmann::json params = stats.value("params", nlohmann::json::object());
        const double cap = params.value("receiver_share_cap", 1.0);
        if (counts.value("receiver_share_capped_vpls", 0.0) >= 1.0 && cap > 0.0) {
            cost.receiverShare = std::min(cost.receiverShare, cap);
            cost.receiverCut = true;
        }
    }
    // The light views, when this frame drew them: their passes' times (gpu_ms, as technique_ms sums).
    const nlohmann::json lighting = stats.value("lighting", nlohmann::json::object());
    const nlohmann::json passes = stats.value("passes", nlohmann::json::array());
    double shadowMs = 0, rsmMs = 0, techniqueLightMs = 0;
    bool shadowPass = false;
    for (const nlohmann::json& pass : passes) {
        if (!pass.is_object()) continue;
        const std::string name = pass.value("name", std::string());
        double ms = pass.value("gpu_ms", 0.0);
        if (!std::isfinite(ms) || ms < 0.0) ms = 0.0;
        cost.passesMs += ms;
        if (name == "shadow_map") {
            shadowPass = true;
            shadowMs += ms;
        } else if (name == "rsm" || name == "rsm_flux") {
            rsmMs += ms;
        } else if (std::find(lightViewPasses.begin(), lightViewPasses.end(), name) != lightViewPasses.end()) {
            rsmMs += ms;
            techniqueLightMs += ms;
        }
    }
    const int views = lighting.value("views", 0);
    cost.lightViews = std::max(views, 0);
    if (shadowPass && views > 0 && !counts.contains("light_views_reused")) {
        const auto texels = [&](const char* side) {
            const double s = lighting.value(side, 0.0);
            return std::isfinite(s) && s > 0.0 ? double(views) * s * s : 0.0;
        };
        cost.drewLightViews = true;
        cost.shadowTexels = texels("shadow_side");
        cost.shadowMs = shadowMs;
        cost.rsmTexels = rsmMs > 0.0 ? texels("rsm_side") : 0.0;
        cost.rsmMs = rsmMs;
        cost.lightViewTechniqueMs = std::min(techniqueLightMs, std::max(cost.techniqueMs, 0.0));
    }
    return cost;
}

void noteReceiverCap(nlohmann::json& budget, const nlohmann::json& frameStats, int width, int height) {
    const nlohmann::json counts = frameStats.value("counts", nlohmann::json::object());
    const auto vpls = static_cast<long>(counts.value("receiver_share_capped_vpls", 0.0));
    const double pixels = static_cast<double>(std::max(width, 0)) * std::max(height, 0);
    if (!budget.is_object() || vpls < 1 || !(pixels > 0.0)) return;
    budget["receiver_capped_vpls"] = vpls;
    const double cap = budget.value("receiver_share_cap", 0.0);
    const std::string asked = budget.contains("vpl_cap") && budget["vpl_cap"].is_number()
                                  ? budget["vpl_cap"].dump()
                                  : budget.value("vpls", nlohmann::json(0)).dump();
    budget["reason"] =
        budget.value("reason", std::string()) +
        fmt("; this view's receivers (%.0f%% of the pixels) exceed the %.0f%% cap set from the "
            "last frame: ",
            100.0 * counts.value("receivers_total", 0.0) / pixels, 100.0 * cap) +
        std::to_string(vpls) + " of " + asked + " VPLs gathered";
}

nlohmann::json BudgetChoice::toJson(double targetMs, long requestedVpls) const {
    return {{"target_ms", targetMs},
            {"scale", scale},
            {"vpls", requestedVpls},
            {"vpl_cap", vplCap > 0 ? nlohmann::json(vplCap) : nlohmann::json(nullptr)},
            {"receiver_share_cap",
             receiverShareCap > 0 ? nlohmann::json(receiverShareCap) : nlohmann::json(nullptr)},
            {"predicted_ms", predictedMs},
            {"light_view_cap", shadowSideCap > 0 || rsmSideCap > 0
                                   ? nlohmann::json{{"shadow_side", shadowSideCap},
                                                    {"rsm_side", rsmSideCap > 0 ? nlohmann::json(rsmSideCap)
                                                                                : nlohmann::json(nullptr)},
                                                    {"shadow_side_asked", shadowSideAsked},
                                                    {"rsm_side_asked", rsmSideAsked},
                                                    {"predicted_ms", lightViewMs}}
                                   : nlohmann::json(nullptr)},
            {"reason", reason}};
}

double FrameBudget::predictMs(const std::string& key, double pixels, long vpls) const {
    const auto it = mRates.find(key);
    if (it == mRates.end() || it->second.frames == 0) return 0.0;
    return predict(it->second, pixels, vpls, 1.0);
}

double FrameBudget::predict(const Rates& r, double pixels, long vpls, double techniqueFactor) {
    const double technique =
        vpls > 0 ? r.vpl * pixels * std::pow(static_cast<double>(vpls), r.exponent) : r.tech * pixels;
    return pixels * (r.base + r.encode) + technique * techniqueFactor;
}

double FrameBudget::vplPassesMs(const std::string& key, double pixels, long vpls) const {
    const auto it = mRates.find(key);
    if (it == mRates.end() || it->second.frames == 0 || !(pixels > 0.0)) return 0.0;
    const Rates& r = it->second;
    return r.vpl * pixels * std::pow(static_cast<double>(std::max(1L, vpls)), r.exponent);
}

double FrameBudget::exponentAt(const std::string& key, long vpls, const std::string& techniqueParams) const {
    const auto it = mRates.find(key);
    if (it == mRates.end() || it->second.exponentParams != techniqueParams) return 0.0;
    const auto at = it->second.exponentAt.find(vpls);
    return at == it->second.exponentAt.end() ? 0.0 : at->second;
}

void FrameBudget::record(const std::string& key, const FrameCost& measured) {
    if (!(measured.pixels > 0) || !std::isfinite(measured.frameMs) || measured.frameMs < 0) return;
    Rates& r = mRates[key];
    FrameCost cost = measured;
    // A first frame's time outside its passes is compiling and first uploads (cornell's first
    // hier_isr frame: 343 ms, its passes 238 ms; the next at that size 205 ms): its passes stand for
    // it. The passes keep some of it (direct 15 against 9 ms), which only errs towards a small frame.
    r.firstByPasses = r.frames == 0 && cost.passesMs > 0.0 && std::isfinite(cost.passesMs);
    if (r.firstByPasses) cost.frameMs = std::min(cost.frameMs, cost.passesMs);
    // The light views' passes are the light views' (their own rates below), not the pixels'.
    const double lightMs =
        cost.drewLightViews ? std::max(cost.shadowMs, 0.0) + std::max(cost.rsmMs, 0.0) : 0.0;
    const double lightTechniqueMs = cost.drewLightViews ? cost.lightViewTechniqueMs : 0.0;
    const double technique = std::clamp(cost.techniqueMs - lightTechniqueMs, 0.0, cost.frameMs);
    // What grows with the VPLs: the technique's VPL passes where it names them (the rest of its
    // passes cost per pixel, with the renderer's: counted with the VPLs they had a frame with few
    // VPLs predict its next level at several times its cost), all its passes otherwise.
    const double scaling = cost.vpls > 0 && std::isfinite(cost.vplPassesMs) && cost.vplPassesMs >= 0.0
                               ? std::clamp(cost.vplPassesMs - lightTechniqueMs, 0.0, technique)
                               : technique;
    const double base =
        std::max(cost.frameMs - scaling - std::min(lightMs, cost.frameMs - scaling), 0.0) / cost.pixels;
    const double encode = std::max(cost.encodeMs, 0.0) / cost.pixels;
    const double exponent = usableVplCostExponent(cost.vplCostExponent);
    // Another exponent (measured near each frame for some techniques): the VPL rate is carried over so
    // that it predicts the last frame's VPLs as before.
    if (exponent != r.exponent && r.lastVpls > 0)
        r.vpl *= std::pow(static_cast<double>(r.lastVpls), r.exponent - exponent);
    r.exponent = exponent;
    if (cost.vpls > 0) r.lastVpls = cost.vpls;
    const long gathered = cost.gatheredVpls > 0 ? cost.gatheredVpls : cost.vpls;
    // Exponents measured under other parameters (another tau) do not hold for these.
    if (cost.techniqueParams != r.exponentParams) {
        r.exponentAt.clear();
        r.exponentParams = cost.techniqueParams;
    }
    if (gathered > 0) {
        if (r.exponentAt.size() >= kMaxExponentCounts && !r.exponentAt.count(gathered)) r.exponentAt.clear();
        r.exponentAt[gathered] = exponent;
    }
    const double vpl =
        cost.vpls > 0 ? scaling / (cost.pixels * std::pow(static_cast<double>(cost.vpls), exponent)) : 0.0;
    const double tech = scaling / cost.pixels;
    // Half the weight on the newest frame: one noisy frame moves the choice, two confirm it. The
    // second frame replaces the first, whose time included compiling the technique's shaders
    // (FrameBudget::choose).
    const double a = r.frames <= 1 ? 1.0 : 0.5;
    r.base += a * (base - r.base);
    r.encode += a * (encode - r.encode);
    if (cost.vpls > 0) r.vpl += a * (vpl - r.vpl);
    r.tech += a * (tech - r.tech);
    // The last frame's, not a mean: the cap follows the view (its next frame sees nearly the same).
    r.receiverShare =
        std::isfinite(cost.receiverShare) && cost.receiverShare >= 0.0 ? cost.receiverShare : -1;
    r.receiverCut = r.receiverShare >= 0.0 && cost.receiverCut;
    ++r.frames;
    if (cost.lightViews > 0) r.lightViews = cost.lightViews;
    r.lastDrewLightViews = cost.drewLightViews;
    if (cost.drewLightViews) {
        // As the frame's rates: the newest drawing weighs half, the first one whole.
        const double al = r.lightFrames == 0 ? 1.0 : 0.5;
        if (cost.shadowTexels > 0.0)
            r.shadowTexel += al * (cost.shadowMs / cost.shadowTexels - r.shadowTexel);
        if (cost.rsmTexels > 0.0) r.rsmTexel += al * (cost.rsmMs / cost.rsmTexels - r.rsmTexel);
        ++r.lightFrames;
    }
}

void FrameBudget::chooseLightViews(const Rates* rates, const LightViewAsk& ask, BudgetChoice& out) const {
    if (ask.shadowMapSize <= 0 || ask.rsmSize <= 0) return;
    const int shadowDefault = lightViewDefaults().shadowSide, rsmDefault = lightViewDefaults().rsmSide;
    const int views = rates ? std::max(rates->lightViews, 1) : 1;
    // As the renderer sizes them (LightModel.h), and never below the defaults' sides (or the asked,
    // when smaller): larger maps are a still view's.
    const int shadowAsked = lightViewSide(ask.shadowMapSize, shadowDefault, views, 64);
    const int rsmAsked = lightViewSide(ask.rsmSize, rsmDefault, views, 16);
    const int shadowFloor = std::min(shadowAsked, lightViewSide(shadowDefault, shadowDefault, views, 64));
    const int rsmFloor =
        ask.readsRsm ? std::min(rsmAsked, lightViewSide(rsmDefault, rsmDefault, views, 16)) : rsmAsked;
    out.shadowSideAsked = shadowAsked;
    out.rsmSideAsked = rsmAsked;
    const auto ms = [&](int shadow, int rsm) {
        if (!rates) return 0.0;
        const double v = views;
        return v * double(shadow) * shadow * rates->shadowTexel +
               (ask.readsRsm ? v * double(rsm) * rsm * rates->rsmTexel : 0.0);
    };
    int shadow = shadowAsked, rsm = rsmAsked;
    const bool measured = rates && rates->lightFrames > 0;
    const double allowed = kLightViewShareOfFrame * mConfig.targetMs;
    if (shadow > shadowFloor || rsm > rsmFloor) {
        if (!measured) {
            shadow = shadowFloor;
            rsm = rsmFloor;
        } else {
            // Halve the dearer of the two maps (above its floor) until they fit their share.
            while (ms(shadow, rsm) > allowed) {
                const double shadowPart = ms(shadow, 0), rsmPart = ms(0, rsm);
                const bool shadowCan = shadow > shadowFloor, rsmCan = rsm > rsmFloor;
                if (!shadowCan && !rsmCan) break;
                if (shadowCan && (!rsmCan || shadowPart >= rsmPart))
                    shadow = std::max(shadowFloor, shadow / 2);
                else
                    rsm = std::max(rsmFloor, rsm / 2);
            }
        }
    }
    out.lightViewMs = ms(shadow, rsm);
    if (shadow == shadowAsked && rsm == rsmAsked) return;
    out.shadowSideCap = shadow;
    out.rsmSideCap = ask.readsRsm ? rsm : 0;
    std::string sides =
        "shadow maps " + std::to_string(shadow) + " of " + std::to_string(shadowAsked) + " texels";
    if (ask.readsRsm) sides += ", RSMs " + std::to_string(rsm) + " of " + std::to_string(rsmAsked);
    out.lightViewReason = measured ? "light views drawn again at " + sides +
                                         fmt(" (%.0f ms predicted; they may take %.0f ms of the target)",
                                             out.lightViewMs, allowed)
                                   : "light views drawn again at " + sides +
                                         ": their cost on this scene and technique is not measured yet, so "
                                         "the defaults' sides first";
}

BudgetChoice FrameBudget::choose(const std::string& key, long requestedVpls, bool cappable, double fullPixels,
                                 const LightViewAsk& lightViews,
                                 const std::function<long(long)>& renderedVpls) {
    const Config& c = mConfig;
    BudgetChoice out;
    auto it = mRates.find(key);
    chooseLightViews(it == mRates.end() ? nullptr : &it->second, lightViews, out);
    const auto withLightViews = [&out] {
        if (!out.lightViewReason.empty()) out.reason += "; " + out.lightViewReason;
        return out;
    };
    // The first frame of a scene and technique is a small one: nothing is measured. Its time included
    // compiling the technique's shaders and uploading what the scene's first draw needs (471 ms for
    // cornell's first multires_gather frame, against about 60 ms for the next at that size), and its
    // whole time would take the next frames down to 16 VPLs and a fifth of the size, from which the
    // budget climbs for a second; its passes alone (record) predict the second frame, and without
    // them the second is a small one too (a guess: hier_isr at tau 0 took 205 ms so). The second's
    // time replaces the first's (record).
    const int measured = it == mRates.end() ? 0 : it->second.frames;
    const bool onlyFirst = measured == 1;
    if (measured == 0 || (onlyFirst && !it->second.firstByPasses)) {
        out.scale = std::clamp(c.firstScale, c.minScale, c.maxScale);
        if (cappable && requestedVpls > c.firstVplCap) out.vplCap = c.firstVplCap;
        out.receiverShareCap = std::clamp(c.firstReceiverShareCap, kMinReceiverShareCap, 1.0);
        out.reason =
            std::string(measured == 0 ? "first frame of this scene and technique: nothing measured yet"
                                      : "second frame of this scene and technique: the first one's time "
                                        "included compiling its shaders") +
            ", so a small one (" + fmt("%.2f", out.scale) + " of the size" +
            (out.vplCap > 0 ? ", " + std::to_string(out.vplCap) + " VPLs" : std::string()) + ")";
        return withLightViews();
    }
    Rates& rates = it->second;
    if (rates.receiverShare >= 0.0)
        out.receiverShareCap = receiverShareCapAfter(rates.receiverShare, rates.receiverCut);
    // After a frame the cap cut, the next one may gather a quarter more per pixel and VPL (its cap
    // grows so): the technique's passes, which the gather then dominates, are predicted so.
    const double workGrowth = rates.receiverCut ? kCutReceiverShareGrowth : 1.0;
    // A frame that draws its light views again (a light drag, a changed light parameter; when the
    // session does not say, one after a frame that drew them): their predicted time comes first,
    // whatever the size.
    const bool redraw = lightViews.redraw == LightViewAsk::Redraw::Unknown
                            ? rates.lastDrewLightViews
                            : lightViews.redraw == LightViewAsk::Redraw::Yes;
    const double lightViewMs = redraw ? out.lightViewMs : 0.0;
    // The ladder from the best frame to the cheapest: size down to the preferred minimum, then VPLs
    // down, then size down to the minimum.
    // A cap of v renders what the technique's knob leaves of it: hier_isr's 444 are 256 leaves, and
    // predicted as 444 at its exponent near 1 the step above the 256 looked 1.7x dearer than it is.
    const auto rendered = [&](long v) {
        const long r = renderedVpls ? renderedVpls(v) : v;
        return r > 0 ? std::min(r, v) : v;
    };
    std::vector<Candidate> ladder;
    for (double s = c.maxScale; s > c.preferredMinScale * 1.0001; s *= 0.9) ladder.push_back({s, 0});
    ladder.push_back({c.preferredMinScale, 0});
    long lastVpls = 0;
    if (cappable && requestedVpls > c.minVpls) {
        for (double v = requestedVpls * 0.7; v > c.minVpls; v *= 0.7) {
            const long r = rendered(static_cast<long>(v));
            if (r != lastVpls) ladder.push_back({c.preferredMinScale, lastVpls = r});
        }
        // The floor as rendered: a knob in steps may already have reached it (a candidate twice).
        const long floorVpls = rendered(c.minVpls);
        if (floorVpls != lastVpls) ladder.push_back({c.preferredMinScale, lastVpls = floorVpls});
    }
    for (double s = c.preferredMinScale * 0.9; s > c.minScale; s *= 0.9) ladder.push_back({s, lastVpls});
    ladder.push_back({c.minScale, lastVpls});

    const double target = c.targetMs;
    const int previous = rates.level;
    int chosen = static_cast<int>(ladder.size()) - 1;
    double predicted = 0.0;
    for (int i = 0; i < static_cast<int>(ladder.size()); ++i) {
        const Candidate& cand = ladder[static_cast<size_t>(i)];
        const long vpls = cand.vpls > 0 ? cand.vpls : requestedVpls;
        const double ms =
            predict(rates, fullPixels * cand.scale * cand.scale, vpls, workGrowth) + lightViewMs;
        // Climbing above the last choice needs 15 % headroom, so measurement noise does not make the
        // size flicker between two frames.
        const double allowed = previous >= 0 && i < previous ? target * 0.85 : target;
        if (ms <= allowed) {
            chosen = i;
            predicted = ms;
            break;
        }
        predicted = ms;
    }
    rates.level = chosen;
    const Candidate& pick = ladder[static_cast<size_t>(chosen)];
    out.scale = pick.scale;
    out.vplCap = pick.vpls > 0 && pick.vpls < requestedVpls ? pick.vpls : 0;
    out.predictedMs = predicted;
    if (predicted > target)
        out.reason = fmt("even the cheapest frame (%.2f of the size", pick.scale) +
                     (out.vplCap > 0 ? ", " + std::to_string(out.vplCap) + " VPLs" : std::string()) +
                     fmt(") is predicted at %.0f ms, over the %.0f ms target", predicted, target);
    else if (chosen == 0)
        out.reason = fmt("full quality fits: %.0f ms predicted for the %.0f ms target", predicted, target);
    else
        out.reason =
            fmt("%.2f of the size", pick.scale) +
            (out.vplCap > 0
                 ? " and " + std::to_string(out.vplCap) + " of " + std::to_string(requestedVpls) + " VPLs"
                 : std::string()) +
            fmt(" meet the %.0f ms target (%.0f ms predicted from this session's frames)", target, predicted);
    if (onlyFirst)
        out.reason += "; second frame of this scene and technique: predicted from the first one's passes, "
                      "without its compile time";
    return withLightViews();
}

} // namespace gis
