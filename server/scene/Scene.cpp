#include "scene/Scene.h"

#include <limits>
#include <utility>

#include <glm/gtc/matrix_inverse.hpp>

#include "scene/Geometry.h"

namespace gis {

std::size_t Scene::triangleCount() const {
    std::size_t n = 0;
    for (const auto& m : meshes) n += m.indices.size() / 3 * m.placements();
    return n;
}

std::size_t Scene::storedTriangleCount() const {
    std::size_t n = 0;
    for (const auto& m : meshes) n += m.indices.size() / 3;
    return n;
}

std::size_t Scene::instanceCount() const {
    std::size_t n = 0;
    for (const auto& m : meshes) n += m.instances.size();
    return n;
}

void Scene::updateBounds() {
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    bool any = false;
    const auto add = [&](const glm::vec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
        any = true;
    };
    for (const auto& m : meshes) {
        if (!m.instanced()) {
            for (const auto& p : m.positions) add(p);
            continue;
        }
        if (m.positions.empty()) continue;
        glm::vec3 ownLo = m.positions[0], ownHi = m.positions[0];
        for (const auto& p : m.positions) {
            ownLo = glm::min(ownLo, p);
            ownHi = glm::max(ownHi, p);
        }
        for (const glm::mat4& toWorld : m.instances) {
            const Bounds placed = placedBounds({ownLo, ownHi}, toWorld);
            add(placed.min);
            add(placed.max);
        }
    }
    bounds = any ? Bounds{lo, hi} : Bounds{};
}

Bounds placedBounds(const Bounds& own, const glm::mat4& toWorld) {
    Bounds out{glm::vec3(std::numeric_limits<float>::max()), glm::vec3(-std::numeric_limits<float>::max())};
    for (int corner = 0; corner < 8; ++corner) {
        const glm::vec3 p(toWorld * glm::vec4(corner & 1 ? own.max.x : own.min.x,
                                              corner & 2 ? own.max.y : own.min.y,
                                              corner & 4 ? own.max.z : own.min.z, 1.0f));
        out.min = glm::min(out.min, p);
        out.max = glm::max(out.max, p);
    }
    return out;
}

void transformMesh(Mesh& mesh, const glm::mat4& toWorld) {
    const glm::mat3 linear(toWorld);
    const glm::mat3 normalMatrix = glm::inverseTranspose(linear);
    for (auto& p : mesh.positions) p = glm::vec3(toWorld * glm::vec4(p, 1.0f));
    for (auto& n : mesh.normals) n = safeNormalize(normalMatrix * n, glm::vec3(0.0f));
    // Tangents follow the surface (the linear part); a mirror flips the bitangent's handedness. One
    // that is zero or not finite stays zero: that vertex's normal is left unmapped.
    const bool mirrored = glm::determinant(linear) < 0.0f;
    for (auto& t : mesh.tangents) {
        const glm::vec3 v = safeNormalize(linear * glm::vec3(t), glm::vec3(0.0f));
        t = v == glm::vec3(0.0f) ? glm::vec4(0.0f)
                                 : glm::vec4(v, (t.w < 0.0f ? -1.0f : 1.0f) * (mirrored ? -1.0f : 1.0f));
    }
    if (mirrored)
        for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3)
            std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
}

Scene flattenInstances(const Scene& scene, std::vector<int>* sourceMesh) {
    Scene out;
    out.name = scene.name;
    out.materials = scene.materials;
    out.textures = scene.textures;
    out.lights = scene.lights;
    out.cameras = scene.cameras;
    out.bounds = scene.bounds;
    out.notShown = scene.notShown;
    if (sourceMesh) sourceMesh->clear();
    for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
        const Mesh& mesh = scene.meshes[i];
        if (!mesh.instanced()) {
            out.meshes.push_back(mesh);
            if (sourceMesh) sourceMesh->push_back(static_cast<int>(i));
            continue;
        }
        for (std::size_t k = 0; k < mesh.instances.size(); ++k) {
            Mesh placed = mesh;
            placed.instances.clear();
            placed.name.append(1, '@').append(std::to_string(k));
            transformMesh(placed, mesh.instances[k]);
            out.meshes.push_back(std::move(placed));
            if (sourceMesh) sourceMesh->push_back(static_cast<int>(i));
        }
    }
    return out;
}

} // namespace gis
