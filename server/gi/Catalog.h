// The GL-free half of every technique (DESIGN.md §4): name, paper, parameter table and the
// capabilities other layers ask about, so that the frame description, the CPU reference, the effect
// plan, the server's limits and the client read them without linking the renderer (CMake target
// gis_catalog, below frame/). Each technique's folder defines its entry in Info.cpp;
// gi/Technique.h pairs the entries with the GL implementations, in the same order.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/Param.h"

namespace gis {

struct TechniqueInfo {
    std::string name;        ///< registry key, e.g. "rsm_gather"
    std::string description; ///< one line
    std::string paper;       ///< seed paper and section
    ParamTable params;
    /// Whether the technique carries glossy VPL transport with these parameters (FrameInputs::glossy;
    /// docs/nondiffuse.md); empty for none. The planner reads it without creating the technique.
    std::function<bool(const ParamSet&)> glossyTransport;
    /// The most VPLs (or virtual lights) one frame with these technique and frame parameters uses:
    /// what --max-vpls bounds and what the refinement predictor scales by. Empty: none.
    std::function<long(const ParamSet& technique, const ParamSet& frame)> vplEstimate;
    /// Lowers the technique's VPL knob so that vplEstimate is at most `vpls` (never raises it): how
    /// the session's frame budget (session/FrameBudget.h) makes an interactive frame cheaper. Empty:
    /// the count cannot be capped (hier_isr's cut adapts per receiver instead).
    std::function<void(ParamSet& technique, long vpls)> limitVpls;
    /// Caps the gather's work per frame at `share` receivers per pixel (the techniques that gather over
    /// the eye hierarchy's receiver list): a frame whose hierarchy selects more receivers than `share`
    /// of its pixels gathers from proportionally fewer VPLs, so that receivers x VPLs stay at what
    /// `share` would cost. The frame budget sets it from its last frame's share: the receivers, and
    /// with them the gather's time, can grow tenfold between two frames of an orbit, which no cost
    /// model fitted on the frames before predicts. Empty: no such cap.
    std::function<void(ParamSet& technique, double share)> capReceiverShare;
    /// How the technique's passes' time grows with vplEstimate: about vpls^vplCostExponent (at a fixed
    /// size). 1 for the techniques that sum over every VPL; below 1 for a traversal whose cut grows
    /// much more slowly than its leaves (hier_isr). The frame budget models and caps with it.
    double vplCostExponent = 1.0;
    /// The exponent near a rendered frame's own VPL count, from its counters (stats.counts), for the
    /// frame budget's model of the next interactive frames (frameVplCostExponent). Empty: the
    /// technique's cost has one exponent. hier_isr's traversal grows about linearly with its leaves
    /// at tau 0, and at a few hundred leaves at any tau, but far more slowly over thousands at tau
    /// 0.01, so that no one exponent fits both the live view's frames and a final step.
    std::function<double(const nlohmann::json& counts)> localVplCostExponent;
    /// The passes (gl::Pass names) whose time grows with vplEstimate, as vpls^vplCostExponent: the
    /// gathers and splats over the VPLs and what is built over them. The rest of a frame (shadow maps,
    /// G-buffer, eye hierarchy, upsampling) costs about the same at any VPL count, so a refinement
    /// step predicted from a frame with far fewer VPLs scales only these (AdaptiveQuality). Empty: the
    /// whole frame is taken to scale. tests/gl/TechniquesGlTest.cpp checks that a frame has each.
    std::vector<std::string> vplPasses;
    /// The passes that run only when the light views are drawn again and whose time grows with the
    /// RSMs' texels (the light tree built over them): the frame budget counts them with the light
    /// views rather than with the pixels (session/FrameBudget.h). Empty: none.
    std::vector<std::string> lightViewPasses;
    /// Effect knobs the effect plan may set (docs/effects.md): the multiresolution eye hierarchy
    /// (coarsest_size and the discontinuity thresholds of gi/common/ParamSpecs.h), VPL visibility
    /// (vpl_shadows) and bias compensation (clamp_b, ssbc_iterations).
    bool eyeHierarchy = false;
    bool vplVisibility = false;
    bool biasCompensation = false;
    /// Whether execute() reads the lights' RSMs (lights.rsm.*): the renderer skips the RSM passes,
    /// one per light view, for a technique that does not.
    bool readsRsm = true;
    /// Whether it samples lights from the camera's view (second_order's negative lights): a tile of a
    /// refinement step (frame/Tiles.h) then samples its own set, so tiles differ slightly at their
    /// seams where a whole frame would not (tests/gl/TilesGlTest.cpp measures by how much).
    bool viewSampled = false;
    /// Whether, with these parameters, its indirect light already carries indirect shadows (vpl_shadows
    /// on, second_order's negative lights): the renderer then leaves glTF occlusion maps out of it.
    /// Empty: never.
    std::function<bool(const ParamSet&)> indirectShadows;
    /// Whether, with these parameters, the technique honours FrameInputs::vplPart: it renders one of
    /// vplParts interleaved subsets of its VPLs scaled by vplParts, so that the average of the parts
    /// is the whole set's indirect light (it is linear in the VPLs: no screen-space pass on the sum).
    /// Refinement then spreads a step too slow for one slice over several (FrameState::VplPart).
    /// Empty: never.
    std::function<bool(const ParamSet& technique)> vplParts;
};

/// Every technique, in the registry's stable order.
const std::vector<TechniqueInfo>& techniqueCatalog();
/// Throws gis::InputError(where, ...) listing the known names when `name` is unknown.
const TechniqueInfo& findTechniqueInfo(const std::string& name, const std::string& where = "technique");

/// x^2 for VPL grids and light-tree sides (a long, so 256^2 and 1024^2 fit).
inline long squared(long x) {
    return x * x;
}
/// vplEstimate of the grid-VPL techniques: vpl_grid^2.
inline long gridVplEstimate(const ParamSet& technique, const ParamSet&) {
    return squared(technique.getInt("vpl_grid"));
}
/// limitVpls of the grid-VPL techniques: the largest vpl_grid with vpl_grid^2 <= vpls.
void limitGridVpls(ParamSet& technique, long vpls);

/// A technique's vplCostExponent as the cost models use it (the frame
/// budget, refinement's planner, the receiver cap): within [0.05, 1] (above 1 would model VPLs
/// that cost more than linearly, 0 none at all); 1 when not finite.
double usableVplCostExponent(double exponent);

/// The cost exponent near a rendered frame with these counters: the technique's
/// localVplCostExponent where it has one and it gives a number, vplCostExponent otherwise; as
/// usableVplCostExponent makes it.
double frameVplCostExponent(const TechniqueInfo& info, const nlohmann::json& counts);

/// The receiver work cap (capReceiverShare) of a frame whose eye hierarchy listed `receivers` over
/// `pixels`, for a technique whose parameters ask for `estimate` VPLs (vplEstimate): where receivers
/// exceed receiver_share_cap x pixels, lowers the VPL knob through info.limitVpls to at most
/// estimate x (cap x pixels / receivers)^(1 / vplCostExponent), so that receivers x VPLs^exponent
/// stay at the cap's, and never below 16 VPLs (the frame budget's floor; a smaller estimate stays).
/// `exponent` > 0 replaces vplCostExponent: the technique's own measurement at `estimate` (hier_isr's
/// near its asked leaves, whose cost grows there far more slowly than the fixed exponent says).
/// Returns the VPLs it allowed, or 0 when the frame is within the cap (the parameters unchanged).
long capVplsForReceivers(const TechniqueInfo& info, ParamSet& technique, long estimate, double pixels,
                         double receivers, double exponent = 0.0);

// The entries, one per technique folder (gi/<name>/Info.cpp).
TechniqueInfo noIndirectInfo();
TechniqueInfo rsmGatherInfo();
TechniqueInfo ssbcInfo();
TechniqueInfo multiresSplatInfo();
TechniqueInfo multiresGatherInfo();
TechniqueInfo isrInfo();
TechniqueInfo hierIsrInfo();
TechniqueInfo secondOrderInfo();

} // namespace gis
