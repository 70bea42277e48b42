#version 450 core
// SSBC half resolution (002 §5, ssbc_half_resolution): bilateral upsampling of one step's
// half-resolution compensation (ssbc_integrate.comp with uReceiverLevel 1: (1/pi) sum per 2x2 block)
// to every pixel. Each pixel blends the 4 nearest level-1 texels with bilinear weights times the
// edge weight (ssbc_common.glsl) between the pixel's own position and normal and the texel's
// area-weighted means, then applies its own albedo. Where every weight vanishes (a pixel unlike all
// 4 neighbouring block means, e.g. on a thin feature), it takes its own block's value: the nearest
// sample, which always exists for a covered pixel.
// Writes C to the next step's level 0 and adds it to the target, like the full-resolution pass.
#include "common.glsl"
#include "gi/common/ssbc_common.glsl"

layout(local_size_x = GIS_SSBC_GROUP, local_size_y = GIS_SSBC_GROUP) in;

layout(binding = 0) uniform sampler2D uGeo;    // mips: xyz mean position, w summed area
layout(binding = 1) uniform sampler2D uNormal; // mips: xyz mean normal
layout(binding = 2) uniform sampler2D uHalf;   // (1/pi) sum per level-1 texel, a = covered
layout(binding = 3) uniform sampler2D gAlbedo;

layout(rgba32f, binding = 0) uniform image2D uTarget;              // += C
layout(rgba32f, binding = 1) uniform writeonly image2D uNextIllum; // level 0 of the next step's input

uniform int uSlot; // counter slot of this step

const float kMinWeight = 1e-6; // below this total the blend is undefined: nearest sample instead

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(gFrame.viewport.xy);
    vec4 stats = vec4(0.0);
    vec3 comp = vec3(0.0);
    vec4 self = all(lessThan(p, size)) ? texelFetch(uGeo, p, 0) : vec4(0.0);
    // Same receivers as full resolution: pixels with a footprint area.
    if (self.w > 0.0) {
        vec3 np = texelFetch(uNormal, p, 0).xyz;
        vec3 eye = gFrame.cameraPos.xyz;
        ivec2 halfSize = (size + 1) >> 1;
        // Level-1 texel t is centred on full-resolution pixel edge 2t + 1.
        vec2 f = (vec2(p) + 0.5) * 0.5 - 0.5;
        ivec2 t0 = ivec2(floor(f));
        vec2 fr = f - vec2(t0);
        vec3 sum = vec3(0.0);
        float wsum = 0.0;
        for (int k = 0; k < 4; ++k) {
            ivec2 o = ivec2(k & 1, k >> 1);
            ivec2 t = t0 + o;
            if (any(lessThan(t, ivec2(0))) || any(greaterThanEqual(t, halfSize))) continue;
            vec4 g = texelFetch(uGeo, t, 1);
            vec4 h = texelFetch(uHalf, t, 0);
            if (!(g.w > 0.0) || h.a < 0.5) continue;
            vec2 bl = mix(1.0 - fr, fr, vec2(o));
            float w = bl.x * bl.y * ssbcEdgeWeight(self.xyz, np, g.xyz, texelFetch(uNormal, t, 1).xyz, eye);
            sum += w * max(sanitize(h.rgb), vec3(0.0));
            wsum += w;
        }
        vec3 e = wsum > kMinWeight ? sum / wsum : max(sanitize(texelFetch(uHalf, p >> 1, 0).rgb), vec3(0.0));
        comp = max(sanitize(texelFetch(gAlbedo, p, 0).rgb * e), vec3(0.0));
        stats = vec4((comp.r + comp.g + comp.b) / 3.0, 0.0, 0.0, wsum > kMinWeight ? 0.0 : 1.0);
        vec4 current = imageLoad(uTarget, p);
        imageStore(uTarget, p, vec4(max(sanitize(current.rgb), vec3(0.0)) + comp, current.a));
    }
    if (all(lessThan(p, imageSize(uNextIllum)))) imageStore(uNextIllum, p, vec4(comp, self.w > 0.0 ? 1.0 : 0.0));
    ssbcGroupSum(stats, uSlot);
}
