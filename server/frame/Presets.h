// Quality presets per technique (presets/presets.json), chosen by `gi-bench report` from the
// measured error-versus-time fronts (docs/accuracy.md) and applied before explicit overrides:
// `gi-render --preset NAME`, and the server's adaptive quality.
//
// File shape: {"techniques": {TECH: {"interactive": {param: value, ...}, "balanced": {...},
// "final": {...}}}, ...}; each preset holds only the parameters that differ from the technique's
// defaults, so parameters added to a table later keep their defaults.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "frame/FrameState.h"

namespace gis {

/// $GI_PRESETS when set, else the source tree's presets/presets.json.
std::string defaultPresetsPath();
/// Reads and checks the file's shape. Throws InputError naming the path.
nlohmann::json loadPresets(const std::string& path);
/// "interactive", "balanced", "final".
const std::vector<std::string>& knownPresets();

/// The parameter object of preset `name` for `technique`. Throws InputError ("preset 'x': ...") for
/// an unknown preset name (listing the valid ones) or a technique the file has no presets for.
nlohmann::json presetParams(const nlohmann::json& presets, const std::string& technique,
                            const std::string& name);
/// Same, from defaultPresetsPath() (read once per process).
nlohmann::json presetParams(const std::string& technique, const std::string& name);

/// Applies the preset to the state's technique parameters through the same validation as any other
/// change (all or nothing); errors name the preset.
void applyPreset(FrameState& state, const nlohmann::json& presets, const std::string& name);
/// Same, from defaultPresetsPath().
void applyPreset(FrameState& state, const std::string& name);

/// The file's "default_technique": {"name": TECH, "reason": ...} (gi-bench report: the technique whose
/// interactive preset has the lowest error within the interactive budget); "" when absent.
std::string presetDefaultTechnique(const nlohmann::json& presets);

} // namespace gis
