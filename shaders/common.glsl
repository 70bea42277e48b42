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

// A Vpl stored as three RGBA32F texels from `first` (position, normal, flux) of a buffer texture:
// the gathers' VPL batches and the light tree's nodes, which start with a Vpl's layout.
Vpl vplFromTexels(samplerBuffer texels, int first) {
    Vpl v;
    v.position = texelFetch(texels, first);
    v.normal = texelFetch(texels, first + 1);
    v.flux = texelFetch(texels, first + 2);
    return v;
}

layout(std140, binding = GIS_UBO_LIGHTS) uniform LightBlock {
    LightUniforms gLights;
};

int lightCount() { return gLights.counts.x; }
int lightViewCount() { return gLights.counts.y; }
int lightType(int i) { return int(gLights.lights[i].info.x + 0.5); }
int lightOfView(int v) { return int(gLights.views[v].eye.w + 0.5); }

// glTF KHR_lights_punctual spot attenuation of light i: 1 inside the inner cone, 0 outside the outer,
// smooth in between; 1 for point and directional lights. cosInner > cosOuter is guaranteed by scene
// validation; the max() keeps the division finite if both cones coincide.
float spotFactor(int i, vec3 dirFromLight) {
    if (lightType(i) != GIS_LIGHT_SPOT) return 1.0;
    float cd = dot(gLights.lights[i].direction.xyz, dirFromLight);
    float cosOuter = gLights.lights[i].direction.w;
    float cosInner = gLights.lights[i].color.w;
    float t = clamp((cd - cosOuter) / max(cosInner - cosOuter, 1e-4), 0.0, 1.0);
    return t * t;
}

// The spec's recommended range window: clamp(1 - (d / range)^4, 0, 1)^2, 1 without a range (0).
float rangeWindow(int i, float dist) {
    float range = gLights.lights[i].info.y;
    if (!(range > 0.0)) return 1.0;
    float r = dist / range;
    float r2 = r * r;
    float w = clamp(1.0 - r2 * r2, 0.0, 1.0);
    return w * w;
}

// Light i seen from surface point p: the unit direction towards the light, the distance (a huge
// number for a directional light) and the irradiance on a surface facing the light (lux x colour
// for a directional light; I x spot x window / d^2 for the others). False where the direction is
// undefined (p at the light's position, digest S.4 case 1): the light contributes nothing there.
bool lightIncidence(int i, vec3 p, out vec3 l, out float dist, out vec3 irradiance) {
    GpuLight light = gLights.lights[i];
    if (lightType(i) == GIS_LIGHT_DIRECTIONAL) {
        l = -light.direction.xyz;
        dist = 1e30;
        irradiance = light.color.rgb * light.position.w;
        return true;
    }
    vec3 toLight = light.position.xyz - p;
    float d2 = dot(toLight, toLight);
    if (!(d2 > 1e-20)) {
        l = vec3(0.0, 1.0, 0.0);
        dist = 0.0;
        irradiance = vec3(0.0);
        return false;
    }
    dist = sqrt(d2);
    l = toLight / dist;
    irradiance = light.color.rgb * (light.position.w * spotFactor(i, -l) * rangeWindow(i, dist) / d2);
    return true;
}

// Unit direction from p towards light i (the light's reversed axis where p is at its position).
vec3 directionToLight(int i, vec3 p) {
    GpuLight light = gLights.lights[i];
    if (lightType(i) == GIS_LIGHT_DIRECTIONAL) return -light.direction.xyz;
    vec3 toLight = light.position.xyz - p;
    float d2 = dot(toLight, toLight);
    return d2 > 1e-20 ? toLight * inversesqrt(d2) : -light.direction.xyz;
}

// Distance from view v's centre of projection (its near plane for an orthographic view) to p (m).
float lightViewDistance(int v, vec3 p) {
    LightView view = gLights.views[v];
    if (view.info.x > 0.5) return max(dot(p - view.eye.xyz, view.axis.xyz), 0.0);
    return length(p - view.eye.xyz);
}

// The measure of the RSM texel centred at `texelCentre` (texel units) of view v, as the light sees
// it: its solid angle (sr) for a perspective view, its area perpendicular to the light (m^2) for an
// orthographic one. Perspective, exact (rsm_solid_angle=exact): the texel's area on the
// unit-distance image plane, (2 tan(fov/2) / N)^2, times cos^3 of its off-axis angle, so the
// texels' sum is the frustum's solid angle. equal: 001 Eq. 4, the frustum's solid angle
// 4 asin(t^2 / (1 + t^2)) split evenly over N^2 texels (biased: brighter off-axis, dimmer on-axis;
// 000 Fig. 13).
float rsmTexelMeasure(int v, vec2 texelCentre) {
    float res = max(gFrame.rsmInfo.x, 1.0);
    float t = gLights.views[v].info.y;
    if (gLights.views[v].info.x > 0.5) {
        float side = 2.0 * t / res;
        return side * side;
    }
    if (gFrame.toneInfo.w > 0.5) return 4.0 * asin(clamp(t * t / (1.0 + t * t), 0.0, 1.0)) / (res * res);
    vec2 uv = (texelCentre / res * 2.0 - 1.0) * t;
    float texel = 2.0 * t / res;
    return texel * texel * pow(1.0 + dot(uv, uv), -1.5);
}
