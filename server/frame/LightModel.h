// The frame's camera and lights as every consumer sees them: the GL frame and light uniforms
// (render/FrameRenderer), the CPU reference (reference/) and the effect plan (effects/) take their
// matrices, cones, falloff and power from here, so that the three cannot drift apart. GL-free.
//
// Units (docs/lights.md): positions in scene units (metres for glTF); intensity as glTF
// KHR_lights_punctual gives it, candela for spot and point lights and lux for directional ones, used
// as radiometric intensity (W/sr) and irradiance (W/m^2) with a factor of 1 (the renderer's radiance
// unit is "1 lux / sr"; exposure maps it to the display). Colour linear RGB >= 0; cone angles in
// radians from the axis; range in scene units (0 = infinite).
//
// Light views: each rendered light gets the shadow-map and RSM views of its type, one layer each in
// the light-view array textures:
//   spot         one perspective view along the axis, the outer cone as half-angle (<= 85 degrees);
//   point        six perspective cube faces of exactly 90 degrees (+X, -X, +Y, -Y, +Z, -Z), so the
//                RSM texels tile the sphere once (a cube rather than a dual paraboloid: docs/lights.md);
//   directional  one orthographic view along the direction, fitted to the scene's bounds: the
//                light-space box of the bounds' eight corners, made square, so every surface that
//                can be lit or cast a shadow is in it, whatever the camera sees (indirect light
//                comes from outside the view too).
// Near and far planes are distances to the scene's bounds (scale-relative, digest S.4 case 14).
// Views share one side length (texels): shadow_map_size and rsm_size, halved while the views' texels
// would exceed the larger of four full-size maps and sixteen default-size ones (lightViewSide), so
// many lights cost a bounded memory: at the defaults, sixteen views (a point light and ten spots) keep
// full resolution in 64 MB of shadow maps and 48 MB of RSMs.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "frame/FrameState.h"
#include "scene/Scene.h"

namespace gis {

/// Perspective view-projection of `camera` for a width x height frame: the field of view clamped to
/// [0.01, 3] rad, znear >= 1e-4 and zfar >= 2 znear, so any camera gives a finite matrix.
glm::mat4 cameraViewProj(const Camera& camera, int width, int height);
/// The view-projection of `state`'s frame: cameraViewProj at its size or, for a tile
/// (FrameState::window), the full image's projection cropped to the tile's pixels.
glm::mat4 frameViewProj(const FrameState& state);

/// The spot light's shadow-map and RSM frustum: a perspective along the light's axis with the
/// outer cone as half-angle (at most 85 degrees), near and far planes from the distances to the
/// scene's bounds. `tanHalfFov` receives tan(half-angle).
glm::mat4 lightViewProj(const Light& light, const Bounds& sceneBounds, float* tanHalfFov = nullptr);

/// One shadow-map and RSM layer of a light.
struct LightViewModel {
    int light = 0; ///< index into LightSetModel::lights
    glm::mat4 viewProj{1.0f};
    glm::vec3 eye{0.0f}; ///< centre of projection, or the centre of the near plane (orthographic)
    glm::vec3 axis{0.0f, -1.0f, 0.0f}; ///< unit forward direction
    bool orthographic = false;
    float tanHalfFov = 1.0f; ///< perspective
    float halfWidth = 1.0f;  ///< orthographic, scene units
    int face = 0;            ///< cube face of a point light, 0 otherwise
};

struct LightModel {
    bool on = false; ///< enabled, with a finite positive intensity and colour, reaching the scene
    LightType type = LightType::Spot;
    std::string id, name;
    glm::vec3 position{0.0f};
    glm::vec3 axis{0.0f, -1.0f, 0.0f}; ///< unit direction the light points along
    glm::vec3 color{0.0f};             ///< linear RGB, >= 0 and finite
    float intensity = 0.0f;            ///< cd (spot, point) or lux (directional); 0 when off
    float cosOuter = -1.0f;            ///< cos of the outer cone angle (spot)
    float cosInner = 1.0f;             ///< cos of the inner cone angle (> cosOuter for a valid spot)
    float range = 0.0f;                ///< scene units, 0 = infinite
    int firstView = 0, viewCount = 0;  ///< its layers in LightSetModel::views

    glm::vec3 power() const { return intensity * color; }
    /// glTF KHR_lights_punctual cone attenuation: 1 inside the inner cone, 0 outside the outer one,
    /// ((cos - cosOuter) / (cosInner - cosOuter))^2 between; 1 for point and directional lights.
    /// Term for term spotFactor() of shaders/common.glsl. `dirFromLight` is a unit vector.
    float spotFactor(const glm::vec3& dirFromLight) const;
    /// The spec's range window clamp(1 - (d / range)^4, 0, 1)^2 (1 without a range): rangeWindow().
    float rangeWindow(float distance) const;
    /// Unit direction from `p` towards the light, the distance (infinite for a directional light) and
    /// the irradiance on a surface facing the light: lux x colour, or I f(dir) window(d) / d^2 x
    /// colour. False where the direction is undefined (p at the light): lightIncidence() in GLSL.
    bool incidence(const glm::vec3& p, glm::vec3& toLight, float& distance, glm::vec3& irradiance) const;
    /// A rough scalar weight of the light's reach into a scene of radius `sceneRadius`: luminance of
    /// the flux it sends into the bounds (point and spot: I x solid angle; directional: E x pi R^2).
    double sceneFlux(float sceneRadius) const;
};

/// Luminance of a linear Rec. 709 colour (its Y): the weight every light measure uses.
inline double luminance(const glm::dvec3& c) {
    return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
}

/// The lights a frame renders, their views, and what was left out and why.
struct LightSetModel {
    std::vector<LightModel> lights; ///< the rendered ones, in the state's order
    std::vector<LightViewModel> views;
    std::vector<std::string> skipped; ///< "light 'NAME' (ID): REASON" for every light not rendered
    int shadowSide = 0;               ///< texels per view side of the shadow maps
    int rsmSide = 0;                  ///< texels per view side of the RSMs
    int maxLights = 0;                ///< the cap the set was made with
    bool any() const { return !lights.empty(); }
};

/// max_lights' default (frame/FrameParams.cpp).
constexpr int kDefaultMaxLights = 16;
/// max_lights' maximum: GIS_MAX_LIGHTS of shaders/shared/FrameData.h (checked in render/FrameRenderer.cpp).
constexpr int kMaxLights = 64;

/// The views' texel budget per map kind (header comment): the larger of this many full-size maps and
/// kViewTexelBudgetDefaultMaps maps of the parameter's default size.
constexpr int kViewTexelBudgetMaps = 4;
constexpr int kViewTexelBudgetDefaultMaps = 16;

/// The model of one light (no views) in a scene with these bounds; `on` false with no intensity
/// when disabled, black, zero or non-finite.
LightModel makeLightModel(const FrameLight& light, const Bounds& sceneBounds);

/// The light set of `state` (its lights, and the frame parameters max_lights, shadow_map_size and
/// rsm_size) in a scene with these bounds.
LightSetModel makeLightSet(const FrameState& state, const Bounds& sceneBounds);

/// The shared side of `views` maps of `fullSide` texels (halved while views x side^2 exceeds
/// max(kViewTexelBudgetMaps x fullSide^2, kViewTexelBudgetDefaultMaps x defaultSide^2), not below
/// `minSide`).
int lightViewSide(int fullSide, int defaultSide, int views, int minSide);

/// The frame parameters' defaults, texels per side: shadow_map_size and rsm_size.
struct LightViewDefaults {
    int shadowSide;
    int rsmSide;
};
const LightViewDefaults& lightViewDefaults();

/// The light views an earlier frame left drawn: whether they show this frame's lights (the same light
/// block, solid-angle rule, RSMs when this frame reads them, level of detail) and their sides.
struct KeptLightViews {
    bool sameLights = false;
    int shadowSide = 0;
    int rsmSide = 0;
};
/// The sides a frame's light views have, and whether the kept maps serve it.
struct LightViewSides {
    int shadow = 0;
    int rsm = 0;
    bool keep = false;
};
/// A frame asking for maps of `askedShadow` and `askedRsm` texels (after lightViewSide) under a cap
/// of `capShadow` and `capRsm` (FrameState::LightViewCap; 0: none): kept maps of the same lights
/// serve when each side lies between the capped and the asked side (at the asked side only, without
/// a cap), so a camera move after a capped light drag, or after a refinement step drew them whole,
/// draws nothing; else they are drawn at the capped sides. `readsRsm` false: the RSMs' side does not
/// decide (the frame does not read them).
LightViewSides lightViewSides(int askedShadow, int askedRsm, int capShadow, int capRsm, bool readsRsm,
                              const KeptLightViews& kept);

} // namespace gis
