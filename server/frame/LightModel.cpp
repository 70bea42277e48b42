#include "frame/LightModel.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>

#include "frame/FrameParams.h"
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

glm::mat4 frameViewProj(const FrameState& state) {
    if (!state.window.active()) return cameraViewProj(state.camera, state.width, state.height);
    const auto& w = state.window;
    const glm::mat4 full = cameraViewProj(state.camera, w.fullWidth, w.fullHeight);
    // The tile's edges in the full image's NDC (y up, rows counted from the top), then the affine map
    // taking them to [-1, 1]; sizes are >= 1 px, so no division by zero.
    const double fw = w.fullWidth, fh = w.fullHeight;
    const double left = -1.0 + 2.0 * w.x / fw, right = -1.0 + 2.0 * (w.x + state.width) / fw;
    const double top = 1.0 - 2.0 * w.y / fh, bottom = 1.0 - 2.0 * (w.y + state.height) / fh;
    glm::mat4 crop(1.0f);
    crop[0][0] = static_cast<float>(2.0 / (right - left));
    crop[3][0] = static_cast<float>(-(right + left) / (right - left));
    crop[1][1] = static_cast<float>(2.0 / (top - bottom));
    crop[3][1] = static_cast<float>(-(top + bottom) / (top - bottom));
    return crop * full;
}

namespace {

// Near and far planes of a perspective view from `eye` that must see the whole bounds: far past
// the farthest corner by 5% of the extent (room for the shadow lookup's normal offset); near half the
// way to the bounds for an eye outside them, else 1e-3 of the far plane (geometry closer to a light
// inside the bounds than that is clipped). Scale-relative (digest S.4 case 14): every term is a
// distance to the scene's bounds (absolute terms clipped the geometry next to the light of a
// millimetre-scale scene).
glm::vec2 perspectiveDepthRange(const glm::vec3& eye, const Bounds& bounds) {
    const glm::vec3 lo = glm::min(bounds.min, bounds.max), hi = glm::max(bounds.min, bounds.max);
    const float extent = glm::length(hi - lo);
    float farthest = 0.0f;
    for (int i = 0; i < 8; ++i) {
        const glm::vec3 corner((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
        farthest = std::max(farthest, glm::length(corner - eye));
    }
    const float nearest = glm::length(glm::clamp(eye, lo, hi) - eye);
    float reach = farthest * 1.001f + 0.05f * extent;
    if (!(reach > 0.0f) || !std::isfinite(reach)) reach = 1.0f; // no bounds, or a light on a point scene
    return {std::max(0.5f * nearest, reach * 1e-3f), reach};
}

std::string fmtLength(float v) {
    std::ostringstream o;
    o.precision(3);
    o << v;
    return o.str();
}

} // namespace

glm::mat4 lightViewProj(const Light& light, const Bounds& bounds, float* tanHalfFov) {
    const glm::vec3 dir = safeNormalize(light.direction, {0, -1, 0});
    const glm::mat4 view = glm::lookAt(light.position, light.position + dir, upFor(dir, {0, 1, 0}));
    const float half = std::clamp(light.outerConeAngle, 0.01f, kMaxLightHalfFov);
    if (tanHalfFov) *tanHalfFov = std::tan(half);
    const glm::vec2 depth = perspectiveDepthRange(light.position, bounds);
    return glm::perspective(2.0f * half, 1.0f, depth.x, depth.y) * view;
}

float LightModel::spotFactor(const glm::vec3& dirFromLight) const {
    if (type != LightType::Spot) return 1.0f;
    const float cd = glm::dot(axis, dirFromLight);
    const float t = std::clamp((cd - cosOuter) / std::max(cosInner - cosOuter, 1e-4f), 0.0f, 1.0f);
    return t * t;
}

float LightModel::rangeWindow(float distance) const {
    if (!(range > 0.0f)) return 1.0f;
    const float r = distance / range;
    const float w = std::clamp(1.0f - r * r * r * r, 0.0f, 1.0f);
    return w * w;
}

bool LightModel::incidence(const glm::vec3& p, glm::vec3& toLight, float& distance,
                           glm::vec3& irradiance) const {
    if (type == LightType::Directional) {
        toLight = -axis;
        distance = std::numeric_limits<float>::infinity();
        irradiance = color * intensity;
        return true;
    }
    const glm::vec3 d = position - p;
    const float d2 = glm::dot(d, d);
    if (!(d2 > 1e-20f)) {
        toLight = glm::vec3(0.0f, 1.0f, 0.0f);
        distance = 0.0f;
        irradiance = glm::vec3(0.0f);
        return false;
    }
    distance = std::sqrt(d2);
    toLight = d / distance;
    irradiance = color * (intensity * spotFactor(-toLight) * rangeWindow(distance) / d2);
    return true;
}

double LightModel::sceneFlux(float sceneRadius) const {
    const double y = luminance(glm::dvec3(color * intensity));
    constexpr double kPi = 3.14159265358979323846;
    switch (type) {
    case LightType::Directional:
        return y * kPi * double(sceneRadius) * double(sceneRadius);
    case LightType::Point:
        return y * 4.0 * kPi;
    case LightType::Spot:
        return y * 2.0 * kPi * (1.0 - double(cosOuter));
    }
    return 0.0;
}

LightModel makeLightModel(const FrameLight& frameLight, const Bounds& sceneBounds) {
    (void)sceneBounds;
    const Light& l = frameLight.light;
    LightModel m;
    m.type = l.type;
    m.id = frameLight.id;
    m.name = l.name;
    m.position = l.position;
    m.axis = safeNormalize(l.direction, {0.0f, -1.0f, 0.0f});
    m.color = glm::max(l.color, glm::vec3(0.0f));
    if (!finite(m.color)) m.color = glm::vec3(0.0f);
    const bool positioned = l.type == LightType::Directional || finite(l.position);
    m.on = frameLight.enabled && l.intensity > 0.0f && std::isfinite(l.intensity) && positioned &&
           glm::dot(m.color, m.color) > 0.0f;
    m.intensity = m.on ? l.intensity : 0.0f;
    if (l.type == LightType::Spot) {
        m.cosOuter = std::cos(l.outerConeAngle);
        m.cosInner = std::cos(l.innerConeAngle);
    }
    m.range = std::isfinite(l.range) && l.range > 0.0f ? l.range : 0.0f;
    return m;
}

int lightViewSide(int fullSide, int defaultSide, int views, int minSide) {
    int side = std::max(fullSide, 1);
    const double budget =
        std::max(double(kViewTexelBudgetMaps) * double(fullSide) * double(fullSide),
                 double(kViewTexelBudgetDefaultMaps) * double(defaultSide) * double(defaultSide));
    while (side / 2 >= minSide && double(views) * double(side) * double(side) > budget) side /= 2;
    return side;
}

const LightViewDefaults& lightViewDefaults() {
    static const LightViewDefaults defaults{
        static_cast<int>(frameParamTable().find("shadow_map_size")->defaultValue),
        static_cast<int>(frameParamTable().find("rsm_size")->defaultValue)};
    return defaults;
}

LightViewSides lightViewSides(int askedShadow, int askedRsm, int capShadow, int capRsm, bool readsRsm,
                              const KeptLightViews& kept) {
    const int lowShadow = capShadow > 0 ? std::min(capShadow, askedShadow) : askedShadow;
    const int lowRsm = capRsm > 0 ? std::min(capRsm, askedRsm) : askedRsm;
    const auto serves = [](int side, int low, int high) { return side >= low && side <= high; };
    if (kept.sameLights && serves(kept.shadowSide, lowShadow, askedShadow) &&
        (!readsRsm || serves(kept.rsmSide, lowRsm, askedRsm)))
        return {kept.shadowSide, kept.rsmSide, true};
    return {lowShadow, lowRsm, false};
}

namespace {

// An orthographic view along `axis` holding every corner of the bounds: the light-space box of the
// eight corners, made square (one texel size in both directions), depth from the nearest to the
// farthest corner with 5% of the extent as margin on each side.
LightViewModel orthographicView(const glm::vec3& axis, const Bounds& bounds) {
    const glm::vec3 lo = glm::min(bounds.min, bounds.max), hi = glm::max(bounds.min, bounds.max);
    const glm::vec3 centre = 0.5f * (lo + hi);
    const float extent = std::max(glm::length(hi - lo), 1e-6f);
    const glm::mat4 view = glm::lookAt(centre - axis * extent, centre, upFor(axis, {0, 1, 0}));
    glm::vec3 vmin(std::numeric_limits<float>::max()), vmax(-std::numeric_limits<float>::max());
    for (int i = 0; i < 8; ++i) {
        const glm::vec3 corner((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
        const glm::vec3 v = glm::vec3(view * glm::vec4(corner, 1.0f));
        vmin = glm::min(vmin, v);
        vmax = glm::max(vmax, v);
    }
    const glm::vec2 mid = 0.5f * (glm::vec2(vmin) + glm::vec2(vmax));
    const float half = std::max(0.5f * std::max(vmax.x - vmin.x, vmax.y - vmin.y), 1e-6f) * 1.001f;
    // Camera space looks down -z: the near plane is at -vmax.z, the far one at -vmin.z.
    const float margin = 0.05f * extent;
    const float znear = -vmax.z - margin, zfar = -vmin.z + margin;
    LightViewModel out;
    out.orthographic = true;
    out.halfWidth = half;
    out.axis = axis;
    out.viewProj = glm::ortho(mid.x - half, mid.x + half, mid.y - half, mid.y + half, znear, zfar) * view;
    // The near plane's centre in world space: camera-space (mid, -znear).
    const glm::mat4 inv = glm::inverse(view);
    out.eye = glm::vec3(inv * glm::vec4(mid, -znear, 1.0f));
    return out;
}

// Cube face f of a point light: 90 degrees along +X, -X, +Y, -Y, +Z, -Z.
LightViewModel cubeFaceView(const glm::vec3& position, int face, const Bounds& bounds) {
    static const glm::vec3 kAxes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    const glm::vec3 axis = kAxes[face];
    const glm::vec3 up = std::abs(axis.y) > 0.5f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
    const glm::vec2 depth = perspectiveDepthRange(position, bounds);
    LightViewModel out;
    out.viewProj = glm::perspective(glm::radians(90.0f), 1.0f, depth.x, depth.y) *
                   glm::lookAt(position, position + axis, up);
    out.eye = position;
    out.axis = axis;
    out.tanHalfFov = 1.0f;
    out.face = face;
    return out;
}

// Why light `m` cannot light anything inside the bounds, or "" when it may.
std::string unreachable(const LightModel& m, const Bounds& bounds) {
    if (m.type == LightType::Directional || !(m.range > 0.0f)) return "";
    const glm::vec3 lo = glm::min(bounds.min, bounds.max), hi = glm::max(bounds.min, bounds.max);
    const float gap = glm::length(glm::clamp(m.position, lo, hi) - m.position);
    if (gap >= m.range)
        return "its range (" + fmtLength(m.range) + ") ends before the scene's bounds (" + fmtLength(gap) +
               " away)";
    return "";
}

} // namespace

LightSetModel makeLightSet(const FrameState& state, const Bounds& bounds) {
    LightSetModel set;
    const ParamSet& fp = state.frameParams;
    const bool hasParams = fp.has("max_lights");
    set.maxLights = hasParams ? fp.getInt("max_lights") : kDefaultMaxLights;
    for (const FrameLight& fl : state.lights) {
        LightModel m = makeLightModel(fl, bounds);
        const std::string who = "light '" + fl.light.name + "' (" + fl.id + ")";
        std::string reason;
        if (!fl.enabled)
            reason = "disabled";
        else if (!m.on)
            reason = "has no intensity (intensity or colour is zero)";
        else
            reason = unreachable(m, bounds);
        if (reason.empty() && static_cast<int>(set.lights.size()) >= set.maxLights)
            reason = "over max_lights (" + std::to_string(set.maxLights) + "): raise it to render this light";
        if (!reason.empty()) {
            set.skipped.push_back(who + ": " + reason);
            continue;
        }
        const int index = static_cast<int>(set.lights.size());
        m.firstView = static_cast<int>(set.views.size());
        if (m.type == LightType::Spot) {
            LightViewModel v;
            Light l = fl.light;
            l.direction = m.axis;
            v.viewProj = lightViewProj(l, bounds, &v.tanHalfFov);
            v.eye = m.position;
            v.axis = m.axis;
            set.views.push_back(v);
        } else if (m.type == LightType::Point) {
            for (int f = 0; f < 6; ++f) set.views.push_back(cubeFaceView(m.position, f, bounds));
        } else {
            set.views.push_back(orthographicView(m.axis, bounds));
        }
        m.viewCount = static_cast<int>(set.views.size()) - m.firstView;
        for (int v = m.firstView; v < m.firstView + m.viewCount; ++v)
            set.views[static_cast<size_t>(v)].light = index;
        set.lights.push_back(m);
    }
    const int views = std::max(static_cast<int>(set.views.size()), 1);
    const int shadowDefault = lightViewDefaults().shadowSide, rsmDefault = lightViewDefaults().rsmSide;
    set.shadowSide =
        lightViewSide(hasParams ? fp.getInt("shadow_map_size") : shadowDefault, shadowDefault, views, 64);
    set.rsmSide = lightViewSide(hasParams ? fp.getInt("rsm_size") : rsmDefault, rsmDefault, views, 16);
    return set;
}

} // namespace gis
