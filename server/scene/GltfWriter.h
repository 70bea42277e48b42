// A Scene written as one binary glTF 2.0 file (.glb): what gi-render --export writes, so a built-in
// scene can be opened in other tools and the loader's cost measured on files of any size.
#pragma once

#include <string>

#include "scene/Scene.h"

namespace gis {

/// Writes `scene` to `path`: one node per mesh (positions already in world space), POSITION, NORMAL,
/// TEXCOORD_0 and COLOR_0 where the mesh has them, 32-bit indices; metallic-roughness materials with
/// their textures (PNG), alpha mode and emissive strength; the lights (KHR_lights_punctual) and
/// cameras. Generated tangents are not written (a reader regenerates them). Throws gis::Error when
/// the file cannot be written.
void writeGlb(const Scene& scene, const std::string& path);

} // namespace gis
