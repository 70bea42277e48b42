#include "scene/SceneLoader.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>

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

Camera framingCamera(const Bounds& bounds) {
    const float radius = std::max(bounds.radius(), 1e-3f);
    const float distance = radius / std::sin(0.5f * kFramingFov);
    Camera cam;
    cam.name = "framing";
    cam.target = bounds.center();
    cam.position = cam.target + glm::vec3(0.0f, 0.0f, distance);
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
    if (scene.materials.empty()) scene.materials.push_back(Material{.name = "default"});
    scene.updateBounds();
    if (scene.cameras.empty() && !scene.meshes.empty()) scene.cameras.push_back(framingCamera(scene.bounds));
    validateScene(scene, where);
}

} // namespace gis
