#version 450 core
// Reflective shadow map (000 §3 step 1): per texel world position, normal and reflected flux.
#include "common.glsl"
#include "render/material.glsl"

in vec3 vWorldPos;
in vec3 vNormal;
in vec2 vTexcoord;

layout(location = 0) out vec4 outPosition; // xyz world (m), w = 1 valid
layout(location = 1) out vec4 outNormal;   // xyz unit normal facing the light
layout(location = 2) out vec4 outFlux;     // rgb reflected flux of this texel

void main() {
    vec3 toLight = gFrame.lightPos.xyz - vWorldPos;
    float d2 = dot(toLight, toLight);
    vec3 l = d2 > 1e-20 ? toLight * inversesqrt(d2) : -gFrame.lightDir.xyz;
    vec3 n = safeNormal(vNormal, vWorldPos, l);

    // Exact solid angle of this texel seen from the light: the texel's area on the image plane at
    // unit distance, (2 tan(fov/2) / N)^2, times cos^3 of its off-axis angle. Using it (rather than
    // an equal solid angle per texel) makes the flux sum exact (000 Fig. 13 discusses the bias).
    float res = gFrame.rsmInfo.x;
    float t = gFrame.rsmInfo.y;
    vec2 uv = (gl_FragCoord.xy / res * 2.0 - 1.0) * t;
    float texel = 2.0 * t / res;
    float solidAngle = texel * texel * pow(1.0 + dot(uv, uv), -1.5);
    if (gFrame.toneInfo.w > 0.5) {
        // 001 Eq. 4: every texel gets the frustum's solid angle / N^2. A square frustum of half-angle
        // tangent t subtends 4 asin(t^2 / (1 + t^2)) sr. Brighter off-axis, dimmer on-axis (000 Fig. 13).
        solidAngle = 4.0 * asin(clamp(t * t / (1.0 + t * t), 0.0, 1.0)) / (res * res);
    }

    float intensity = gFrame.lightPos.w * spotFactor(-l);
    vec3 albedo = materialAlbedo(vTexcoord);
    // Flux arriving on the texel's surface patch is I * solid angle (the patch's cosine is already
    // in its projected area); a Lambertian surface reflects albedo times that.
    outFlux = vec4(sanitize(gFrame.lightColor.rgb * intensity * solidAngle * albedo), 1.0);
    outPosition = vec4(vWorldPos, 1.0);
    outNormal = vec4(n, 0.0);
}
