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
        const Bounds own = ownBounds(m);
        for (const glm::mat4& toWorld : m.instances) {
            const Bounds placed = placedBounds(own, toWorld);
            add(placed.min);
            add(placed.max);
        }
    }
    bounds = any ? Bounds{lo, hi} : Bounds{};
}

Bounds ownBounds(const Mesh& mesh) {
    if (mesh.positions.empty()) return {};
    Bounds out{mesh.positions[0], mesh.positions[0]};
    for (const glm::vec3& p : mesh.positions) {
        out.min = glm::min(out.min, p);
        out.max = glm::max(out.max, p);
    }
    return out;
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

Scene flattenInstances(const Scene& scene) {
    Scene out = scene;
    Mesh placed; // one placement at a time, its buffers reused
    for (Mesh& flat : out.meshes) {
        if (!flat.instanced()) continue;
        const Mesh mesh = std::move(flat);
        // Every placement in one mesh: a field of 200,000 one-triangle blades is one mesh of
        // 200,000 triangles here, not 200,000 meshes (each a BVH geometry of its own).
        Mesh merged{.name = mesh.name, .material = mesh.material};
        const auto append = [](auto& into, const auto& from) {
            into.insert(into.end(), from.begin(), from.end());
        };
        for (const glm::mat4& toWorld : mesh.instances) {
            placed.positions = mesh.positions;
            placed.normals = mesh.normals;
            placed.tangents = mesh.tangents;
            placed.indices = mesh.indices;
            transformMesh(placed, toWorld);
            const auto base = static_cast<std::uint32_t>(merged.positions.size());
            for (std::uint32_t& index : placed.indices) index += base;
            append(merged.positions, placed.positions);
            append(merged.normals, placed.normals);
            append(merged.tangents, placed.tangents);
            append(merged.texcoords, mesh.texcoords);
            append(merged.colors, mesh.colors);
            append(merged.indices, placed.indices);
        }
        flat = std::move(merged);
    }
    return out;
}

} // namespace gis
