#version 450 core
// Final full-resolution indirect radiance: level 0 of the reconstruction (000 §3.5) fused with the
// per-pixel shading. Gathers store
// irradiance, so the pixel's own albedo / pi is applied here at full resolution and texture detail
// survives coarse patches; the per-VPL (non-diffuse) splat stores outgoing radiance already.
// Optional detail modulation (000 Eq. 3): c * (alpha <V, N> + 1 - alpha).
#include "common.glsl"
#include "gi/common/eye_hierarchy.glsl"


layout(binding = 0) uniform sampler2D gPosition;
layout(binding = 1) uniform sampler2D gNormal;
layout(binding = 2) uniform sampler2D gAlbedo;
layout(binding = 3) uniform sampler2D uReconstructed; // levels >= 1 finished
layout(binding = 4) uniform sampler2D uRendered;      // level 0 receivers (alpha 1)
layout(binding = 11) uniform sampler2D uAtlasPosition; // levels >= 1: xyz mean position; w covered pixels
layout(binding = 12) uniform sampler2D uAtlasNormal;   // levels >= 1: xyz mean unit normal
uniform int uInterpolate; // 0: replicate the parent (per-VPL lists)
layout(location = 0) out vec4 outIndirect;

uniform int uIrradiance;   // 1: buffer holds irradiance (multiply by albedo / pi); 0: radiance
uniform float uDetailAlpha; // [0, 1]; 0 = off

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 pos = texelFetch(gPosition, p, 0);
    vec3 normal = texelFetch(gNormal, p, 0).xyz;
    // Computed for background pixels too and selected away: llvmpipe would run a divergent branch anyway.
    EyeGeometry fine;
    fine.position = pos;
    fine.normal = normal;
    // Level 0 at the atlas origin.
    vec3 c = eyeCombine(texelFetch(uRendered, p, 0), uReconstructed, uAtlasPosition, uAtlasNormal, 0, p,
                        uInterpolate != 0, fine).rgb;
    if (uIrradiance != 0) c *= texelFetch(gAlbedo, p, 0).rgb * kInvPi;
    if (uDetailAlpha > 0.0) {
        vec3 toEye = gFrame.cameraPos.xyz - pos.xyz;
        float len2 = dot(toEye, toEye);
        float cosV = len2 > 1e-20 ? max(dot(normal, toEye * inversesqrt(len2)), 0.0) : 1.0;
        c *= uDetailAlpha * cosV + (1.0 - uDetailAlpha);
    }
    outIndirect = vec4(pos.w > 0.5 ? max(sanitize(c), vec3(0.0)) : vec3(0.0), 1.0);
}
