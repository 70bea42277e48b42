// The exposure a frame starts from: the EV that the `exposure` parameter adjusts. The built-in scenes
// and the default light rig are lit for EV 0. A file's own lights come in any strength (Blender
// exports a 60 W lamp as about 3,000 cd and its sun as over a thousand lux, ten stops above the
// built-in Cornell box), so the frame meters them, once, from the scene and its lights rather than
// from a view, so that the exposure does not change as the camera moves. An incident-light meter, as
// a photographer's: it reads the light falling on the surfaces, not what they reflect, so black or
// white materials do not fool it.
//   - up to kMeterTriangles triangles, taken at an even stride through every mesh's placements;
//   - at each centroid, the illuminance every enabled light sends there (its cone, range and inverse
//     square law; no shadows: the meter casts no rays), on whichever side faces the light;
//   - the area-weighted geometric mean over the lit ones (robust to a lamp right above one spot),
//     against the same mean of the built-in Cornell box (kMeterKeyIlluminance), which EV 0 was made
//     for: EV = log2(key_cornell / key).
// Known limit: without shadows, a room lit through its window by a sun meters as if the sun reached
// every wall (the built-in sun-room meters 3.3 EV darker than it was made for).
// The result lies in [-kMeterEvLimit, kMeterEvLimit]. The frame parameter `metering` off makes the
// `exposure` parameter absolute again (comparing light strengths).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "frame/FrameState.h"
#include "scene/Scene.h"

namespace gis {

/// Triangles the meter visits at most (an even stride through larger scenes): enough for a mean
/// over surfaces, a few milliseconds for a million-triangle file.
constexpr std::size_t kMeterTriangles = 65536;
/// The built-in Cornell box's metered key (lux in the renderer's units): the area-weighted geometric
/// mean of the illuminance on its lit surfaces, measured by meterLight and rounded. EV 0 shows
/// it as made.
constexpr double kMeterKeyIlluminance = 0.75;
/// Largest correction, in EV, either way: 2^24 spans a millicandela lamp to a hundred-kilolux sun.
constexpr double kMeterEvLimit = 24.0;

struct MeteredLight {
    double key = 0.0;        ///< area-weighted geometric mean illuminance (lux) of the lit ones; 0: none
    std::size_t samples = 0; ///< triangles visited
    std::size_t lit = 0;     ///< of which some light reached
    double litArea = 0.0;    ///< their area over the visited area, in [0, 1]
};

/// The meter's reading of `scene` under `lights` (the enabled ones); pure and deterministic.
MeteredLight meterLight(const Scene& scene, const std::vector<FrameLight>& lights);

/// The scene's base exposure (FrameState::baseExposure): authored by the scene, EV 0 for the default
/// rig (a file without lights), or metered from the file's own lights. It depends on the scene only:
/// lights edited in a session or given by a request keep it, so their changes show.
BaseExposure baseExposure(const Scene& scene);

/// The stats' and state's `lighting.exposure`: {base_ev (as metering applies it), source, note,
/// ev (what the frame tone-maps with)}.
nlohmann::json baseExposureJson(const FrameState& state);

/// An EV value for messages: signed, one decimal ("-11.3 EV").
std::string evText(double ev);

/// The EV a frame tone-maps with: the base (unless `metering` is off) plus the `exposure` parameter.
double frameExposureEv(const FrameState& state);

} // namespace gis
