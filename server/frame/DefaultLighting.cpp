#include "frame/DefaultLighting.h"

#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "scene/Geometry.h"

namespace gis {
namespace {

constexpr float kDistanceRadii = 2.5f;
constexpr float kUpDeg = 35.0f;
constexpr float kRightDeg = 25.0f;
constexpr float kConeMargin = 1.15f;
constexpr float kMaxOuterDeg = 80.0f;
constexpr float kInnerFraction = 0.8f;
constexpr float kCentreLux = 1.6f;

} // namespace

Light defaultKeyLight(const Bounds& bounds, const Camera& camera) {
    const glm::vec3 centre = bounds.center();
    const float radius = std::max(bounds.radius(), 1e-3f);
    // An orthonormal camera frame: f towards the camera, u its up, r its right (it looks along -f).
    const glm::vec3 f = safeNormalize(camera.position - centre, glm::vec3(0.0f, 0.0f, 1.0f));
    const glm::vec3 anyUp = std::abs(f.y) < 0.99f ? glm::vec3(0.0f, 1.0f, 0.0f) : glm::vec3(1.0f, 0.0f, 0.0f);
    glm::vec3 u = camera.up - glm::dot(camera.up, f) * f;
    u = safeNormalize(u, safeNormalize(anyUp - glm::dot(anyUp, f) * f, glm::vec3(0.0f, 1.0f, 0.0f)));
    const glm::vec3 r = glm::cross(-f, u);
    const float yaw = glm::radians(kRightDeg), pitch = glm::radians(kUpDeg);
    const glm::vec3 horizontal = std::cos(yaw) * f + std::sin(yaw) * r;
    const glm::vec3 dir = safeNormalize(std::cos(pitch) * horizontal + std::sin(pitch) * u, f);

    const float distance = kDistanceRadii * radius;
    Light l;
    l.name = "default key light";
    l.type = LightType::Spot;
    l.position = centre + dir * distance;
    l.direction = -dir;
    l.color = glm::vec3(1.0f);
    const float half = std::asin(std::clamp(kConeMargin * radius / distance, 0.0f, 1.0f));
    l.outerConeAngle = std::min(half, glm::radians(kMaxOuterDeg));
    l.innerConeAngle = kInnerFraction * l.outerConeAngle;
    l.intensity = kCentreLux * distance * distance; // E = I / d^2 at the centre (cd = lux m^2)
    return l;
}

DefaultLighting defaultLighting(const Scene& scene, const Camera& camera) {
    DefaultLighting out;
    out.key = defaultKeyLight(scene.bounds, camera);
    if (scene.lights.empty()) {
        out.reason = "the scene has no lights: showing a default key light over the camera's shoulder";
    } else {
        int point = 0, directional = 0;
        for (const Light& l : scene.lights) {
            if (l.type == LightType::Point) ++point;
            if (l.type == LightType::Directional) ++directional;
        }
        out.reason =
            "the scene's lights (" + std::to_string(point) + " point, " + std::to_string(directional) +
            " directional) are not rendered yet: showing a default key light over the camera's shoulder";
    }
    return out;
}

} // namespace gis
