#version 450 core
// Composite: direct + indirect + reflections, sanitised (no NaN/Inf/negative leaves this pass), then exposure,
// tone mapping and sRGB encoding for display. The linear sum is kept for EXR output and metrics.
#include "common.glsl"

layout(binding = 0) uniform sampler2D gDirect;
layout(binding = 1) uniform sampler2D gIndirect;
layout(binding = 2) uniform sampler2D gReflection; // env probe + planar mirrors (render/Reflections)
layout(binding = 3) uniform sampler2D gAlbedo;     // a: glTF occlusion (1 without a map)
uniform int uHasIndirect;
uniform int uApplyOcclusion; // 1: the indirect light is multiplied by the occlusion map
// Frames with reflections get a program of their own: llvmpipe runs both sides of a branch on a
// uniform, so the others would fetch and sanitise a reflection for every pixel.
#ifndef GIS_COMPOSITE_REFLECTION
#define GIS_COMPOSITE_REFLECTION 1
#endif

layout(location = 0) out vec4 outDisplay; // RGBA8: tone-mapped sRGB
layout(location = 1) out vec4 outLinear;  // RGBA32F: linear radiance

// ACES filmic fit by K. Narkowicz (2015): one common filmic curve.
vec3 filmic(vec3 x) {
    const float a = 2.51, b = 0.03, c = 2.43, d = 0.59, e = 0.14;
    return clamp((x * (a * x + b)) / (x * (c * x + d) + e), 0.0, 1.0);
}

vec3 linearToSrgb(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec3 c = sanitize(texelFetch(gDirect, px, 0).rgb);
    if (uHasIndirect == 1) {
        vec3 indirect = sanitize(texelFetch(gIndirect, px, 0).rgb);
        float ao = texelFetch(gAlbedo, px, 0).a;
        if (uApplyOcclusion == 1) indirect *= ao >= 0.0 ? min(ao, 1.0) : 1.0; // NaN: no occlusion
        c += indirect;
    }
#if GIS_COMPOSITE_REFLECTION
    c += max(sanitize(texelFetch(gReflection, px, 0).rgb), vec3(0.0));
#endif
    c = max(c, vec3(0.0));
    outLinear = vec4(c, 1.0);
    vec3 exposed = c * gFrame.toneInfo.x;
    vec3 mapped = gFrame.toneInfo.y > 0.5 ? filmic(exposed) : clamp(exposed, 0.0, 1.0);
    outDisplay = vec4(linearToSrgb(mapped), 1.0);
}
