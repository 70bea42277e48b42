// The frame's camera and light as every consumer sees them: the GL frame uniforms (render/
// FrameRenderer), the CPU reference (reference/) and the effect plan (analysis/) take their
// matrices, cone and power from here, so that the three cannot drift apart. GL-free.
//
// Units: positions in scene units (metres for glTF); intensity as the scene gives it (glTF
// KHR_lights_punctual: candela for spot and point lights, lux for directional ones), colour linear
// RGB >= 0; cone angles in radians from the axis.
#pragma once

#include <glm/glm.hpp>

#include "frame/FrameState.h"
#include "scene/Scene.h"

namespace gis {

/// Perspective view-projection of `camera` for a width x height frame: the field of view clamped to
/// [0.01, 3] rad, znear >= 1e-4 and zfar >= 2 znear, so any camera gives a finite matrix.
glm::mat4 cameraViewProj(const Camera& camera, int width, int height);

/// The spot light's shadow-map and RSM frustum: a perspective along the light's axis with the
/// outer cone as half-angle (at most 85 degrees), near and far planes from the distances to the
/// scene's bounds (scale-relative, digest S.4 case 14). `tanHalfFov` receives tan(half-angle).
glm::mat4 lightViewProj(const Light& light, const Bounds& sceneBounds, float* tanHalfFov = nullptr);

struct LightModel {
    bool on = false; ///< enabled, with a finite positive intensity and a finite position
    LightType type = LightType::Spot;
    glm::vec3 position{0.0f};
    glm::vec3 axis{0.0f, -1.0f, 0.0f}; ///< unit direction the light points along
    glm::vec3 color{0.0f};             ///< linear RGB, >= 0 and finite
    float intensity = 0.0f;            ///< cd (spot, point) or lux (directional); 0 when off
    float cosOuter = 0.0f;             ///< cos of the outer cone angle
    float cosInner = 1.0f;             ///< cos of the inner cone angle (> cosOuter for a valid spot)
    glm::mat4 viewProj{1.0f};          ///< lightViewProj()
    float tanHalfFov = 1.0f;           ///< of viewProj

    glm::vec3 power() const { return intensity * color; }
    /// glTF KHR_lights_punctual cone attenuation: 1 inside the inner cone, 0 outside the outer one,
    /// ((cos - cosOuter) / (cosInner - cosOuter))^2 between; 1 for point and directional lights.
    /// Term for term spotFactor() of shaders/common.glsl. `dirFromLight` is a unit vector.
    float spotFactor(const glm::vec3& dirFromLight) const;
};

/// The light of `state` (its light and lightEnabled) in a scene with these bounds.
LightModel makeLightModel(const FrameState& state, const Bounds& sceneBounds);

} // namespace gis
