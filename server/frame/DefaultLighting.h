// Default lighting for a scene the renderer would otherwise show black: a file with no lights (most
// downloaded models). The rig is a key light "over the camera's shoulder" and a dim fill, sized from
// the scene bounds and the view so that it works at any scale. The key:
//   - position: the bounds' centre plus 2.5 bounding radii along the direction to the camera,
//     turned 35 degrees up and 25 degrees to the camera's right (the classic key-light placement);
//   - a spot aimed at the centre whose outer cone covers the bounding sphere with 15% margin
//     (at most 80 degrees), inner cone 80% of the outer, so the whole model is lit with a soft edge;
//   - intensity chosen for an illuminance of 1.6 lux at the centre, the built-in Cornell box's floor
//     value, so the default exposure suits it; colour white.
// A spot key (rather than a directional one) keeps the light's reach inside the bounding sphere, so
// its shadow map spends its texels on the model. The fill: a directional light from the camera's
// other side, 20 degrees below the view axis, at 20% of the key's illuminance (0.32 lux), so faces
// the key cannot see are dim rather than black. Both are editable like any light.
#pragma once

#include <string>

#include "scene/Scene.h"

namespace gis {

struct DefaultLighting {
    Light key;
    Light fill;
    std::string reason; ///< why the default is used, for the stats and the client
};

/// The key light for `bounds` seen from `camera`. Finite for any finite bounds and camera (a camera
/// at the centre or a degenerate box fall back to looking down -z with radius 1e-3 at least).
Light defaultKeyLight(const Bounds& bounds, const Camera& camera);

/// The fill light for `bounds` seen from `camera` (directional, see above).
Light defaultFillLight(const Bounds& bounds, const Camera& camera);

/// The rig for a scene without lights, and the reason.
DefaultLighting defaultLighting(const Scene& scene, const Camera& camera);

} // namespace gis
