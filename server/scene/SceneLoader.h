// Scene loading entry points: built-in scenes and glTF files, both finished the same way so every
// consumer can rely on the guarantees listed on finalizeScene. Only gis::InputError leaves these
// functions; bad files never crash the process.
#pragma once

#include <string>
#include <vector>

#include "scene/Scene.h"

namespace gis {

/// "builtin:NAME" for a scene generated in code, otherwise a path ending in .gltf or .glb.
Scene loadScene(const std::string& name);

/// Names accepted by makeBuiltinScene (and by loadScene after "builtin:").
std::vector<std::string> builtinSceneNames();
Scene makeBuiltinScene(const std::string& name);

/// Loads a .gltf (JSON, external or data-URI buffers) or .glb file, flattened to world space.
Scene loadGltf(const std::string& path);

/// Brings a freshly built scene to the loaded-scene guarantees, then validates it:
///  - missing normals generated as area-weighted vertex normals (cross products summed over the
///    triangles sharing an index, so shared vertices smooth and split vertices stay hard);
///  - non-finite or zero normals replaced by the face normal, or (0, 1, 0) on degenerate faces;
///  - a default white diffuse material when there is none;
///  - bounds recomputed, and a camera framing them when there is none.
/// Throws InputError(where, ...) when the scene is still invalid.
void finalizeScene(Scene& scene, const std::string& where);

/// Checks the invariants documented in Scene.h; throws InputError(where, message naming the mesh,
/// light, material or camera and the problem). Degenerate triangles are allowed.
void validateScene(const Scene& scene, const std::string& where);

} // namespace gis
