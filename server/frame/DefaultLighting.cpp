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
constexpr float kFillFraction = 0.2f;
constexpr float kFillLeftDeg = 40.0f;
constexpr float kFillDownDeg = 20.0f;

// An orthonormal camera frame around the bounds' centre: f towards the camera, u its up, r its right
// (it looks along -f).
struct ViewFrame {
    glm::vec3 f, u, r;
};
ViewFrame viewFrame(const glm::vec3& centre, const Camera& camera) {
    const glm::vec3 f = safeNormalize(camera.position - centre, glm::vec3(0.0f, 0.0f, 1.0f));
    const glm::vec3 anyUp = std::abs(f.y) < 0.99f ? glm::vec3(0.0f, 1.0f, 0.0f) : glm::vec3(1.0f, 0.0f, 0.0f);
    glm::vec3 u = camera.up - glm::dot(camera.up, f) * f;
    u = safeNormalize(u, safeNormalize(anyUp - glm::dot(anyUp, f) * f, glm::vec3(0.0f, 1.0f, 0.0f)));
    return {f, u, glm::cross(-f, u)};
}

} // namespace

Light defaultKeyLight(const Bounds& bounds, const Camera& camera) {
    const glm::vec3 centre = bounds.center();
    const float radius = std::max(bounds.radius(), 1e-3f);
    const auto [f, u, r] = viewFrame(centre, camera);
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

Light defaultFillLight(const Bounds& bounds, const Camera& camera) {
    const auto [f, u, r] = viewFrame(bounds.center(), camera);
    const float yaw = glm::radians(kFillLeftDeg), pitch = glm::radians(kFillDownDeg);
    const glm::vec3 horizontal = std::cos(yaw) * f - std::sin(yaw) * r;
    const glm::vec3 towardsLight = safeNormalize(std::cos(pitch) * horizontal - std::sin(pitch) * u, f);
    Light l;
    l.name = "default fill light";
    l.type = LightType::Directional;
    l.direction = -towardsLight;
    l.position = bounds.center() + towardsLight * (kDistanceRadii * std::max(bounds.radius(), 1e-3f));
    l.color = glm::vec3(1.0f);
    l.intensity = kFillFraction * kCentreLux; // lux
    return l;
}

DefaultLighting defaultLighting(const Scene& scene, const Camera& camera) {
    DefaultLighting out;
    out.key = defaultKeyLight(scene.bounds, camera);
    out.fill = defaultFillLight(scene.bounds, camera);
    out.reason = "the scene has no lights: showing default lighting (a key light over the camera's shoulder "
                 "and a dim fill)";
    return out;
}

} // namespace gis
