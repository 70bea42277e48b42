#include "frame/LightModel.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "scene/Geometry.h"

namespace gis {
namespace {

// Spot cones wider than this get a light frustum of this half-angle: tan() grows without bound
// towards 90 degrees. Radians (85 degrees).
constexpr float kMaxLightHalfFov = 1.4835299f;

glm::vec3 upFor(glm::vec3 forward, glm::vec3 preferred) {
    glm::vec3 up = safeNormalize(preferred, {0, 1, 0});
    if (std::abs(glm::dot(up, forward)) > 0.999f)
        up = std::abs(forward.z) < 0.9f ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0);
    return up;
}

bool finite(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

} // namespace

glm::mat4 cameraViewProj(const Camera& camera, int width, int height) {
    const glm::vec3 forward = safeNormalize(camera.target - camera.position, {0, 0, -1});
    const glm::mat4 view = glm::lookAt(camera.position, camera.position + forward, upFor(forward, camera.up));
    const float aspect = static_cast<float>(width) / static_cast<float>(std::max(height, 1));
    const float fov = std::clamp(camera.yfovRadians, 0.01f, 3.0f);
    const float znear = std::max(camera.znear, 1e-4f);
    const float zfar = std::max(camera.zfar, znear * 2.0f);
    return glm::perspective(fov, aspect, znear, zfar) * view;
}

glm::mat4 lightViewProj(const Light& light, const Bounds& bounds, float* tanHalfFov) {
    const glm::vec3 dir = safeNormalize(light.direction, {0, -1, 0});
    const glm::mat4 view = glm::lookAt(light.position, light.position + dir, upFor(dir, {0, 1, 0}));
    const float half = std::clamp(light.outerConeAngle, 0.01f, kMaxLightHalfFov);
    if (tanHalfFov) *tanHalfFov = std::tan(half);
    // Scale-relative frustum (digest S.4 case 14): every term is a distance to the scene's bounds, so a
    // scene scaled by s gets the same frustum scaled by s (absolute terms, a 1 m margin and a 1 mm near
    // plane, clipped the geometry next to the light of a millimetre-scale scene).
    const glm::vec3 lo = glm::min(bounds.min, bounds.max), hi = glm::max(bounds.min, bounds.max);
    const float extent = glm::length(hi - lo);
    float farthest = 0.0f;
    for (int i = 0; i < 8; ++i) {
        const glm::vec3 corner((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
        farthest = std::max(farthest, glm::length(corner - light.position));
    }
    const float nearest = glm::length(glm::clamp(light.position, lo, hi) - light.position);
    // Far plane: past the farthest bounds corner by 5% of the extent (room for the shadow lookup's
    // normal offset). Near plane: half the way to the bounds for a light outside them, else 1e-3 of the
    // far plane (geometry closer to a light inside the bounds than that is clipped).
    float reach = farthest * 1.001f + 0.05f * extent;
    if (!(reach > 0.0f) || !std::isfinite(reach)) reach = 1.0f; // no bounds, or a light on a point scene
    const float znear = std::max(0.5f * nearest, reach * 1e-3f);
    return glm::perspective(2.0f * half, 1.0f, znear, reach) * view;
}

float LightModel::spotFactor(const glm::vec3& dirFromLight) const {
    if (type != LightType::Spot) return 1.0f;
    const float cd = glm::dot(axis, dirFromLight);
    const float t = std::clamp((cd - cosOuter) / std::max(cosInner - cosOuter, 1e-4f), 0.0f, 1.0f);
    return t * t;
}

LightModel makeLightModel(const FrameState& state, const Bounds& sceneBounds) {
    const Light& l = state.light;
    LightModel m;
    m.type = l.type;
    m.on = state.lightEnabled && l.intensity > 0.0f && std::isfinite(l.intensity) && finite(l.position);
    m.position = l.position;
    m.axis = safeNormalize(l.direction, {0.0f, -1.0f, 0.0f});
    m.color = glm::max(l.color, glm::vec3(0.0f));
    if (!finite(m.color)) m.color = glm::vec3(0.0f);
    m.intensity = m.on ? l.intensity : 0.0f;
    m.cosOuter = std::cos(l.outerConeAngle);
    m.cosInner = std::cos(l.innerConeAngle);
    m.viewProj = lightViewProj(l, sceneBounds, &m.tanHalfFov);
    return m;
}

} // namespace gis
