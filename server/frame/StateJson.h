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

/// The fields of a light (protocol/PROTOCOL.md `light`): any of "type" ("spot", "point",
/// "directional"), "name", "position": [x, y, z] (m), "direction": [x, y, z] (normalised, non-zero),
/// "intensity": 0..1e6 (cd; lux for directional), "color": [r, g, b] in [0, 1], "range": >= 0 (m, 0
/// infinite), "cone_deg": 1..85 (outer half-angle; the inner cone keeps its proportion of the outer
/// one unless "inner_cone_deg" is given, which must be smaller), "enabled": bool; absent fields keep
/// their value. `applyLightJson` takes a `light` message: the fields nested in "light" (protocol 2,
/// "type" there is the light's) or flat beside the message's "type" (protocol 1, which cannot change
/// the light's type); it edits the light named by "id" (beside or inside "light"), or the first light
/// when there is none (protocol 1's single light; with no light at all it adds one).
void applyLightJson(FrameState& state, const nlohmann::json& light, const std::string& where);
/// Edits light `id` ("" = the first; none at all: adds one) with `fields` (the light's "type" read
/// only when `allowType`); `idWhere` is the pointer an unknown id is reported at (default where/id).
void editLightJson(FrameState& state, const std::string& id, const nlohmann::json& fields,
                   const std::string& where, bool allowType = true, const std::string& idWhere = {});
/// Adds a light from those fields (defaults: a white 1 cd spot at the origin pointing down), under
/// its "id" when given (which must be new), else nextLightId(). Returns the id.
std::string addLightJson(FrameState& state, const nlohmann::json& light, const std::string& where);
/// Removes light `id`; throws InputError listing the ids when there is none.
void removeLight(FrameState& state, const std::string& id, const std::string& where);
/// Replaces every light with the array `lights` (each needs a "type"), all or nothing.
void setLightsJson(FrameState& state, const nlohmann::json& lights, const std::string& where);
/// Lights a frame state may hold (the renderer shows at most max_lights of them).
constexpr std::size_t kMaxFrameLights = 256;

/// {"position", "target", "up", "fov_deg"}.
nlohmann::json cameraJson(const Camera& camera);
/// {"id", "name", "type", "position", "direction", "intensity", "color", "range", "cone_deg",
/// "inner_cone_deg", "enabled"}.
nlohmann::json lightJson(const FrameLight& light);
/// Every light, in order.
nlohmann::json lightsJson(const FrameState& state);
/// The first light (protocol 1's `light`), null when there is none.
nlohmann::json lightJson(const FrameState& state);

} // namespace gis
