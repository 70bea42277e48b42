#version 450 core
// Direct light from every light, each with a PCF-filtered shadow map, plus emission: the diffuse lobe
// rho_d / pi and, where the surface has one, the specular lobe of render/brdf.glsl.
#include "common.glsl"
#include "render/brdf.glsl"
#include "render/lighting.glsl"

layout(binding = 0) uniform sampler2D gPosition;
layout(binding = 1) uniform sampler2D gNormal;
layout(binding = 2) uniform sampler2D gAlbedo;
layout(binding = 3) uniform sampler2D gEmissive;
layout(binding = 5) uniform sampler2D gSpecular; // rgb F0, a roughness

layout(location = 0) out vec4 outRadiance;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 pos = texelFetch(gPosition, px, 0);
    if (pos.w < 0.5) {
        outRadiance = vec4(0.0);
        return;
    }
    vec3 n = texelFetch(gNormal, px, 0).xyz;
    vec3 albedo = texelFetch(gAlbedo, px, 0).rgb;
    vec3 emissive = texelFetch(gEmissive, px, 0).rgb;
    vec4 spec = texelFetch(gSpecular, px, 0);
    vec3 toEye = gFrame.cameraPos.xyz - pos.xyz;
    float e2 = dot(toEye, toEye);
    vec3 v = e2 > 1e-20 ? toEye * inversesqrt(e2) : n;
    vec3 radiance = emissive + lightsReflected(pos.xyz, n, albedo, spec, v, gFrame.shadingInfo.z > 0.5);
    outRadiance = vec4(max(sanitize(radiance), vec3(0.0)), 1.0);
}
