#include "scene/SceneLoader.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <glm/trigonometric.hpp>

#include "scene/Geometry.h"

namespace gis {
namespace {

constexpr glm::vec3 kUp{0.0f, 1.0f, 0.0f};
constexpr float kFramingFov = 0.6981317f; // 40 degrees

/// Visits every triangle whose indices are in range; out-of-range ones are left for validateScene.
template <typename F> void forEachValidTriangle(const Mesh& mesh, F&& f) {
    const std::size_t n = mesh.positions.size();
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const std::uint32_t i0 = mesh.indices[t], i1 = mesh.indices[t + 1], i2 = mesh.indices[t + 2];
        if (i0 < n && i1 < n && i2 < n) f(i0, i1, i2);
    }
}

glm::vec3 faceNormal(const Mesh& m, std::uint32_t i0, std::uint32_t i1, std::uint32_t i2) {
    return areaNormal(m.positions[i0], m.positions[i1], m.positions[i2]);
}

void generateNormals(Mesh& mesh) {
    // Summing unnormalised cross products weights each face by its area, so slivers barely count.
    std::vector<glm::vec3> sum(mesh.positions.size(), glm::vec3(0.0f));
    forEachValidTriangle(mesh, [&](std::uint32_t i0, std::uint32_t i1, std::uint32_t i2) {
        const glm::vec3 n = faceNormal(mesh, i0, i1, i2);
        if (!isFinite(n)) return;
        sum[i0] += n;
        sum[i1] += n;
        sum[i2] += n;
    });
    mesh.normals.resize(mesh.positions.size());
    // Zero sums (opposing faces cancelling, only degenerate faces) are fixed by repairNormals.
    for (std::size_t i = 0; i < sum.size(); ++i) mesh.normals[i] = safeNormalize(sum[i], glm::vec3(0.0f));
}

void repairNormals(Mesh& mesh) {
    if (mesh.normals.size() != mesh.positions.size()) return; // reported by validateScene
    std::vector<bool> bad(mesh.normals.size(), false);
    bool anyBad = false;
    for (std::size_t i = 0; i < mesh.normals.size(); ++i) {
        const glm::vec3 n = safeNormalize(mesh.normals[i], glm::vec3(0.0f));
        mesh.normals[i] = n;
        bad[i] = n == glm::vec3(0.0f);
        anyBad = anyBad || bad[i];
    }
    if (!anyBad) return;
    std::vector<bool> fixed(bad.size(), false);
    forEachValidTriangle(mesh, [&](std::uint32_t i0, std::uint32_t i1, std::uint32_t i2) {
        const glm::vec3 n = safeNormalize(faceNormal(mesh, i0, i1, i2), glm::vec3(0.0f));
        if (n == glm::vec3(0.0f)) return;
        for (std::uint32_t i : {i0, i1, i2})
            if (bad[i] && !fixed[i]) {
                mesh.normals[i] = n;
                fixed[i] = true;
            }
    });
    for (std::size_t i = 0; i < bad.size(); ++i)
        if (bad[i] && !fixed[i]) mesh.normals[i] = kUp;
}

// Per-vertex tangents from the texture coordinates (each triangle's dP/du, summed by area as the
// normals are, then made orthogonal to the normal); w is the bitangent's handedness. glTF's texture
// v runs down the image while a normal map's +y is up it, so the bitangent b = w cross(n, t) points
// along -dP/dv, as the MikkTSpace tangents exporters write. Vertices on no usable triangle get a zero
// tangent, which leaves their normal unmapped.
void generateTangents(Mesh& mesh) {
    const std::size_t n = mesh.positions.size();
    if (mesh.texcoords.size() != n || mesh.normals.size() != n) return;
    std::vector<glm::vec3> tangent(n, glm::vec3(0.0f)), bitangent(n, glm::vec3(0.0f));
    forEachValidTriangle(mesh, [&](std::uint32_t i0, std::uint32_t i1, std::uint32_t i2) {
        const glm::vec3 e1 = mesh.positions[i1] - mesh.positions[i0],
                        e2 = mesh.positions[i2] - mesh.positions[i0];
        const glm::vec2 d1 = mesh.texcoords[i1] - mesh.texcoords[i0],
                        d2 = mesh.texcoords[i2] - mesh.texcoords[i0];
        const float det = d1.x * d2.y - d2.x * d1.y;
        if (!(std::fabs(det) > 1e-20f)) return; // degenerate mapping
        const glm::vec3 t = (e1 * d2.y - e2 * d1.y) / det, b = (e2 * d1.x - e1 * d2.x) / det;
        if (!isFinite(t) || !isFinite(b)) return;
        // Weighted by the triangle's area (|cross| of its edges), as the normals.
        const float area = glm::length(glm::cross(e1, e2));
        const float scale = area / std::max(glm::length(t), 1e-30f);
        for (std::uint32_t i : {i0, i1, i2}) {
            tangent[i] += t * scale;
            bitangent[i] += b * scale;
        }
    });
    mesh.tangents.assign(n, glm::vec4(0.0f));
    for (std::size_t i = 0; i < n; ++i) {
        const glm::vec3 nrm = mesh.normals[i];
        const glm::vec3 t = safeNormalize(tangent[i] - nrm * glm::dot(nrm, tangent[i]), glm::vec3(0.0f));
        if (t == glm::vec3(0.0f)) continue;
        const float w = glm::dot(glm::cross(nrm, t), bitangent[i]) > 0.0f ? -1.0f : 1.0f;
        mesh.tangents[i] = glm::vec4(t, w);
    }
}

Camera framingCamera(const Bounds& bounds) {
    const float radius = std::max(bounds.radius(), 1e-3f);
    const float distance = radius / std::sin(0.5f * kFramingFov);
    Camera cam;
    cam.name = "framing";
    cam.target = bounds.center();
    // A three-quarter view from above (30 degrees round from +z, 25 up): a flat model (a terrain, a
    // field, a floor plan) seen level would be an edge; any direction fits the bounding sphere.
    const float azimuth = glm::radians(30.0f), elevation = glm::radians(25.0f);
    const glm::vec3 towardEye(std::cos(elevation) * std::sin(azimuth), std::sin(elevation),
                              std::cos(elevation) * std::cos(azimuth));
    cam.position = cam.target + distance * towardEye;
    cam.up = kUp;
    cam.yfovRadians = kFramingFov;
    cam.znear = std::max(0.5f * (distance - radius), 1e-3f * distance);
    cam.zfar = distance + 2.0f * radius;
    return cam;
}

} // namespace

void finalizeScene(Scene& scene, const std::string& where) {
    for (auto& mesh : scene.meshes) {
        if (mesh.normals.empty()) generateNormals(mesh);
        repairNormals(mesh);
    }
    for (auto& mesh : scene.meshes) {
        const bool mapped = mesh.material >= 0 && mesh.material < static_cast<int>(scene.materials.size()) &&
                            scene.materials[static_cast<std::size_t>(mesh.material)].normalTexture >= 0;
        if (mapped && mesh.tangents.empty()) generateTangents(mesh);
    }
    if (scene.materials.empty()) scene.materials.push_back(Material{.name = "default"});
    scene.updateBounds();
    if (scene.cameras.empty() && !scene.meshes.empty()) scene.cameras.push_back(framingCamera(scene.bounds));
    validateScene(scene, where);
}

} // namespace gis
