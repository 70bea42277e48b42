// Which surfaces of a scene call for which reflection effect: planar mirrors, specular lobes worth
// an indirect pass, flat and curved meshes. GL-free: the renderer's effect decisions
// (render/Reflections) and the effect plan (analysis/EffectPlan) ask the same questions here.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "scene/Brdf.h"
#include "scene/Scene.h"

namespace gis {

/// A planar mirror: a flat mesh with a smooth metallic material.
struct MirrorPlane {
    int mesh = -1;                      ///< index into Scene::meshes
    glm::vec3 point{0.0f};              ///< a point of the plane (m): the mesh's centroid
    glm::vec3 normal{0.0f, 1.0f, 0.0f}; ///< unit; the side the mesh's vertex normals face
    glm::vec3 f0{1.0f};                 ///< reflectance at normal incidence
    float roughness = 0.0f;             ///< the material's, for the optional glossy blur
};

/// Which meshes of `scene` are planar mirrors: material metallic >= 0.9 and roughness <=
/// maxRoughness, every vertex within 1e-4 of the mesh's extent from its best-fit plane, and a
/// non-degenerate area. At most kMaxMirrors, the largest first.
std::vector<MirrorPlane> findPlanarMirrors(const Scene& scene, float maxRoughness);
inline constexpr int kMaxMirrors = 4;

/// Whether a material's specular lobe is worth an indirect specular pass (environment probe or glossy
/// VPL transport): metals always, dielectrics only below `split` roughness. A rough dielectric
/// reflects a few percent (F0 = 0.04) of a blurred environment, close to what its diffuse lobe
/// already gets; it keeps its direct highlights. So a glTF file of plain materials (roughness 1)
/// runs no reflection pass.
bool specularWorthAPass(const Material& m, float split);

/// The mesh's best-fit plane and whether every vertex lies within 1e-4 of the mesh's extent from it
/// (area-weighted, oriented like the vertex normals); degenerate meshes are not flat.
struct Flatness {
    bool flat = false;
    glm::dvec3 normal{0.0, 1.0, 0.0}, centre{0.0};
    double area = 0.0;
    glm::dvec3 lo{0.0}, hi{0.0}; ///< the mesh's bounds (m)
};
Flatness flatness(const Mesh& mesh);

/// The material of `mesh`, or null when its index is out of range.
const Material* meshMaterial(const Scene& scene, const Mesh& mesh);

/// The reflection model's view of a material (scene/Brdf.h) with its base colour.
brdf::Surface materialSurface(const Material& m);

} // namespace gis
