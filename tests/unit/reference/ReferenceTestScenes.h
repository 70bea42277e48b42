// Scenes built in code for the reference renderer's validation tests, with closed-form answers.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "frame/FrameState.h"
#include "scene/SceneLoader.h"

namespace gis::test {

constexpr float kTestPi = 3.14159265358979323846f;

/// UV sphere of radius r around `centre` with `segments` longitude steps and segments / 2 latitude rings,
/// vertex normals pointing inwards (towards the centre).
inline Mesh makeInwardSphere(float r, int segments, glm::vec3 centre = glm::vec3(0.0f)) {
    Mesh mesh;
    mesh.name = "sphere";
    const int rings = segments / 2;
    for (int j = 0; j <= rings; ++j) {
        const float theta = kTestPi * static_cast<float>(j) / static_cast<float>(rings);
        for (int i = 0; i <= segments; ++i) {
            const float phi = 2.0f * kTestPi * static_cast<float>(i) / static_cast<float>(segments);
            const glm::vec3 d(std::sin(theta) * std::cos(phi), std::cos(theta),
                              std::sin(theta) * std::sin(phi));
            mesh.positions.push_back(centre + r * d);
            mesh.normals.push_back(-d);
            mesh.texcoords.emplace_back(static_cast<float>(i) / segments, static_cast<float>(j) / rings);
        }
    }
    const auto row = static_cast<std::uint32_t>(segments + 1);
    for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(rings); ++j)
        for (std::uint32_t i = 0; i < static_cast<std::uint32_t>(segments); ++i) {
            const std::uint32_t a = j * row + i, b = a + 1, c = a + row, d = c + 1;
            if (j != 0) mesh.indices.insert(mesh.indices.end(), {a, b, d});
            if (j + 1 != static_cast<std::uint32_t>(rings))
                mesh.indices.insert(mesh.indices.end(), {a, d, c});
        }
    return mesh;
}

/// Axis-aligned horizontal quad at height y spanning [x0, x1] x [z0, z1], normal +y.
inline Mesh makeQuadY(float y, float x0, float x1, float z0, float z1, int material) {
    Mesh mesh;
    mesh.name = "quad";
    mesh.positions = {{x0, y, z0}, {x1, y, z0}, {x1, y, z1}, {x0, y, z1}};
    mesh.normals.assign(4, glm::vec3(0.0f, 1.0f, 0.0f));
    mesh.texcoords = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    mesh.indices = {0, 2, 1, 0, 3, 2};
    mesh.material = material;
    return mesh;
}

inline Material diffuse(const glm::vec3& albedo, const std::string& name = "diffuse") {
    Material m;
    m.name = name;
    m.baseColor = glm::vec4(albedo, 1.0f);
    return m;
}

inline Camera lookAt(glm::vec3 position, glm::vec3 target, float fovDegrees = 60.0f) {
    Camera c;
    c.name = "test";
    c.position = position;
    c.target = target;
    c.yfovRadians = glm::radians(fovDegrees);
    c.znear = 0.01f;
    c.zfar = 50.0f;
    return c;
}

inline Light pointLight(glm::vec3 position, float intensity, glm::vec3 colour = glm::vec3(1.0f)) {
    Light l;
    l.name = "point";
    l.type = LightType::Point;
    l.position = position;
    l.intensity = intensity;
    l.color = colour;
    return l;
}

/// A FrameState built by hand: the reference reads only camera, lights and the size.
inline FrameState frameFor(const Camera& camera, const Light& light, int w, int h) {
    FrameState s;
    s.camera = camera;
    s.lights = {{"light0", light, true}};
    s.width = w;
    s.height = h;
    return s;
}

/// Closed sphere (radius r, albedo rho, `segments` longitude steps) with a point light of intensity i at
/// its centre and a camera inside it.
inline Scene makeSphereFurnace(float r, float rho, int segments) {
    Scene scene;
    scene.name = "test:sphere";
    scene.materials.push_back(diffuse(glm::vec3(rho)));
    scene.meshes.push_back(makeInwardSphere(r, segments));
    scene.cameras.push_back(lookAt({0.0f, 0.1f * r, 0.3f * r}, {0.0f, -0.2f * r, -r}));
    finalizeScene(scene, "sphere");
    return scene;
}

inline double mean(const std::vector<float>& v) {
    double s = 0;
    for (float x : v) s += x;
    return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

inline double rmse(const std::vector<float>& a, const std::vector<float>& b) {
    double s = 0;
    for (size_t i = 0; i < a.size(); ++i)
        s += (static_cast<double>(a[i]) - b[i]) * (static_cast<double>(a[i]) - b[i]);
    return a.empty() ? 0.0 : std::sqrt(s / static_cast<double>(a.size()));
}

} // namespace gis::test
