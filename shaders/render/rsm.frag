#version 450 core
// Reflective shadow map (000 §3 step 1): per texel world position, normal and reflected flux.
#include "common.glsl"
#include "render/material.glsl"

in vec3 vWorldPos;
in vec3 vNormal;
in vec2 vTexcoord;

layout(location = 0) out vec4 outPosition; // xyz world (m), w = 1 valid
layout(location = 1) out vec4 outNormal;   // xyz unit normal facing the light
layout(location = 2) out vec4 outFlux;     // rgb diffusely reflected flux of this texel
layout(location = 3) out vec4 outSpecular; // rgb F0, a perceptual roughness (glossy VPLs)

void main() {
    vec3 toLight = gFrame.lightPos.xyz - vWorldPos;
    float d2 = dot(toLight, toLight);
    vec3 l = d2 > 1e-20 ? toLight * inversesqrt(d2) : -gFrame.lightDir.xyz;
    vec3 n = safeNormal(vNormal, vWorldPos, l);

    // Exact per-texel solid angle (or 001 Eq. 4's equal split): see rsmTexelSolidAngle.
    float solidAngle = rsmTexelSolidAngle(gl_FragCoord.xy);

    float intensity = gFrame.lightPos.w * spotFactor(-l);
    vec3 albedo = materialAlbedo(vTexcoord);
    // Flux arriving on the texel's surface patch is I * solid angle (the patch's cosine is already
    // in its projected area); the diffuse lobe reflects rho_d times that. A glossy VPL's specular
    // lobe is evaluated where it is received, from outSpecular and the light position.
    outFlux = vec4(sanitize(gFrame.lightColor.rgb * intensity * solidAngle * albedo), 1.0);
    outPosition = vec4(vWorldPos, 1.0);
    outNormal = vec4(n, 0.0);
    outSpecular = vec4(materialF0(materialBaseColor(vTexcoord)), clamp(uMetalRoughSpec.y, 0.0, 1.0));
}
