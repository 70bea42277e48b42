#version 450 core
// Reflective shadow map (000 §3 step 1) of one light view: per texel world position, normal and
// reflected flux, for every light type. A texel carries the flux arriving on its surface patch,
// E_perp x A_perp, where A_perp is the patch's area perpendicular to the light: I x measure for a
// perspective view (the measure is the texel's solid angle, A_perp = omega d^2, E_perp = I / d^2),
// E x measure for an orthographic one (the measure is the texel's area). The patch's cosine is
// already in its projected area.
#include "common.glsl"
#include "render/material.glsl"

in vec3 vWorldPos;
in vec3 vNormal;
in vec2 vTexcoord;
in vec4 vTangent;

uniform int uView; // the light view this layer belongs to (mesh.vert's selector)

layout(location = 0) out vec4 outPosition; // xyz world (m), w = 1 valid
layout(location = 1) out vec4 outNormal;   // xyz unit normal facing the light
layout(location = 2) out vec4 outFlux;     // rgb diffusely reflected flux of this texel; a: A_perp (m^2, 001 Eq. 3's disk area)
layout(location = 3) out vec4 outSpecular; // rgb F0, a perceptual roughness (glossy VPLs)

void main() {
    CUT_OUT(vTexcoord);
    int light = lightOfView(uView);
    vec3 l, irradiance;
    float dist;
    bool defined = lightIncidence(light, vWorldPos, l, dist, irradiance);
    vec3 n = safeNormal(vNormal, vWorldPos, l);
    n = materialNormal(n, vNormal, vTangent, vTexcoord);

    float measure = rsmTexelMeasure(uView, gl_FragCoord.xy);
    bool ortho = gLights.views[uView].info.x > 0.5;
    // Perspective: E_perp x A_perp = (I f w / d^2) (omega d^2); orthographic: E x area.
    float areaPerp = ortho ? measure : measure * dist * dist;
    vec3 arriving = defined ? irradiance * areaPerp : vec3(0.0);
    vec3 albedo = materialAlbedo(vTexcoord);
    // The diffuse lobe reflects rho_d times the arriving flux. A glossy VPL's specular lobe is
    // evaluated where it is received, from outSpecular and the light.
    outFlux = vec4(sanitize(arriving * albedo), isBad(areaPerp) ? 0.0 : max(areaPerp, 0.0));
    outPosition = vec4(vWorldPos, 1.0);
    outNormal = vec4(n, 0.0);
    outSpecular = materialSpecular(vTexcoord);
}
