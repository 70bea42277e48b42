#version 450 core
// Final indirect radiance: the fix-up irradiance where the discontinuity pass flagged the pixel,
// bilinear upsampling of the low-res irradiance elsewhere (003 §3.5), times albedo / pi. Then 003
// §3.4's "direct + indirect - negative", clamped at 0 (digest 003.1 step 7): the output is
// max(indirect - negative, -direct), so the renderer's composite (direct + this) is >= 0 without
// losing the subtraction, and the clamped pixels are counted.
#include "common.glsl"
#include "gi/second_order/second_order.glsl"

layout(binding = 0) uniform sampler2D gPosition;
layout(binding = 1) uniform sampler2D gAlbedo;
layout(binding = 2) uniform sampler2D gDirect;
layout(binding = 3) uniform sampler2D gFlag;
layout(binding = 4) uniform sampler2D gFullIrradiance;
layout(binding = 5) uniform sampler2D gLowIrradiance;
layout(binding = 6) uniform sampler2D gLowPosition;

uniform int uFactor;
uniform ivec2 uLowSize;
uniform int uFixup;     // 1 when the discontinuity and fix-up passes ran
uniform int uHasDirect; // 0: no direct texture given, clamp the indirect term at 0 instead

layout(location = 0) out vec4 outRadiance;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    if (texelFetch(gPosition, px, 0).w < 0.5) discard; // background stays the cleared 0 (and uncounted)

    vec3 e;
    if (uFixup == 1 && texelFetch(gFlag, px, 0).r > 0.5) {
        e = texelFetch(gFullIrradiance, px, 0).rgb;
    } else {
        ivec2 texel[4];
        float weight[4];
        lowResNeighbours(px, uFactor, uLowSize, texel, weight);
        vec3 sum = vec3(0.0);
        float total = 0.0;
        for (int k = 0; k < 4; ++k) {
            // Empty low-res texels carry no data (not black): only reachable without the fix-up.
            float w = texelFetch(gLowPosition, texel[k], 0).w >= 0.5 ? weight[k] : 0.0;
            sum += w * texelFetch(gLowIrradiance, texel[k], 0).rgb;
            total += w;
        }
        e = total > 1e-6 ? sum / total : vec3(0.0);
    }
    vec3 albedo = texelFetch(gAlbedo, px, 0).rgb;
    vec3 radiance = sanitize(albedo * kInvPi * e);
    vec3 direct = uHasDirect == 1 ? max(sanitize(texelFetch(gDirect, px, 0).rgb), vec3(0.0)) : vec3(0.0);
    if (any(lessThan(radiance, -direct))) atomicAdd(gClampedPixels, 1u);
    outRadiance = vec4(max(radiance, -direct), 1.0);
}
