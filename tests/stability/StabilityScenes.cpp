// Builds the S.4 scenes in code (see StabilityScenes.h). Surfaces are grids of quads so that vertex
// based techniques see more than two triangles per wall, as in server/scene/BuiltinScenes.cpp.
#include "StabilityScenes.h"

#include <cmath>
#include <limits>
#include <map>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "scene/SceneLoader.h"

namespace gis::stability::scenes {
namespace {

int addMaterial(Scene& s, const std::string& name, glm::vec3 albedo) {
    s.materials.push_back(Material{.name = name, .baseColor = glm::vec4(albedo, 1.0f)});
    return static_cast<int>(s.materials.size()) - 1;
}

/// n x n grid spanning origin + [0,1]u + [0,1]v, facing cross(u, v).
Mesh grid(const std::string& name, int material, glm::vec3 origin, glm::vec3 u, glm::vec3 v, int n = 8) {
    Mesh m{.name = name, .material = material};
    const glm::vec3 normal = glm::normalize(glm::cross(u, v));
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const float s = float(i) / float(n), t = float(j) / float(n);
            m.positions.push_back(origin + s * u + t * v);
            m.normals.push_back(normal);
            m.texcoords.emplace_back(s, t);
        }
    const auto row = static_cast<std::uint32_t>(n + 1);
    for (std::uint32_t j = 0; j < std::uint32_t(n); ++j)
        for (std::uint32_t i = 0; i < std::uint32_t(n); ++i) {
            const std::uint32_t p00 = j * row + i, p10 = p00 + 1, p01 = p00 + row, p11 = p01 + 1;
            m.indices.insert(m.indices.end(), {p00, p10, p11, p00, p11, p01});
        }
    return m;
}

Light spot(glm::vec3 position, glm::vec3 direction, float outerDeg, float innerDeg, float intensity = 6.0f) {
    return Light{.name = "spot",
                 .type = LightType::Spot,
                 .position = position,
                 .direction = glm::normalize(direction),
                 .intensity = intensity,
                 .innerConeAngle = glm::radians(innerDeg),
                 .outerConeAngle = glm::radians(outerDeg)};
}

Camera camera(glm::vec3 position, glm::vec3 target, float fovDeg = 40.0f, float znear = 0.05f,
              float zfar = 20.0f) {
    return Camera{.name = "default",
                  .position = position,
                  .target = target,
                  .up = glm::vec3(0, 1, 0),
                  .yfovRadians = glm::radians(fovDeg),
                  .znear = znear,
                  .zfar = zfar};
}

ScenePtr finish(Scene s, const std::string& name) {
    s.name = name;
    finalizeScene(s, name);
    return std::make_shared<const Scene>(std::move(s));
}

} // namespace

ScenePtr builtin(const std::string& name) {
    static std::map<std::string, ScenePtr> cache;
    auto& s = cache[name];
    if (!s) s = std::make_shared<const Scene>(loadScene("builtin:" + name));
    return s;
}

ScenePtr sphere(float radius, float albedo, float outerDeg, float innerDeg) {
    Scene s;
    const int mat = addMaterial(s, "sphere", glm::vec3(albedo));
    Mesh m{.name = "sphere", .material = mat};
    const int rings = 48, segments = 96;
    const double pi = glm::pi<double>();
    for (int j = 0; j <= rings; ++j)
        for (int i = 0; i <= segments; ++i) {
            const double theta = pi * j / rings, phi = 2.0 * pi * i / segments;
            const glm::dvec3 d(std::sin(theta) * std::cos(phi), std::cos(theta),
                               std::sin(theta) * std::sin(phi));
            m.positions.push_back(glm::vec3(d * double(radius)));
            m.normals.push_back(glm::vec3(-d)); // facing the centre, where light and camera are
            m.texcoords.emplace_back(float(i) / segments, float(j) / rings);
        }
    const auto row = static_cast<std::uint32_t>(segments + 1);
    for (std::uint32_t j = 0; j < std::uint32_t(rings); ++j)
        for (std::uint32_t i = 0; i < std::uint32_t(segments); ++i) {
            const std::uint32_t p00 = j * row + i, p10 = p00 + 1, p01 = p00 + row, p11 = p01 + 1;
            m.indices.insert(m.indices.end(), {p00, p11, p10, p00, p01, p11});
        }
    s.meshes.push_back(std::move(m));
    s.lights.push_back(spot({0, 0, 0}, {0, -1, 0}, outerDeg, innerDeg, 1.0f));
    // Looking sideways and slightly up: the lower (lit) and upper (unlit) halves are both in view.
    s.cameras.push_back(camera({0, 0, 0}, {1, 0.15f, 0.2f}, 90.0f, 0.01f * radius, 4.0f * radius));
    return finish(std::move(s), "stability:sphere");
}

ScenePtr disk(float radius, float lightHeight, float receiverHeight, float albedo) {
    Scene s;
    const int mat = addMaterial(s, "disk", glm::vec3(albedo));
    const int recv = addMaterial(s, "receiver", glm::vec3(0.8f));
    Mesh d{.name = "disk", .material = mat};
    const int rings = 24, segments = 64;
    d.positions.emplace_back(0, 0, 0);
    for (int j = 1; j <= rings; ++j)
        for (int i = 0; i < segments; ++i) {
            const float r = radius * float(j) / rings, phi = 2.0f * glm::pi<float>() * float(i) / segments;
            d.positions.emplace_back(r * std::cos(phi), 0.0f, r * std::sin(phi));
        }
    d.normals.assign(d.positions.size(), glm::vec3(0, 1, 0));
    auto at = [&](int ring, int i) { return std::uint32_t(1 + (ring - 1) * segments + (i % segments)); };
    for (int i = 0; i < segments; ++i) d.indices.insert(d.indices.end(), {0u, at(1, i + 1), at(1, i)});
    for (int j = 1; j < rings; ++j)
        for (int i = 0; i < segments; ++i)
            d.indices.insert(d.indices.end(), {at(j, i), at(j, i + 1), at(j + 1, i + 1), at(j, i),
                                               at(j + 1, i + 1), at(j + 1, i)});
    s.meshes.push_back(std::move(d));
    const float half = 3.0f * radius;
    s.meshes.push_back(
        grid("receiver", recv, {-half, receiverHeight, -half}, {2 * half, 0, 0}, {0, 0, 2 * half}, 12));
    const float inner = glm::degrees(std::atan(1.2f * radius / lightHeight));
    s.lights.push_back(spot({0, lightHeight, 0}, {0, -1, 0}, std::min(inner + 5.0f, 89.0f), inner, 1.0f));
    s.cameras.push_back(
        camera({0, 0.5f * lightHeight, 2.5f * radius}, {0, receiverHeight, 0}, 60.0f, 0.01f, 50.0f));
    return finish(std::move(s), "stability:disk");
}

ScenePtr floorOnly(float size, float height) {
    Scene s;
    const int mat = addMaterial(s, "floor", glm::vec3(0.8f));
    const float h = 0.5f * size;
    s.meshes.push_back(grid("floor", mat, {-h, 0, -h}, {0, 0, size}, {size, 0, 0}));
    s.lights.push_back(spot({0, height, 0}, {0.2f, -1, 0.1f}, 50.0f, 40.0f));
    s.cameras.push_back(camera({0, 1.2f * height, 1.6f * size}, {0, 0, 0}));
    return finish(std::move(s), "stability:floor");
}

ScenePtr floorAndSky() {
    Scene s;
    const int mat = addMaterial(s, "floor", glm::vec3(0.8f));
    const int wall = addMaterial(s, "wall", glm::vec3(0.6f, 0.5f, 0.4f));
    s.meshes.push_back(grid("floor", mat, {-1, 0, -1}, {0, 0, 2}, {2, 0, 0}));
    s.meshes.push_back(grid("wall", wall, {-1, 0, -1}, {0, 1, 0}, {0, 0, 2}));
    // Aimed past the floor's +x edge: roughly half the cone sees nothing.
    s.lights.push_back(spot({0.2f, 1.2f, 0}, {1, -0.8f, 0}, 45.0f, 35.0f));
    s.cameras.push_back(camera({0.5f, 1.4f, 3.2f}, {0.3f, 0.2f, 0}));
    return finish(std::move(s), "stability:floor-and-sky");
}

ScenePtr depthEdges() {
    Scene s;
    const int white = addMaterial(s, "white", glm::vec3(0.8f));
    const int red = addMaterial(s, "red", glm::vec3(0.7f, 0.1f, 0.1f));
    s.meshes.push_back(grid("back_wall", white, {-3, -3, -2}, {6, 0, 0}, {0, 6, 0}));
    // The floor exchanges light with the walls and panels (parallel planes facing the same way
    // exchange none).
    s.meshes.push_back(grid("floor", white, {-3, -1.5f, -2}, {0, 0, 5}, {6, 0, 0}));
    // The near panel's right edge is at x = 0, on the camera axis: it projects onto the boundary
    // between the two centre columns, a cell boundary of every eye level of an even-width image.
    s.meshes.push_back(grid("near_panel", red, {-3, -1.5f, 0}, {3, 0, 0}, {0, 4.5f, 0}));
    // A triangle with a diagonal edge in the upper right.
    Mesh diag{.name = "diagonal", .material = red};
    diag.positions = {{0.1f, 0.1f, -1}, {2.5f, 0.1f, -1}, {2.5f, 2.5f, -1}};
    diag.normals.assign(3, glm::vec3(0, 0, 1));
    diag.indices = {0, 1, 2};
    s.meshes.push_back(std::move(diag));
    s.lights.push_back(spot({0.5f, 1.0f, 2.5f}, {-0.2f, -0.3f, -1}, 60.0f, 50.0f));
    s.cameras.push_back(camera({0, 0, 3}, {0, 0, 0}, 70.0f));
    return finish(std::move(s), "stability:depth-edges");
}

ScenePtr blackRegion() {
    Scene s;
    const int white = addMaterial(s, "white", glm::vec3(0.8f));
    const int black = addMaterial(s, "black", glm::vec3(0.0f));
    s.meshes.push_back(grid("wall_white", white, {-1, 0, -1}, {1, 0, 0}, {0, 1.5f, 0}));
    s.meshes.push_back(grid("wall_black", black, {0, 0, -1}, {1, 0, 0}, {0, 1.5f, 0}));
    s.meshes.push_back(grid("floor", white, {-1, 0, -1}, {0, 0, 1.5f}, {2, 0, 0}));
    s.lights.push_back(spot({0, 1.4f, 0.3f}, {0, -0.6f, -1}, 55.0f, 45.0f));
    s.cameras.push_back(camera({0, 0.9f, 2.2f}, {0, 0.6f, -1}, 60.0f));
    return finish(std::move(s), "stability:black-region");
}

ScenePtr highFrequencyNormals(int n) {
    Scene s;
    const int mat = addMaterial(s, "bumpy", glm::vec3(0.8f));
    Mesh m = grid("bumpy", mat, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, n);
    std::uint32_t state = 12345u;
    auto next = [&] {
        state = state * 1664525u + 1013904223u;
        return float(state >> 8) / float(1u << 24) * 2.0f - 1.0f;
    };
    for (glm::vec3& nrm : m.normals)
        nrm = glm::normalize(glm::vec3(next(), next(), 0.35f + 0.65f * std::abs(next())));
    s.meshes.push_back(std::move(m));
    const int side = addMaterial(s, "side", glm::vec3(0.7f));
    s.meshes.push_back(grid("side", side, {-1, -1, 0}, {0, 2, 0}, {0, 0, 1.5f}));
    s.lights.push_back(spot({0.4f, 0.3f, 1.5f}, {-0.3f, -0.1f, -1}, 60.0f, 50.0f));
    s.cameras.push_back(camera({0, 0, 1.9f}, {0, 0, 0}, 60.0f));
    return finish(std::move(s), "stability:high-frequency-normals");
}

ScenePtr degenerate(bool nanPosition) {
    Scene s = *builtin("cornell-empty");
    const float nan = std::numeric_limits<float>::quiet_NaN();
    Mesh m{.name = "degenerate", .material = 0};
    m.positions = {
        {-0.5f, 0.5f, 0.0f}, {-0.5f, 0.5f, 0.0f}, {-0.5f, 0.5f, 0.0f}, // one point three times: zero area
        {0.0f, 0.2f, 0.0f},  {0.3f, 0.5f, 0.0f},  {0.6f, 0.8f, 0.0f},  // collinear
        {0.2f, 1.0f, 0.2f},  {0.6f, 1.0f, 0.2f},  {0.4f, 1.4f, 0.2f},  // ordinary, one NaN normal
    };
    m.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1},       {0, 0, 1}, {0, 0, 1},
                 {0, 0, 1}, {0, 0, 1}, {nan, nan, nan}, {0, 0, 1}};
    m.texcoords.assign(m.positions.size(), glm::vec2(0.5f));
    m.indices = {0, 1, 2, 3, 4, 5, 6, 7, 8, 6, 6, 7 /* duplicate-vertex triangle */};
    if (nanPosition) {
        const auto base = static_cast<std::uint32_t>(m.positions.size());
        m.positions.insert(m.positions.end(), {{-0.6f, 1.2f, 0.3f}, {nan, 1.5f, 0.3f}, {-0.2f, 1.5f, 0.3f}});
        m.normals.insert(m.normals.end(), 3, glm::vec3(0, 0, 1));
        m.texcoords.insert(m.texcoords.end(), 3, glm::vec2(0.5f));
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
    }
    s.meshes.push_back(std::move(m));
    // Bounds of the finite geometry: the NaN position must not turn the light frustum into NaN
    // (a loaded scene can never carry one: validateScene rejects it).
    s.name = nanPosition ? "stability:degenerate-nan-position" : "stability:degenerate";
    return std::make_shared<const Scene>(std::move(s));
}

ScenePtr transformed(const ScenePtr& base, float scale, glm::vec3 translate, const std::string& name) {
    Scene s = *base;
    auto map = [&](glm::vec3 p) { return p * scale + translate; };
    const glm::mat4 toScaled = glm::scale(glm::translate(glm::mat4(1.0f), translate), glm::vec3(scale));
    for (Mesh& m : s.meshes) {
        if (m.instanced()) { // own-space geometry: the placements move instead
            for (glm::mat4& placement : m.instances) placement = toScaled * placement;
            continue;
        }
        for (glm::vec3& p : m.positions) p = map(p);
    }
    for (Light& l : s.lights) {
        l.position = map(l.position);
        l.intensity *= scale * scale;
    }
    for (Camera& c : s.cameras) {
        c.position = map(c.position);
        c.target = map(c.target);
        c.znear *= scale;
        c.zfar *= scale;
    }
    s.updateBounds();
    s.name = name;
    return std::make_shared<const Scene>(std::move(s));
}

ScenePtr instanced(const ScenePtr& base, const std::string& name) {
    Scene s = *base;
    for (Mesh& m : s.meshes) {
        if (m.instanced() || m.positions.empty()) continue;
        glm::vec3 centre(0.0f);
        for (const glm::vec3& p : m.positions) centre += p;
        centre /= static_cast<float>(m.positions.size());
        const glm::mat4 placement =
            glm::rotate(glm::translate(glm::mat4(1.0f), centre), glm::radians(30.0f), glm::vec3(0, 1, 0));
        transformMesh(m, glm::inverse(placement));
        m.instances = {placement};
    }
    s.updateBounds();
    s.name = name;
    return std::make_shared<const Scene>(std::move(s));
}

ScenePtr withAlbedo(const ScenePtr& base, float albedo, const std::string& name) {
    Scene s = *base;
    for (Material& m : s.materials) m.baseColor = glm::vec4(glm::vec3(albedo), 1.0f);
    s.name = name;
    return std::make_shared<const Scene>(std::move(s));
}

ScenePtr cornellOccluder(bool offscreen) {
    Scene s = *builtin("cornell-empty");
    if (offscreen) // beside the right wall, facing the room; the test's camera keeps it out of view
        s.meshes.push_back(grid("occluder", 0, {0.9f, 0.2f, -0.6f}, {0, 0, 1.2f}, {0, 1.2f, 0}, 2));
    else // 5 cm in front of the back wall
        s.meshes.push_back(grid("occluder", 0, {-0.4f, 0.6f, -0.95f}, {0.8f, 0, 0}, {0, 0.8f, 0}, 2));
    s.name = offscreen ? "stability:cornell-occluder-offscreen" : "stability:cornell-occluder";
    return finish(std::move(s), s.name);
}

} // namespace gis::stability::scenes
