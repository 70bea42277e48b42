// The camera and light of a FrameState as JSON, in the shapes of protocol/PROTOCOL.md (`camera` and
// `light` messages, the `state` object) and of POST /api/render: one place for their meaning, so the
// WebSocket session, the HTTP API and gi-render --request move the camera and light the same way.
//
// The apply functions check everything they read, whether or not a schema ran before (types, finite
// values, the protocol's ranges, and what a schema cannot say: position != target, non-zero up and
// direction), and change the state only when the whole object is valid. Keys they do not know are
// ignored (the schemas reject them; a protocol message also carries "type"). Errors are
// InputError(where + "/field", reason) with `where` the JSON pointer of the object ("" for a whole
// message, "/camera" inside a render request).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "frame/FrameState.h"

namespace gis {

/// {"position": [x, y, z], "target": [x, y, z], "up"?: [x, y, z], "fov_deg"?: 1..170} in world
/// metres. position and target are required; up and fov_deg keep their current value when absent.
void applyCameraJson(FrameState& state, const nlohmann::json& camera, const std::string& where);

/// Any of {"position": [x, y, z], "direction": [x, y, z] (normalised, non-zero), "intensity": >= 0 (cd),
/// "color": [r, g, b] in [0, 1], "cone_deg": 1..85 (outer half-angle; the inner cone keeps its
/// proportion of the outer one), "enabled": bool}; absent fields keep their value.
void applyLightJson(FrameState& state, const nlohmann::json& light, const std::string& where);

/// {"position", "target", "up", "fov_deg"}.
nlohmann::json cameraJson(const Camera& camera);
/// {"position", "direction", "intensity", "color", "cone_deg", "enabled"} of the state's spotlight.
nlohmann::json lightJson(const FrameState& state);

} // namespace gis
