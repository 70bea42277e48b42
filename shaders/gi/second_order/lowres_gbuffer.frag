#version 450 core
// 003 §3.5: S_locam, the G-buffer averaged over factor x factor blocks (covered pixels only). A block
// straddling an edge averages to a point between the surfaces; the discontinuity test then sends
// every pixel near it to the full-resolution fix-up.
#include "common.glsl"

layout(binding = 0) uniform sampler2D gPosition;
layout(binding = 1) uniform sampler2D gNormal;

uniform int uFactor; // full-res pixels per low-res texel side

layout(location = 0) out vec4 outPosition; // xyz mean world position; w = 1 where any pixel is covered
layout(location = 1) out vec4 outNormal;   // xyz unit mean normal

void main() {
    ivec2 size = textureSize(gPosition, 0);
    ivec2 origin = ivec2(gl_FragCoord.xy) * uFactor;
    vec3 position = vec3(0.0), normal = vec3(0.0), firstNormal = vec3(0.0, 1.0, 0.0);
    float covered = 0.0;
    for (int y = 0; y < uFactor; ++y)
        for (int x = 0; x < uFactor; ++x) {
            ivec2 px = origin + ivec2(x, y);
            if (any(greaterThanEqual(px, size))) continue; // partial block at an odd-sized edge
            vec4 p = texelFetch(gPosition, px, 0);
            if (p.w < 0.5) continue;
            vec3 n = texelFetch(gNormal, px, 0).xyz;
            if (covered == 0.0) firstNormal = n;
            position += p.xyz;
            normal += n;
            covered += 1.0;
        }
    if (covered == 0.0) {
        outPosition = vec4(0.0);
        outNormal = vec4(0.0, 1.0, 0.0, 0.0);
        return;
    }
    float len2 = dot(normal, normal);
    // Opposite normals can cancel: fall back to one of the block's own normals.
    normal = len2 > 1e-12 ? normal * inversesqrt(len2) : firstNormal;
    vec3 mean = position / covered;
    bool ok = !(isBad(mean.x) || isBad(mean.y) || isBad(mean.z));
    outPosition = ok ? vec4(mean, 1.0) : vec4(0.0);
    outNormal = vec4(sanitize(normal), 0.0);
}
