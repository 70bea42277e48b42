// Everything one frame depends on besides the scene: view, light, size, technique and parameters.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/Param.h"
#include "scene/Scene.h"

namespace gis {

struct FrameState {
    Camera camera;
    Light light; ///< the spotlight the pipeline renders (from the scene, or as the client moved it)
    bool lightEnabled = true;
    /// Where `light` came from: "scene" (the file's first spot light), "default" (frame/
    /// DefaultLighting.h: the file has no light the renderer shows) or "request" (an API render
    /// request's light), with a sentence saying which or why; reported in the stats as `lighting`.
    /// A client moving the light keeps the source: it is still that light, edited.
    std::string lightSource = "scene";
    std::string lightNote;
    int width = 512;
    int height = 512;
    std::string technique = "rsm_gather";
    ParamSet frameParams;     ///< frameParamTable(): exposure, tone map, shadow and RSM sizes
    ParamSet techniqueParams; ///< the technique's own table
    /// The effect plan applied to this state (analysis/EffectPlan.h), copied into the stats as `plan`;
    /// null when none was made. The renderer only reports it.
    nlohmann::json plan;
};

} // namespace gis

namespace gis {

/// The scene's first camera and first spot light (a scene without one gets the default key light of
/// frame/DefaultLighting.h, with lightSource "default"), default frame parameters and the technique's default
/// parameters. Throws InputError for an unknown technique.
FrameState makeFrameState(const Scene& scene, const std::string& technique);
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
