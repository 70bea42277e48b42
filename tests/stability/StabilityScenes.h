// Scenes of the S.4 hard cases, generated in code: analytic sphere, on-axis disk, floor and sky,
// depth edges, black regions, high-frequency normals, degenerate and NaN-carrying meshes, and
// transformed copies (scale, translation) of any scene. Scenes that must carry what finalizeScene
// or validateScene would repair or reject (NaN normals and positions) are returned as built, with
// only their bounds updated, so they reach the GPU as they are.
#pragma once

#include <memory>
#include <string>

#include "scene/Scene.h"

namespace gis::stability::scenes {

using ScenePtr = std::shared_ptr<const Scene>;

/// A built-in scene, loaded once per process.
ScenePtr builtin(const std::string& name);

/// Closed diffuse sphere of radius R and albedo rho around the origin, exact radial (inward)
/// normals, with a spot light at the centre pointing down (outer / inner cone in degrees) and a
/// camera at the centre looking sideways, so the view holds lit and unlit parts of the sphere.
ScenePtr sphere(float radius, float albedo, float outerDeg, float innerDeg);

/// On-axis disk (digest S.4 case 8): a diffuse disk of radius R at y = 0 facing up, a spot at height
/// H pointing down whose inner cone covers the disk, and a receiver plane at height h > H facing down
/// (above the light, so the spot does not light it). Camera between the two looking up at the
/// receiver above the disk centre.
ScenePtr disk(float radius, float lightHeight, float receiverHeight, float albedo);

/// Square floor of side `size` at y = 0 with the spot straight above at `height` (only the floor:
/// every VPL is coplanar with every receiver).
ScenePtr floorOnly(float size, float height);

/// Floor whose spot is tilted so that part of its cone misses all geometry (empty RSM texels), and
/// a camera that sees floor and background.
ScenePtr floorAndSky();

/// A back wall, a floor and a near panel whose vertical edge projects exactly onto the centre pixel
/// column boundary of an even-width image (on every eye level's cell boundary), plus a triangle with
/// a diagonal edge.
ScenePtr depthEdges();

/// A lit wall, half white and half black (covered, albedo 0), next to background, with a floor.
ScenePtr blackRegion();

/// A plane filling the view with pseudo-random per-vertex normals (worst-case refinement).
ScenePtr highFrequencyNormals(int grid);

/// cornell-empty plus a mesh of zero-area, collinear and duplicate-vertex triangles and one vertex
/// with a NaN normal, not finalised (the NaN reaches the GPU). With nanPosition, one extra triangle
/// has a NaN vertex position.
ScenePtr degenerate(bool nanPosition);

/// `base` scaled by s about the origin and moved by t: positions, camera (and its clip planes),
/// lights; the light intensity is multiplied by s^2 so irradiance, and so the image, is unchanged.
ScenePtr transformed(const ScenePtr& base, float scale, glm::vec3 translate, const std::string& name);

/// `base` with every material's albedo set to `albedo` (grey).
ScenePtr withAlbedo(const ScenePtr& base, float albedo, const std::string& name);
/// `base` with every mesh held in its own space (centred, turned 30 degrees about y) and placed by
/// one instance matrix (Mesh::instances), so the placement path carries the whole scene.
ScenePtr instanced(const ScenePtr& base, const std::string& name);

/// cornell-empty with a thin occluder 5 cm in front of the back wall (negative lights exceed
/// positive ones behind it, digest S.4 case 19b), or (offscreen) a panel beside the right wall that
/// the test's camera keeps out of view (case 19c).
ScenePtr cornellOccluder(bool offscreen);

} // namespace gis::stability::scenes
