// Declarations every pass shares: the frame uniform block and numeric guards.
#include "shared/FrameData.h"

layout(std140, binding = GIS_UBO_FRAME) uniform FrameBlock {
    FrameUniforms gFrame;
};

const float kPi = 3.14159265358979;
const float kInvPi = 0.31830988618379;

// True for NaN and +-Inf: the boundary sanitiser turns such values into 0.
bool isBad(float v) { return isnan(v) || isinf(v); }
vec3 sanitize(vec3 c) {
    return vec3(isBad(c.r) ? 0.0 : c.r, isBad(c.g) ? 0.0 : c.g, isBad(c.b) ? 0.0 : c.b);
}

// glTF KHR_lights_punctual spot attenuation: 1 inside the inner cone, 0 outside the outer,
// smooth in between. cosInner > cosOuter is guaranteed by scene validation; the max() keeps the
// division finite if both cones coincide.
float spotFactor(vec3 dirFromLight) {
    float cd = dot(normalize(gFrame.lightDir.xyz), dirFromLight);
    float cosOuter = gFrame.lightDir.w;
    float cosInner = gFrame.lightColor.w;
    float t = clamp((cd - cosOuter) / max(cosInner - cosOuter, 1e-4), 0.0, 1.0);
    return t * t;
}

// Solid angle (sr) of the RSM texel centred at `texelCentre` (texel units) seen from the spotlight.
// exact (rsm_solid_angle=exact): the texel's area on the unit-distance image plane,
// (2 tan(fov/2) / N)^2, times cos^3 of its off-axis angle, so the texels' sum is the frustum's solid
// angle. equal: 001 Eq. 4, the frustum's solid angle 4 asin(t^2 / (1 + t^2)) split evenly over N^2
// texels (biased: brighter off-axis, dimmer on-axis; 000 Fig. 13).
float rsmTexelSolidAngle(vec2 texelCentre) {
    float res = max(gFrame.rsmInfo.x, 1.0);
    float t = gFrame.rsmInfo.y;
    if (gFrame.toneInfo.w > 0.5) return 4.0 * asin(clamp(t * t / (1.0 + t * t), 0.0, 1.0)) / (res * res);
    vec2 uv = (texelCentre / res * 2.0 - 1.0) * t;
    float texel = 2.0 * t / res;
    return texel * texel * pow(1.0 + dot(uv, uv), -1.5);
}
