#include "scene/SurfaceAnalysis.h"

#include <algorithm>
#include <cmath>

namespace gis {
namespace {

// A material is a mirror candidate when it is this metallic (dimensionless, [0, 1]).
constexpr float kMirrorMinMetallic = 0.9f;
// Vertices farther than this fraction of the mesh's extent from its plane make it curved.
constexpr float kPlanarTolerance = 1e-4f;

} // namespace

brdf::Surface materialSurface(const Material& m) {
    return brdf::surfaceFrom(m, glm::vec3(m.baseColor));
}

/// Whether every vertex of `mesh` lies within kPlanarTolerance of its extent from the area-weighted
/// plane of its triangles (oriented like its vertex normals).
Flatness flatness(const Mesh& mesh) {
    Flatness out;
    if (mesh.positions.empty() || mesh.indices.size() < 3) return out;
    out.lo = out.hi = glm::dvec3(mesh.positions[0]);
    for (const glm::vec3& p : mesh.positions) {
        out.lo = glm::min(out.lo, glm::dvec3(p));
        out.hi = glm::max(out.hi, glm::dvec3(p));
    }
    glm::dvec3 nsum(0.0), csum(0.0);
    double area = 0.0;
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const glm::dvec3 a(mesh.positions[mesh.indices[t]]), b(mesh.positions[mesh.indices[t + 1]]),
            c(mesh.positions[mesh.indices[t + 2]]);
        const glm::dvec3 cr = glm::cross(b - a, c - a);
        const double twice = glm::length(cr);
        if (!(twice > 0.0) || !std::isfinite(twice)) continue;
        // Orient each triangle's normal like its vertex normals, so mixed windings add up.
        glm::dvec3 tn = cr / twice;
        if (!mesh.normals.empty() && glm::dot(glm::dvec3(mesh.normals[mesh.indices[t]]), tn) < 0.0) tn = -tn;
        nsum += tn * (0.5 * twice);
        csum += (a + b + c) / 3.0 * (0.5 * twice);
        area += 0.5 * twice;
    }
    out.area = area;
    const double nlen = glm::length(nsum);
    if (!(area > 0.0) || !(nlen > 0.5 * area)) return out; // degenerate, or folded onto itself
    out.normal = nsum / nlen;
    out.centre = csum / area;
    const double extent = std::max(glm::length(out.hi - out.lo), 1e-12);
    out.flat = true;
    for (const glm::vec3& p : mesh.positions)
        if (std::abs(glm::dot(glm::dvec3(p) - out.centre, out.normal)) > kPlanarTolerance * extent) {
            out.flat = false;
            break;
        }
    return out;
}

/// The material of `mesh`, or null when its index is out of range.
const Material* meshMaterial(const Scene& scene, const Mesh& mesh) {
    if (mesh.material < 0 || mesh.material >= static_cast<int>(scene.materials.size())) return nullptr;
    return &scene.materials[static_cast<size_t>(mesh.material)];
}

std::vector<MirrorPlane> findPlanarMirrors(const Scene& scene, float maxRoughness) {
    struct Candidate {
        MirrorPlane plane;
        float area = 0.0f;
    };
    std::vector<Candidate> found;
    for (size_t mi = 0; mi < scene.meshes.size(); ++mi) {
        const Material* material = meshMaterial(scene, scene.meshes[mi]);
        if (!material) continue;
        const Material& mat = *material;
        const Mesh& mesh = scene.meshes[mi];
        // An instanced mesh is several planes: none of them is a mirror (they read the room probe).
        if (mesh.instanced()) continue;
        if (mat.metallic < kMirrorMinMetallic || mat.roughness > maxRoughness) continue;
        const Flatness f = flatness(mesh);
        if (!f.flat) continue;
        const glm::dvec3 n = f.normal, centre = f.centre;
        const double area = f.area;
        Candidate c;
        c.plane.mesh = static_cast<int>(mi);
        c.plane.point = glm::vec3(centre);
        c.plane.normal = glm::vec3(n);
        c.plane.f0 = materialSurface(mat).f0;
        c.plane.roughness = mat.roughness;
        c.area = static_cast<float>(area);
        found.push_back(c);
    }
    std::stable_sort(found.begin(), found.end(),
                     [](const Candidate& a, const Candidate& b) { return a.area > b.area; });
    std::vector<MirrorPlane> out;
    for (size_t i = 0; i < found.size() && i < static_cast<size_t>(kMaxMirrors); ++i)
        out.push_back(found[i].plane);
    return out;
}

bool specularWorthAPass(const Material& m, float split) {
    return materialSurface(m).hasSpecular() && (m.metallic > 0.0f || m.roughness < split);
}

} // namespace gis
