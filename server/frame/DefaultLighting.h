// Default lighting for a scene the renderer would otherwise show black: a file with no lights (most
// downloaded models), or one whose lights are all of types the renderer cannot show yet (point and
// directional). The rig is one key light "over the camera's shoulder", sized from the scene bounds
// and the view so that it works at any scale:
//   - position: the bounds' centre plus 2.5 bounding radii along the direction to the camera,
//     turned 35 degrees up and 25 degrees to the camera's right (the classic key-light placement);
//   - a spot aimed at the centre whose outer cone covers the bounding sphere with 15% margin
//     (at most 80 degrees), inner cone 80% of the outer, so the whole model is lit with a soft edge;
//   - intensity chosen for an illuminance of 1.6 lux at the centre, the built-in Cornell box's floor
//     value, so the default exposure suits it; colour white.
// A spot was chosen over a directional sun because every technique's VPL set, the shadow map and
// the reference already handle spots; the result is editable like any light.
#pragma once

#include <string>

#include "scene/Scene.h"

namespace gis {

struct DefaultLighting {
    Light key;
    std::string reason; ///< why the default is used, for the stats and the client
};

/// The key light for `bounds` seen from `camera`. Finite for any finite bounds and camera (a camera
/// at the centre or a degenerate box fall back to looking down -z with radius 1e-3 at least).
Light defaultKeyLight(const Bounds& bounds, const Camera& camera);

/// The rig for a scene without a spot light, and the reason, naming the lights it cannot show.
DefaultLighting defaultLighting(const Scene& scene, const Camera& camera);

} // namespace gis
