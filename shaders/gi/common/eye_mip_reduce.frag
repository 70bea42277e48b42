#version 450 core
// One coarser level of the eye hierarchy (min-max mipmaps, 000 §3 step 4; 001 §3.1 step 3): min of
// mins, max of maxes, max of the derivative and curvature max-mips, and coverage-weighted means of
// position, normal and albedo (the coarse patch's receiver sample). Level 1 reduces G-buffer pixels
// directly (GIS_FROM_GBUFFER); coarser levels read the level below from the atlas textures they
// render into (the viewport covers only this level; glTextureBarrier between levels makes that
// defined, GL 4.5 §9.3). Odd sizes: a texel reduces only the children that exist.
// Written without branches: llvmpipe shades a 4x4 block of fragments together and runs both sides
// of a branch whose condition it cannot prove uniform, so every child is fetched (clamped into its
// level) and selected in or out. The neighbour metrics of level 1's pixels (derivative, curvature)
// are a program variant, GIS_EYE_PIXEL_METRICS, not a test of the options uniform.
#include "common.glsl"
#include "gi/common/eye_hierarchy.glsl"
#include "gi/common/eye_pixel.glsl"

#ifndef GIS_EYE_PIXEL_METRICS
#define GIS_EYE_PIXEL_METRICS 0
#endif
// The mean albedo only for hierarchies whose patches read it (EyeHierarchy's patchAlbedo): its fetches
// and its target cost every texel otherwise.
#ifndef GIS_EYE_ALBEDO
#define GIS_EYE_ALBEDO 1
#endif

layout(binding = 0) uniform sampler2D uGeoPosition; // xyz mean position (m); w covered pixels
layout(binding = 1) uniform sampler2D uGeoNormal;   // xyz mean unit normal
layout(binding = 2) uniform sampler2D uGeoAlbedo;   // rgb mean albedo
layout(binding = 3) uniform sampler2D uDepthInfo;   // x min d; y max d (m); z max |grad d|/d; w max curvature
layout(binding = 4) uniform sampler2D uNormalMin;   // xyz per-component min
layout(binding = 5) uniform sampler2D uNormalMax;   // xyz per-component max

layout(location = 0) out vec4 outGeoPosition;
layout(location = 1) out vec4 outGeoNormal;
layout(location = 2) out vec4 outDepthInfo;
layout(location = 3) out vec4 outNormalMin;
layout(location = 4) out vec4 outNormalMax;
layout(location = 5) out uint outDiscFlags; // covered | discontinuous (the flags pass adds the diagonal rule)
#if GIS_EYE_ALBEDO
layout(location = 6) out vec4 outGeoAlbedo;
#endif

uniform int uLevel; // the level written (>= 1)

struct PatchStats {
    float count; // covered pixels; 0 for an empty child, whose other fields are not used
    vec3 pos, normal, albedo, nmin, nmax;
    vec4 depth; // min, max, derivative, curvature; an empty child's is neutral for min/max
};

// Child c of the level below, c inside it.
PatchStats childStats(ivec2 c) {
    PatchStats s;
#if GIS_FROM_GBUFFER
    vec4 p = texelFetch(gPosition, c, 0);
    s.normal = texelFetch(gNormal, c, 0).xyz;
#if GIS_EYE_ALBEDO
    s.albedo = texelFetch(gAlbedo, c, 0).rgb;
#else
    s.albedo = vec3(0.0);
#endif
    bool covered = p.w > 0.5 && !any(isnan(p.xyz)) && !any(isinf(p.xyz)) && !any(isnan(s.normal)) &&
                   !any(isinf(s.normal));
    s.count = covered ? 1.0 : 0.0;
    s.pos = p.xyz;
    s.nmin = s.normal;
    s.nmax = s.normal;
    float d = length(p.xyz - gFrame.cameraPos.xyz);
#if GIS_EYE_PIXEL_METRICS
    vec2 metrics = eyePixelDerivativeCurvature(c, d, s.normal);
#else
    vec2 metrics = vec2(0.0);
#endif
    s.depth = covered ? vec4(d, d, metrics) : vec4(3.0e38, -3.0e38, 0.0, 0.0);
#else
    ivec2 a = eyeAtlas(uLevel - 1, c);
    vec4 gp = texelFetch(uGeoPosition, a, 0);
    s.count = gp.w;
    s.pos = gp.xyz;
    s.depth = texelFetch(uDepthInfo, a, 0);
    s.normal = texelFetch(uGeoNormal, a, 0).xyz;
#if GIS_EYE_ALBEDO
    s.albedo = texelFetch(uGeoAlbedo, a, 0).rgb;
#else
    s.albedo = vec3(0.0);
#endif
    s.nmin = texelFetch(uNormalMin, a, 0).xyz;
    s.nmax = texelFetch(uNormalMax, a, 0).xyz;
#endif
    return s;
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy) - gEye.level[uLevel].xy;
    ivec2 childSize = uLevel == 1 ? gEye.info.yz : gEye.level[uLevel - 1].zw;
    float count = 0.0;
    vec3 pos = vec3(0.0), nrm = vec3(0.0), alb = vec3(0.0);
    vec4 depth = vec4(3.0e38, -3.0e38, 0.0, 0.0);
    vec3 nmin = vec3(2.0), nmax = vec3(-2.0);
    vec3 firstNormal = vec3(0.0);
    for (int k = 0; k < 4; ++k) {
        ivec2 c = 2 * t + ivec2(k & 1, k >> 1);
        bool exists = all(lessThan(c, childSize));
        PatchStats s = childStats(min(c, childSize - 1));
        bool used = exists && s.count > 0.0;
        vec4 merged = vec4(min(depth.x, s.depth.x), max(depth.y, s.depth.y), max(depth.zw, s.depth.zw));
        depth = exists ? merged : depth;
        firstNormal = used && count == 0.0 ? s.normal : firstNormal;
        count += used ? s.count : 0.0;
        pos += used ? s.pos * s.count : vec3(0.0);
        nrm += used ? s.normal * s.count : vec3(0.0);
        alb += used ? s.albedo * s.count : vec3(0.0);
        nmin = used ? min(nmin, s.nmin) : nmin;
        nmax = used ? max(nmax, s.nmax) : nmax;
    }
    float inv = count > 0.0 ? 1.0 / count : 0.0;
    // Opposing normals can cancel: keep a child's normal rather than normalising ~0.
    float len = length(nrm);
    vec3 n = len > 1e-6 * max(count, 1.0) ? nrm / len : firstNormal;
    bool discontinuous = eyePatchDiscontinuous(uLevel, t, count, depth, nmin, nmax);
    outDiscFlags = (count > 0.0 ? GIS_EYE_FLAG_COVERED : 0u) | (discontinuous ? GIS_EYE_FLAG_DISCONTINUOUS : 0u);
    outGeoPosition = vec4(pos * inv, count);
    outGeoNormal = vec4(n, 0.0);
#if GIS_EYE_ALBEDO
    outGeoAlbedo = vec4(alb * inv, 0.0);
#endif
    outDepthInfo = depth;
    outNormalMin = vec4(nmin, 0.0);
    outNormalMax = vec4(nmax, 0.0);
}
