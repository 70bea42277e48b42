// Everything one frame depends on besides the scene: view, light, size, technique and parameters.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/Param.h"
#include "scene/Scene.h"

namespace gis {

/// One light of a frame: a scene light (or a default or added one) as the client or request left it.
struct FrameLight {
    std::string id; ///< stable while the state lives: "light0", "light1", ... (nextLightId())
    Light light;
    bool enabled = true;
};

/// The exposure a frame's `exposure` parameter adds to (frame/Exposure.h).
struct BaseExposure {
    double ev = 0.0;                 ///< EV; finite, within frame/Exposure.h's kMeterEvLimit
    std::string source = "authored"; ///< "authored" (the scene says), "default" (the default rig), "metered"
    std::string note;                ///< one sentence for the stats and the client
};

struct FrameState {
    Camera camera;
    /// Every light the frame may render, in order: the file's lights (all KHR_lights_punctual types),
    /// the default rig, a request's list, or the client's edits. The renderer shows at most
    /// max_lights of the enabled ones (frame/LightModel.h).
    std::vector<FrameLight> lights;
    /// Where `lights` came from: "scene" (the file's lights), "default" (frame/DefaultLighting.h: the
    /// file has no light) or "request" (an API render request's lights), with a sentence saying
    /// which or why; reported in the stats as `lighting`. A client editing, adding or removing lights
    /// keeps the source: they are still those lights, edited.
    std::string lightSource = "scene";
    std::string lightNote;
    /// The scene's base exposure (frame/Exposure.h baseExposure): lights edited later keep it.
    BaseExposure baseExposure;
    int width = 512;
    int height = 512;
    /// A tile of a larger image (tiled refinement, frame/Tiles.h): this frame renders the pixels
    /// [x, x + width) x [y, y + height), rows top to bottom, of a fullWidth x fullHeight image seen
    /// through the same camera; a tile may reach past the image's edges. fullWidth == 0: the frame is
    /// the whole image.
    struct Window {
        int x = 0, y = 0;
        int fullWidth = 0, fullHeight = 0;
        bool active() const { return fullWidth > 0 && fullHeight > 0; }
    } window;
    /// One of `count` interleaved VPL subsets of this frame (count 1: all of them). Where the
    /// technique supports it (TechniqueInfo::vplParts), part k's image shows the average of parts
    /// 0..k of the same size, window and state rendered just before it, so the image converges as the
    /// parts come and part count-1 shows every VPL: refinement's way to split a step that one slice
    /// cannot hold. Elsewhere each part renders the whole frame.
    struct VplPart {
        int index = 0;
        int count = 1;
        bool active() const { return count > 1; }
    } vplPart;
    /// The live view's interactive frames (session/FrameBudget.h): when this frame must draw its light
    /// views again (the lights or their parameters changed), it draws them at most this many texels
    /// per side, shadow maps and RSMs apart; maps kept from an earlier frame of the same lights serve
    /// as they are when their side lies between the cap and what the parameters ask. 0: no cap, the
    /// parameters' sides (every other frame).
    struct LightViewCap {
        int shadowSide = 0;
        int rsmSide = 0;
        bool active() const { return shadowSide > 0 || rsmSide > 0; }
    } lightViewCap;
    /// The live view's interactive frames: the technique's cost exponent at the VPLs this frame asks
    /// for, as the session's frames measured it there (FrameBudget::exponentAt; hier_isr's traversal
    /// grows as leaves^0.13 near 65,536 leaves at the default tau, against its fixed 0.4), which the
    /// receiver cap cuts the VPLs by (capVplsForReceivers). 0: the technique's fixed
    /// vplCostExponent (every other frame: a render request gives the same bytes whatever came before).
    double receiverCapExponent = 0.0;
    std::string technique = "rsm_gather";
    ParamSet frameParams;     ///< frameParamTable(): exposure, tone map, shadow and RSM sizes
    ParamSet techniqueParams; ///< the technique's own table
    /// The effect plan applied to this state (analysis/EffectPlan.h), copied into the stats as `plan`;
    /// null when none was made. The renderer only reports it.
    nlohmann::json plan;
};

} // namespace gis

namespace gis {

/// The scene's first camera and all its lights (a scene without any gets the default rig of
/// frame/DefaultLighting.h, with lightSource "default"), default frame parameters and the technique's
/// default parameters. Throws InputError for an unknown technique.
FrameState makeFrameState(const Scene& scene, const std::string& technique);
/// A light id not used by `state`'s lights ("lightN", N one past the largest in use).
std::string nextLightId(const FrameState& state);
/// The light with this id, or nullptr.
FrameLight* findLight(FrameState& state, const std::string& id);
/// Replaces the lights with `lights`, numbered light0, light1, ...
void setLights(FrameState& state, const std::vector<Light>& lights);
/// Switches technique, resetting its parameters to that technique's defaults.
void setTechnique(FrameState& state, const std::string& technique, const std::string& where = "technique");
/// Sets one parameter by name, in the frame table or the technique's table. Throws InputError.
void setParam(FrameState& state, const std::string& name, const nlohmann::json& value,
              const std::string& where);
void setParamFromString(FrameState& state, const std::string& name, const std::string& text,
                        const std::string& where);
/// Applies {name: value, ...} all or nothing. Returns the names that changed.
std::vector<std::string> applyParams(FrameState& state, const nlohmann::json& values,
                                     const std::string& where);
/// Both tables' values merged into one object.
nlohmann::json paramsJson(const FrameState& state);

/// Per-pass medians over several frames' stats (same shape as one frame's stats, plus "frames").
nlohmann::json medianStats(const std::vector<nlohmann::json>& frames);

} // namespace gis
